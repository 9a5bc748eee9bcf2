"""Maximum penetration and peak force of the linear contact in closed form
(impactsym.contact.extrema), checked against the 40-digit matrix-exponential reference of
tests/references/oscillator.py (extrema refined by mpmath, and a dense 40-digit scan that
they are the largest), against the order-8 integration they replace, and by hand."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from references.oscillator import state

from impactsym.contact import contact_time, impact
from impactsym.contact.extrema import first_zero, linear_extrema
from impactsym.contact.lawkernel import integrate


def force_of(t, damping, force):
    z, v = state(t, damping, force)
    return z + 2 * damping * v


def reference(damping: float, force: float, tau_c: float) -> tuple[float, float]:
    """40-digit sup of z and of max(0, z + 2Dz') over [0, tau_c]: the largest of a scan
    of 240 points (and the limit 2Df where the body sticks), each interior maximum then
    refined by mpmath on the derivative."""
    with mp.workdps(40):
        d, fr = mp.mpf(damping), mp.mpf(force)
        end = mp.mpf(tau_c) if math.isfinite(tau_c) else mp.mpf(60)
        grid = [end * k / 240 for k in range(241)]
        results = []
        for value, slope in (
            (lambda t: state(t, d, fr)[0], lambda t: state(t, d, fr)[1]),
            (
                lambda t: force_of(t, d, fr),
                lambda t: (
                    state(t, d, fr)[1]
                    + 2 * d * (2 * d * fr - 2 * d * state(t, d, fr)[1] - state(t, d, fr)[0])
                ),
            ),
        ):
            values = [value(t) for t in grid]
            best = max(values)
            k = values.index(best)
            if 0 < k < 240:  # an interior maximum: refine it
                best = value(mp.findroot(slope, (grid[k - 1], grid[k + 1]), solver="anderson"))
            if not math.isfinite(tau_c):
                best = max(best, 2 * d * fr)  # the limit of a sticking body
            results.append(float(max(best, 0)))
        return results[0], results[1]


@pytest.mark.parametrize(
    ("damping", "force", "condition"),
    [
        (0.0, 0.0, "force"),
        (0.05, 0.3, "position"),
        (0.3, 0.5, "force"),
        (0.3, 0.5, "position"),
        (0.7, 0.05, "force"),
        (0.999999, 0.2, "force"),
        (1.0, 0.3, "force"),
        (1.000001, 0.2, "position"),
        (1.0, 0.0, "position"),
        (3.0, 0.05, "force"),
        (3.0, 0.4, "force"),
        (0.2, 0.0, "position"),
    ],
)
def test_extrema_match_the_40_digit_reference(damping, force, condition):
    tau_c = float(contact_time(damping, force, condition=condition))
    z_max, peak = linear_extrema(
        np.array([damping]), np.array([2 * damping * force]), np.array([tau_c])
    )
    z_ref, peak_ref = reference(damping, force, tau_c)
    assert abs(z_max[0] - z_ref) <= 1e-14 * z_ref, (z_max[0], z_ref)
    assert abs(peak[0] - peak_ref) <= 1e-14 * peak_ref, (peak[0], peak_ref)


def test_undamped_extrema_by_hand():
    # z = b (1 - cos t) + sin t: z' = 0 at tan t = -1/b, z_max = b + sqrt(1 + b^2); the force
    # z is the penetration itself, peak = z_max (pressed body released at 2 pi - 2 atan(1/b))
    b = np.array([0.0, 0.5, 3.0])
    tau_c = 2 * np.pi - 2 * np.arctan2(1.0, b)
    z_max, peak = linear_extrema(np.zeros(3), b, tau_c)
    np.testing.assert_allclose(z_max, b + np.sqrt(1 + b * b), rtol=1e-15)
    np.testing.assert_allclose(peak, z_max, rtol=1e-15)


def test_first_zero_of_the_damped_oscillation_in_every_regime():
    # y = e^-t (1 - 2t) at D = 1 crosses down at 1/2; D = 5/4: y = e^-t/2 - e^-2t... from
    # y0 = 0, y1 = 1 never crosses; under-damped y = e^{-Dt} sin(w t)/w down at pi/w
    D = np.array([1.0, 1.25, 0.6, 0.6])
    y0, y1 = np.array([1.0, 0.0, 0.0, 0.0]), np.array([-3.0, 1.0, 1.0, -1.0])
    down = first_zero(D, y0, y1, upward=False)
    np.testing.assert_allclose(down[[0, 2]], [0.5, np.pi / 0.8], rtol=1e-15)
    assert math.isinf(down[1])
    assert down[3] == pytest.approx(2 * np.pi / 0.8, rel=1e-15)  # starts downwards at 0
    up = first_zero(D, -y0, -y1, upward=True)
    np.testing.assert_allclose(up[[0, 2]], [0.5, np.pi / 0.8], rtol=1e-15)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_extrema_agree_with_the_integration_they_replace(condition):
    rng = np.random.default_rng(4)
    damping = np.concatenate(
        [rng.uniform(0.0, 1.5, 60), 1.0 + rng.uniform(-0.01, 0.01, 20), [1.0] * 4,
         rng.uniform(1.5, 5.0, 20)]
    )  # fmt: skip
    force = rng.uniform(0.0, 1.0, damping.size)
    force[::5] = 0.0
    b = 2 * damping * force
    tau_c = contact_time(damping, force, condition=condition)
    z_max, peak = linear_extrema(damping, b, tau_c)
    run = integrate("linear", damping, b, np.ones_like(b), condition=condition, end_time=tau_c)
    np.testing.assert_allclose(z_max, run.z_max, rtol=1e-12)
    np.testing.assert_allclose(peak, run.peak, rtol=1e-12)


def test_the_linear_law_takes_the_closed_form_extrema():
    damping, force = np.array([0.1, 0.8, 1.0, 2.5]), np.array([0.3, 0.6, 0.2, 0.05])
    for condition in ("position", "force"):
        r = impact("linear", stiffness=4.0, damping=2 * 2 * damping, mass=1.0, speed=2.0,
                   force=force * (2 * 2 * damping) * 2.0, condition=condition)  # fmt: skip
        tau_c = contact_time(damping, force, condition=condition)
        z_max, peak = linear_extrema(damping, 2 * damping * force, tau_c)
        # length unit v0/omega0 = 1, force unit m omega0 v0 = 4
        np.testing.assert_allclose(r.max_penetration, z_max, rtol=1e-15)
        np.testing.assert_allclose(r.peak_force, 4.0 * peak, rtol=1e-15)


@pytest.mark.parametrize(
    ("D", "error"), [(np.array([-0.5]), ValueError), (np.array([np.nan]), ValueError),
                     ("0.5", TypeError)],
)  # fmt: skip
def test_a_bad_damping_ratio_is_refused_by_name(D, error):
    one = np.ones(1)
    with pytest.raises(error, match="D"):
        first_zero(D, one, one, upward=True)
    with pytest.raises(error, match="D"):
        linear_extrema(D, np.zeros(1), np.full(1, np.pi))
