"""The order-8 integration of the contact laws: events located per element (a batch and
its elements agree), checked on the linear law against the exact linear contact."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.contact.api import contact_time, restitution
from impactsym.contact.lawclosed import (
    hunt_crossley_restitution,
    linear_free_restitution,
    tsuji_zeta,
)
from impactsym.contact.lawkernel import integrate


@pytest.mark.parametrize("condition", ["position", "force"])
def test_linear_law_events_match_the_exact_contact_in_a_batch_and_alone(condition):
    rng = np.random.default_rng(11)
    D = rng.uniform(0.02, 0.9, 24)
    f = np.where(rng.uniform(size=24) < 0.5, 0.0, rng.uniform(0, 0.3, 24))
    q = np.ones_like(D)
    run = integrate("linear", D, 2 * D * f, q, condition=condition)
    tau, e = contact_time(D, f, condition=condition), restitution(D, f, condition=condition)
    released = np.isfinite(tau)
    assert released.sum() > 12
    np.testing.assert_array_equal(np.isinf(run.tau_c), ~released)
    np.testing.assert_allclose(run.tau_c[released], tau[released], rtol=1e-11)
    np.testing.assert_allclose(run.e[released], e[released], rtol=1e-10, atol=1e-12)
    for i in range(0, 24, 5):  # each element alone gives what it gave in the batch
        alone = integrate("linear", D[i : i + 1], 2 * D[i : i + 1] * f[i : i + 1], q[:1],
                          condition=condition)  # fmt: skip
        for field in ("tau_c", "e", "z_max", "peak"):
            np.testing.assert_allclose(
                getattr(alone, field), getattr(run, field)[i : i + 1], rtol=1e-14
            )


def test_maximum_penetration_and_peak_force_of_the_damped_linear_contact_to_1e_12():
    # z = exp(-D t) sin(w t) / w: the maximum penetration at tan(w t) = w / D and the
    # peak of z + 2 D z' where its rate z' (1 - 4 D^2) - 2 D z vanishes (D < 1/2), by
    # mpmath at 30 digits: the extrema, located to a bracket of 1e-9 of the step, are
    # exact to the integration's accuracy
    mpmath = pytest.importorskip("mpmath")
    D = np.linspace(0.05, 0.45, 9)
    run = integrate("linear", D, np.zeros_like(D), np.ones_like(D), condition="position")
    with mpmath.workdps(30):
        for i, d in enumerate(D):
            d = mpmath.mpf(d)
            om = mpmath.sqrt(1 - d * d)

            def z(t, d=d, om=om):
                return mpmath.exp(-d * t) * mpmath.sin(om * t) / om

            def w(t, d=d, om=om):
                return mpmath.exp(-d * t) * (mpmath.cos(om * t) - d * mpmath.sin(om * t) / om)

            t_max = mpmath.atan2(om, d) / om
            t_peak = mpmath.findroot(
                lambda t, d=d: w(t) * (1 - 4 * d * d) - 2 * d * z(t), (0, t_max), solver="anderson"
            )
            assert run.z_max[i] == pytest.approx(float(z(t_max)), rel=1e-12)
            peak = z(t_peak) + 2 * d * w(t_peak)
            assert run.peak[i] == pytest.approx(float(peak), rel=1e-12)


def test_exit_taken_early_where_the_force_left_is_negligible_keeps_the_closed_forms():
    # the exit at z = 0 is taken once the force left on the way there changes z' by less
    # than 1e-14 of it (Hunt-Crossley: at z ~ 1e-6, not 1e-14): the restitutions stay
    # the closed forms (Lambert W; the Tsuji map onto the linear contact) to 1e-11
    s = np.array([0.05, 0.3, 1.0, 2.5, 6.0])
    hc = integrate("hunt-crossley", s, np.zeros_like(s), np.full(5, 1.5), condition="position")
    np.testing.assert_allclose(hc.e, hunt_crossley_restitution(s), rtol=1e-11)
    alpha = np.array([0.05, 0.3, 0.8, 1.5, 2.0])
    ts = integrate("tsuji", alpha, np.zeros_like(alpha), np.full(5, 1.5), condition="position")
    e = linear_free_restitution(tsuji_zeta(alpha, 1.5), condition="position")
    np.testing.assert_allclose(ts.e, e, rtol=1e-11)


def test_maximum_penetration_and_peak_of_the_undamped_linear_contact():
    # z = sin(tau): the maximum penetration and the peak force are 1 (located by events)
    run = integrate("linear", np.array([0.0]), np.array([0.0]), np.array([1.0]),
                    condition="position")  # fmt: skip
    assert run.z_max[0] == pytest.approx(1.0, rel=1e-13)
    assert run.peak[0] == pytest.approx(1.0, rel=1e-13)
    assert run.tau_c[0] == pytest.approx(np.pi, rel=1e-12)
