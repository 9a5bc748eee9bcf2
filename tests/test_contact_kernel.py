"""The section-2 kernel (impactsym.contact.kernel): the contact from an arbitrary state,
and the limits that replace the closed forms where they lose double precision, checked
against event-integrated ODEs and mpmath matrix exponentials (no closed forms)."""

from __future__ import annotations

import itertools
import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact import contact_time, restitution, stick_boundary
from impactsym.contact.kernel import first_release, z_dot


def _bisect(fun, lo, hi, steps=80):
    """Root of ``fun`` between ``lo`` and ``hi`` (opposite signs) by plain bisection."""
    sign_lo = mp.sign(fun(lo))
    assert sign_lo * mp.sign(fun(hi)) < 0
    for _ in range(steps):
        mid = (lo + hi) / 2
        if mp.sign(fun(mid)) == sign_lo:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def _release_time_mp(D, f=0):
    """Contact time of the force condition from the matrix exponential of the ODE
    (mpmath, no eigenvalues or closed forms): root of g = 2 D z' + z in tau > 0.
    g is of order D^-3 there, a difference of terms of order 1: hence the digits."""
    with mp.workdps(int(3 * math.log10(D)) + 40):
        D, f = mp.mpf(D), mp.mpf(f)
        A = mp.matrix([[0, 1, 0], [-1, -2 * D, 2 * D * f], [0, 0, 0]])
        x0 = mp.matrix([0, 1, 1])

        def state(tau):
            return mp.expm(A * tau) * x0

        def g(tau):
            z, zd, _ = state(tau)
            return 2 * D * zd + z

        guess = mp.log(16 * D**4) / (2 * D)  # leading order, only to bracket the root
        root = _bisect(g, guess / 2, guess * 2)
        return float(root), float(-state(root)[1])


@pytest.mark.parametrize("D", [1e9, 1e20, 1e40])
def test_far_overdamped_force_contact_releases_at_the_exact_time(D):
    tau_ref, e_ref = _release_time_mp(D)
    assert contact_time(D, 0.0, condition="force") == pytest.approx(tau_ref, rel=1e-14)
    assert restitution(D, 0.0, condition="force") == pytest.approx(e_ref, rel=1e-12)
    assert contact_time(D, 0.0, condition="position") == math.inf
    assert restitution(D, 0.0, condition="position") == 0.0


@pytest.mark.parametrize("D", [1e100, 1e200, 1e300, 1.7e308])
def test_far_overdamped_closed_form_holds_to_the_largest_float(D):
    # the closed form checked against the matrix exponential above, now in mpmath
    with mp.workdps(40):
        Dm = mp.mpf(D)
        sigma = mp.sqrt(Dm**2 - 1)
        mu = Dm + sigma
        tau = mp.log((2 * Dm * mu - 1) * mu**2) / (2 * sigma)
        e = (mp.exp(-tau / mu) / mu - mu * mp.exp(-mu * tau)) / (2 * sigma)
    assert contact_time(D, 0.0, condition="force") == pytest.approx(float(tau), rel=1e-14)
    assert restitution(D, 0.0, condition="force") == pytest.approx(float(e), rel=1e-12, abs=1e-320)


def test_far_overdamped_limit_joins_the_kernels_continuously():
    D = np.array([0.999e8, 1e8, 1.001e8])
    tau = contact_time(D, 0.0, condition="force")
    np.testing.assert_allclose(tau, [_release_time_mp(d)[0] for d in D], rtol=1e-13)


def _boundary_sign_mp(D, f, dps=80):
    """Sign of min g (force condition) after impact, from the matrix exponential."""
    with mp.workdps(dps):
        D, f = mp.mpf(D), mp.mpf(f)
        A = mp.matrix([[0, 1, 0], [-1, -2 * D, 2 * D * f], [0, 0, 0]])
        x0 = mp.matrix([0, 1, 1])

        def gdot(tau):
            z, zd, _ = mp.expm(A * tau) * x0
            return 2 * D * (2 * D * f - z - 2 * D * zd) + zd

        def g(tau):
            z, zd, _ = mp.expm(A * tau) * x0
            return 2 * D * zd + z

        grid = [mp.mpf(10) ** (k / 4) / D for k in range(-8, 40)]
        lo, hi = next((a, b) for a, b in itertools.pairwise(grid) if gdot(a) < 0 < gdot(b))
        ridge = _bisect(gdot, lo, hi)
        return mp.sign(g(ridge))


@pytest.mark.parametrize("f", [1e-40, 1e-100, 1e-300])
def test_tiny_force_stick_boundary_follows_its_asymptote_and_is_exact(f):
    d_star = stick_boundary(f, condition="force")
    assert d_star == pytest.approx(0.5 * f**-0.25, rel=1e-15)
    if f == 1e-40:  # the matrix exponential gets slow beyond
        assert _boundary_sign_mp(d_star * (1 - 1e-9), f) < 0  # releases
        assert _boundary_sign_mp(d_star * (1 + 1e-9), f) > 0  # sticks
    assert contact_time(d_star * 1.001, f, condition="force") == math.inf


# -- the contact from an arbitrary state ----------------------------------------------
def test_restart_kernel_matches_contact_time_at_the_first_impact():
    rng = np.random.default_rng(3)
    damping = np.concatenate([[1.0, 0.0], rng.uniform(0, 3, 400)])
    force = rng.uniform(0, 1, damping.size)
    start = (np.zeros_like(damping), np.ones_like(damping))
    for condition in ("position", "force"):
        plain = contact_time(damping, force, condition=condition)
        restart = first_release(damping, force, state=start, condition=condition)
        assert np.array_equal(np.isinf(plain), np.isinf(restart))
        ok = np.isfinite(plain)
        np.testing.assert_allclose(restart[ok], plain[ok], rtol=1e-13, atol=1e-13)


def _ode_contact(d, fr, z_start, v_start):
    def release(_t, y):
        return 2 * d * y[1] + y[0]

    release.terminal, release.direction = True, -1
    sol = solve_ivp(
        lambda _t, y: [y[1], 2 * d * fr - 2 * d * y[1] - y[0]],
        (0, 300),
        [z_start, v_start],
        events=release,
        rtol=1e-12,
        atol=1e-14,
        method="DOP853",
    )
    if not sol.t_events[0].size:
        return math.inf, 0.0
    return sol.t_events[0][0], -sol.y_events[0][0][1]


@pytest.mark.parametrize(
    ("d", "fr", "z_start", "v_start"),
    [
        (0.3, 0.2, 0.2, 0.5),  # under-damped, element still deflected
        (0.3, 0.2, 0.4, -0.1),  # caught from behind: body still moving away
        (0.6, 0.05, 0.05, 0.3),
        (1.0, 0.02, 0.1, 0.4),  # critical
        (1.0, 0.3, 0.1, 0.4),  # critical, sticks
        (2.5, 0.01, 0.3, 0.2),  # over-damped
        (2.5, 0.2, 0.3, 0.2),  # over-damped, sticks
    ],
)
def test_contact_time_from_a_deflected_state_against_ode(d, fr, z_start, v_start):
    arrays = [np.array([value]) for value in (d, fr, z_start, v_start)]
    tau_c = first_release(arrays[0], arrays[1], state=tuple(arrays[2:]), condition="force")[0]
    expected, speed = _ode_contact(d, fr, z_start, v_start)
    if math.isinf(expected):
        assert math.isinf(tau_c)
        return
    assert tau_c == pytest.approx(expected, rel=1e-9)
    departure = -z_dot(restart=True)(*(np.array([tau_c]), *arrays))[0]
    assert departure == pytest.approx(speed, rel=1e-8)
