"""The unpressed spring-damper contact in closed form (impactsym.contact.unpressed),
checked against the 40-digit matrix-exponential reference of tests/references/oscillator.py
(its roots refined by mpmath), against the kernel's bracketed root it replaces, and at the
critical damping from both sides."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from references.oscillator import contact_function, refine_root, state

from impactsym.contact import contact_time, impact, physical_contact, restitution
from impactsym.contact.kernel import first_release, limits, z_dot
from impactsym.contact.unpressed import force_exponent, unpressed_release

CONDITIONS = ("position", "force")
EPS = 2.0**-52
#: The damping ratios of the check: undamped, tiny, moderate, both sides of critical
#: damping at 1e-6 and at a few ulp, critical, over-damped, far over-damped.
DAMPING = (0.0, 1e-8, 0.3, 0.999999, 1.0 - 2 * EPS, 1.0, 1.0 + 4 * EPS, 1.000001, 3.0, 1e3)


def reference(damping: float, condition: str, guess: float) -> tuple[mp.mpf, mp.mpf]:
    """40-digit contact time and restitution: the root of g near ``guess``, refined by
    mpmath on the matrix-exponential state, after checking that g stays positive on 64
    points before it (so it is the first root)."""
    tau = refine_root(guess, damping, 0.0, condition)
    with mp.workdps(40):
        for k in range(1, 64):
            assert contact_function(tau * k / 64, damping, 0.0, condition) > 0, (damping, k)
        return tau, -state(tau, damping, 0.0)[1]


@pytest.mark.parametrize("condition", CONDITIONS)
@pytest.mark.parametrize("damping", DAMPING)
def test_closed_forms_match_the_40_digit_reference(damping, condition):
    tau_c, e = (float(v) for v in unpressed_release(np.array(damping), condition=condition))
    if condition == "position" and damping >= 1:
        # critically and over-damped: z = t e^-t, or a difference of two decaying
        # exponentials with the slower one ahead, stays positive: the body creeps back
        assert (tau_c, e) == (math.inf, 0.0)
        for t in (0.5, 5.0, 50.0, 500.0):
            assert contact_function(t, damping, 0.0, "position") > 0
        return
    tau_ref, e_ref = reference(damping, condition, tau_c)
    assert abs(tau_c - float(tau_ref)) <= 1e-15 * float(tau_ref), damping
    if e_ref < 1e-300:  # D = 0.999999, position: the rebound speed e^-2221 underflows
        assert e == 0.0
    else:
        assert abs(e - float(e_ref)) <= 1e-14 * float(e_ref), damping


def test_critical_damping_is_met_from_both_sides_without_cancellation():
    # tau_c = 2 - 2(D - 1)/3 + O((D - 1)^2) and e = e^-2 (1 + O((D - 1)^2)) near D = 1 (force)
    offsets = np.array([-1e-4, -1e-9, -64 * EPS, -EPS, 0.0, 2 * EPS, 64 * EPS, 1e-9, 1e-4])
    tau_c, e = unpressed_release(1.0 + offsets, condition="force")
    assert tau_c[4] == 2.0
    assert e[4] == math.exp(-2.0)
    for d, t, ei in zip(1.0 + offsets, tau_c, e, strict=True):
        t_ref, e_ref = reference(float(d), "force", float(t))
        assert abs(t - float(t_ref)) <= 1e-15 * 2.0, d
        assert abs(ei - float(e_ref)) <= 1e-15 * ei, d
    # monotone through D = 1: strictly where the offsets are above rounding; within a few
    # ulps of D = 1 the slope -2/3 moves tau_c by one ulp of 2 or none, depending on the
    # CPU's last bits (both within the 1e-15 of the 40-digit reference above)
    assert np.all(np.diff(tau_c) <= 0)
    assert np.all(np.diff(tau_c[[0, 1, 7, 8]]) < 0)
    assert np.all(np.diff(e) <= 0)


@pytest.mark.parametrize("condition", CONDITIONS)
def test_closed_forms_agree_with_the_kernel_root(condition):
    rng = np.random.default_rng(3)
    damping = np.concatenate(
        [rng.uniform(0.0, 1.0, 200), rng.uniform(1.0, 5.0, 100), 1.0 + rng.uniform(-1e-6, 1e-6, 40)]
    )
    zero = np.zeros_like(damping)
    tau_k = first_release(damping, zero, condition=condition)
    released = np.isfinite(tau_k)
    e_k = np.zeros_like(damping)
    e_k[released] = -z_dot()(tau_k[released], damping[released], zero[released])
    tau_c, e = unpressed_release(damping, condition=condition)
    assert np.array_equal(np.isinf(tau_c), ~released)
    np.testing.assert_allclose(tau_c[released], tau_k[released], rtol=1e-14)
    np.testing.assert_allclose(e[released], e_k[released], rtol=1e-14)
    assert np.all(e[~released] == 0.0)


def test_far_over_damped_force_condition_meets_the_kernels_limit():
    damping = np.array([1e9, 1e20, 1e150, 1e200])
    zero = np.zeros_like(damping)
    decided, tau_limit, e_limit = limits(damping, zero, condition="force")
    assert decided.all()
    tau_c, e = unpressed_release(damping, condition="force")
    np.testing.assert_allclose(tau_c, tau_limit, rtol=1e-14)
    np.testing.assert_allclose(e, e_limit, rtol=1e-14, atol=1e-300)
    # no overflow in sqrt(D^2 - 1) or D arcosh D: tau_c ~ 2 ln(2D)/D, e underflows
    tau_c, e = unpressed_release(np.array([1e300, 1e307, np.inf]), condition="force")
    np.testing.assert_allclose(tau_c[:2], 2 * np.log(2 * np.array([1e300, 1e307])) / [1e300, 1e307])
    assert tau_c[2] == 0.0
    assert np.all(e == 0.0)
    assert force_exponent(np.array(np.inf))[1] == np.inf


@pytest.mark.parametrize("condition", CONDITIONS)
def test_the_api_takes_the_closed_forms_where_unpressed_and_the_kernel_elsewhere(condition):
    damping = np.array([0.2, 0.7, 1.0, 2.0, 0.2, 0.7, 1.0, 2.0])
    force = np.array([0.0, 0.0, 0.0, 0.0, 0.1, 0.3, 0.0, 0.05])
    tau_c = contact_time(damping, force, condition=condition)
    e = restitution(damping, force, condition=condition)
    free = force == 0
    tau_free, e_free = unpressed_release(damping[free], condition=condition)
    assert np.array_equal(tau_c[free], tau_free)
    assert np.array_equal(e[free], e_free)
    # the pressed elements are the kernel's, bit for bit as on their own
    pressed = ~free
    tau_pressed = contact_time(damping[pressed], force[pressed], condition=condition)
    assert np.array_equal(tau_c[pressed], tau_pressed)
    e_pressed = restitution(damping[pressed], force[pressed], condition=condition)
    assert np.array_equal(e[pressed], e_pressed)
    # physical units: F = 0 is f = 0; d = 0.4 sqrt(k m) gives D = 0.2
    c = physical_contact(4.0, 9.0, 0.4 * 6.0 * np.array([1.0, 3.5]), 2.0, condition=condition)
    expected = unpressed_release(np.array([0.2, 0.7]), condition=condition)
    assert np.allclose(c.D, [0.2, 0.7], rtol=1e-15)
    np.testing.assert_allclose(c.normalized_contact_time, expected[0], rtol=1e-15)
    np.testing.assert_allclose(c.contact_time, expected[0] / 1.5, rtol=1e-15)
    np.testing.assert_allclose(c.restitution, expected[1], rtol=1e-14)


def test_the_linear_law_reads_the_same_closed_forms():
    # impact(law="linear") without pressing force is physical_contact, hence the closed form
    damping = np.linspace(0.0, 4.0, 41)
    for condition in CONDITIONS:
        r = impact("linear", stiffness=1.0, damping=damping, mass=1.0, speed=1.0,
                   condition=condition)  # fmt: skip
        tau_c, e = unpressed_release(damping / 2.0, condition=condition)
        assert np.array_equal(r.contact_time, tau_c)
        assert np.array_equal(r.restitution, e)


@pytest.mark.parametrize(
    ("D", "error", "message"),
    [
        (-1.0, ValueError, "D must be >= 0"),
        (np.nan, ValueError, "D"),
        (np.array([0.5, -1e-300]), ValueError, "D must be >= 0"),
        ("0.5", TypeError, "D must be a real number"),
    ],
)
@pytest.mark.parametrize("function", ["unpressed_release", "force_exponent"])
def test_a_bad_damping_ratio_is_refused_by_name(function, D, error, message):
    call = {
        "unpressed_release": lambda: unpressed_release(D, condition="position"),
        "force_exponent": lambda: force_exponent(D),
    }[function]
    with pytest.raises(error, match=message):
        call()
