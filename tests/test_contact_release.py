"""The loaded section-2 oscillator (impactsym.contact.release) against independent references."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact import contact_time, restitution
from impactsym.contact.release import linear_release, release_margin


def test_linear_release_matches_event_integration_in_every_regime():
    rng = np.random.default_rng(3)
    D = np.concatenate([rng.uniform(0.0, 2.5, 36), [0.0, 1.0, 1.0 - 1e-7, 1.0 + 1e-7]])
    c = rng.uniform(0, 3, D.size) * (rng.random(D.size) < 0.7)
    delta = rng.uniform(0, 2, D.size) * (rng.random(D.size) < 0.7)
    rel = linear_release(D, c, delta)
    for i in range(D.size):

        def rhs(t, y, i=i):
            return [y[1], c[i] - 2 * D[i] * y[1] - y[0]]

        def force(t, y, i=i):
            return 2 * D[i] * y[1] + y[0] + delta[i]

        def position(t, y):
            return y[0] if t > 1e-9 else 1.0

        force.terminal = position.terminal = True
        force.direction = position.direction = -1
        sol = solve_ivp(rhs, (0, 200), [0, 1], events=[force, position], rtol=1e-12, atol=1e-14)
        if sol.status == 1 and abs(sol.y[1, -1]) < 1e-8:
            continue  # z -> 0+ only asymptotically (D >= 1, c = 0): round-off 'crossing'
        if sol.status == 1:
            assert rel.contact_time[i] == pytest.approx(sol.t[-1], rel=1e-7)
            assert rel.restitution[i] == pytest.approx(-sol.y[1, -1], abs=1e-7)
            tie = abs(force(0, sol.y[:, -1]) - sol.y[0, -1]) < 1e-9
            assert tie or rel.released_by_position[i] == (len(sol.t_events[1]) > 0)
        else:
            assert math.isinf(rel.contact_time[i])
            assert rel.restitution[i] == 0.0


def test_position_threshold_is_the_papers_position_condition_with_the_same_load():
    # the trajectory is paper section 2's with 2 D f = load; only the thresholds differ
    D = np.array([0.1, 0.4, 0.8, 0.95])
    f = np.array([0.05, 0.3, 0.2, 0.01])
    rel = linear_release(D, 2 * D * f, np.zeros_like(D), force=False)
    position = contact_time(D, f, condition="position")
    np.testing.assert_allclose(rel.contact_time, position, rtol=1e-9)
    np.testing.assert_allclose(rel.restitution, restitution(D, f, condition="position"), atol=1e-9)
    rel = linear_release(D, 2 * D * f, np.zeros_like(D), position=False)
    np.testing.assert_allclose(rel.contact_time, contact_time(D, f, condition="force"), rtol=1e-9)


def test_extremes_match_event_integration():
    # largest penetration and peak force during contact, against a dense ODE solution
    rng = np.random.default_rng(5)
    D = rng.uniform(0.0, 2.0, 12)
    c = rng.uniform(0, 2, D.size)
    delta = rng.uniform(0, 1, D.size)
    rel = linear_release(D, c, delta)
    for i in np.flatnonzero(np.isfinite(rel.contact_time)):
        t = np.linspace(0.0, rel.contact_time[i], 20001)
        sol = solve_ivp(
            lambda _t, y, i=i: [y[1], c[i] - 2 * D[i] * y[1] - y[0]],
            (0, t[-1]),
            [0, 1],
            t_eval=t,
            rtol=1e-12,
            atol=1e-14,
        )
        z, v = sol.y
        assert rel.max_penetration[i] == pytest.approx(z.max(), rel=1e-6, abs=1e-9)
        force = 2 * D[i] * v + z + delta[i]
        assert rel.peak_force[i] == pytest.approx(force.max(), rel=1e-6, abs=1e-9)


def test_release_margin_sign_is_sticking():
    # margin > 0 exactly where both thresholds stay positive: the body never releases
    rng = np.random.default_rng(8)
    D = rng.uniform(0.05, 2.0, 200)
    c = rng.uniform(0.0, 4.0, D.size)
    delta = rng.uniform(0.0, 1.0, D.size)
    margin = release_margin(D, c, delta)
    sticks = linear_release(D, c, delta).sticks
    clear = np.abs(margin) > 1e-9
    assert np.array_equal((margin > 0)[clear], sticks[clear])


def test_linear_release_needs_a_threshold():
    with pytest.raises(ValueError, match="force or the position threshold"):
        linear_release(np.ones(1), np.zeros(1), np.zeros(1), force=False, position=False)


# -- far over-damped: against mpmath at 50 digits ---------------------------------------------


def _mp_release(D, c, delta):
    """First release of z'' + 2 D z' + z = c, z(0) = 0, z'(0) = 1 (D > 1) at
    2 D z' + z + delta <= 0 or z <= 0: ``(tau_c, -z'(tau_c))`` at 50 digits, or ``None``.

    The exponential solution is solved from its initial values by mpmath; both thresholds
    are scanned on a logarithmic grid over the fast and slow time scales, and the first
    sign change is polished by mpmath's root finder."""
    with mp.workdps(50):
        D, c, delta = mp.mpf(D), mp.mpf(c), mp.mpf(delta)
        mu = mp.sqrt(D * D - 1)
        rates = (D - mu, D + mu)  # exact enough at 50 digits
        a, b = mp.lu_solve(mp.matrix([[1, 1], [-rates[0], -rates[1]]]), mp.matrix([-c, 1]))

        def z(t):
            return c + a * mp.exp(-rates[0] * t) + b * mp.exp(-rates[1] * t)

        def v(t):
            return -rates[0] * a * mp.exp(-rates[0] * t) - rates[1] * b * mp.exp(-rates[1] * t)

        def force(t):
            return 2 * D * v(t) + z(t) + delta

        grid = [mp.mpf(10) ** k / rates[1] for k in mp.linspace(-4, 2, 300)]
        grid += [mp.mpf(10) ** k * rates[1] for k in mp.linspace(-6, 1, 200)[1:]]
        first = None
        for fn in (force, z):
            values = [fn(t) for t in grid]
            for lo, hi, g_lo, g_hi in zip(grid, grid[1:], values, values[1:], strict=False):
                if g_lo > 0 >= g_hi:
                    root = mp.findroot(fn, (lo, hi), solver="anderson")
                    first = root if first is None else min(first, root)
                    break
        return None if first is None else (first, -v(first))


_FAR_D = [1.1, 1.5, 2.0, 10.0, 100.0, 1e3, 1581.0, 3e3, 1e4, 1e5]


def _far_cases():
    # loads and offsets as fractions of the depth of the unloaded force's dip below zero
    # (~ 1/(8 D^3); its minimum is where r_s^3 e^{-r_s tau} = r_f^3 e^{-r_f tau}): most
    # release, the last two stick
    cases = []
    for D in _FAR_D:
        fast = D + math.sqrt(D * D - 1.0)
        slow, w = 1.0 / fast, 2.0 * math.sqrt(D * D - 1.0)
        dip = slow**2 * math.exp(-slow * 6.0 * math.log(fast) / w) * (1.0 - slow / fast) / w
        for load, offset in (
            (0, 0),
            (0.3, 0),
            (0, 0.4),
            (0.2, 0.3),
            (0.9, 0),
            (0, 1.5),
            (1.1, 0.4),
        ):
            cases.append((D, load * dip, offset * dip))
    return cases


def test_far_over_damped_release_matches_mpmath():
    cases = _far_cases()
    D, c, delta = (np.array(x) for x in zip(*cases, strict=True))
    rel = linear_release(D, c, delta)
    margin = release_margin(D, c, delta)  # its sign decides sticking under a load
    released = 0
    for i, case in enumerate(cases):
        ref = _mp_release(*case)
        if ref is None:
            assert rel.sticks[i], case
            assert case[1] == 0 or margin[i] > 0, case
            continue
        released += 1
        assert margin[i] < 0, case
        assert rel.contact_time[i] == pytest.approx(float(ref[0]), rel=1e-12, abs=0), case
        assert rel.restitution[i] == pytest.approx(float(ref[1]), rel=1e-12, abs=0), case
        assert not rel.released_by_position[i]
    assert released >= 4 * len(_FAR_D)


def test_far_over_damped_force_condition_is_the_papers():
    # without load and offset: contact_time/restitution of the force condition
    D = np.array([2.0, 10.0, 100.0, 1e3, 1581.0, 3e3, 1e4, 1e5, 1e7])
    rel = linear_release(D, np.zeros_like(D), np.zeros_like(D))
    f = {"condition": "force"}
    np.testing.assert_allclose(rel.contact_time, contact_time(D, 0.0, **f), rtol=1e-13)
    np.testing.assert_allclose(rel.restitution, restitution(D, 0.0, **f), rtol=1e-13)


def test_over_damped_forms_join_without_a_step():
    # the kernel's closed form (D <= 2) and the two-mode form (D > 2) meet continuously
    D = np.array([2.0, np.nextafter(2.0, 3.0)])
    for load, offset in ((0.0, 0.0), (1e-3, 0.0), (0.0, 2e-3), (0.5, 0.2)):
        rel = linear_release(D, np.full(2, load), np.full(2, offset))
        assert rel.contact_time[1] == pytest.approx(rel.contact_time[0], rel=1e-13)
        assert rel.restitution[1] == pytest.approx(rel.restitution[0], rel=1e-13)
        assert rel.max_penetration[1] == pytest.approx(rel.max_penetration[0], rel=1e-13)
        assert rel.peak_force[1] == pytest.approx(rel.peak_force[0], rel=1e-13)
        margin = release_margin(D, np.full(2, load), np.full(2, offset))
        assert margin[1] == pytest.approx(margin[0], rel=1e-12, abs=1e-15)


def test_first_crossing_of_any_level_from_any_state_matches_mpmath():
    # the general crossing (engines' passages start anywhere, levels of both signs): the
    # first tau with level + h(tau) <= 0, against mpmath's root of the closed form
    # (e^{-D t}(h0 cos + (h1 + D h0) sin / mu), cosh/sinh above D = 1) bracketed by a
    # dense scan of its own
    from impactsym.contact.release import first_crossing, homogeneous_modes

    rng = np.random.default_rng(17)
    n = 60
    D = np.concatenate([rng.uniform(0.0, 5.0, n - 4), [1.0, 2.0, 0.3, 3.0]])
    h0, h1 = rng.normal(0, 1, D.size), rng.normal(0, 1, D.size)
    level = rng.normal(0, 1, D.size)
    level = np.where(level + h0 > 0, level, -h0 + np.abs(level))  # starts above
    level[-2:] = [-0.2, -0.4]  # negative levels: the over-damped tail at D = 3
    h0[-2:], h1[-2:] = [0.5, 0.9], [-0.1, 0.3]
    # level 0 next to critical damping: the zero of h from the arctanh series (its first
    # term alone missed by 3e-7 relative at D = 1 + 1e-7)
    near = np.array([1 + 1e-7, 1 + 1e-9, 1 + 1e-5, 1 - 1e-7])
    D = np.concatenate([D, near])
    level = np.concatenate([level, np.zeros(near.size)])
    h0, h1 = np.concatenate([h0, np.full(near.size, 1.0)]), np.concatenate([h1, [-2.0] * 4])
    tau = first_crossing(D, level, h0, h1, homogeneous_modes(D, h0, h1),
                         exclude_start=np.zeros(D.size, bool))  # fmt: skip
    mp.mp.dps = 30
    for i in range(D.size):
        d, a, b, lv = (mp.mpf(float(x[i])) for x in (D, h0, h1, level))
        mu = mp.sqrt(abs(1 - d * d))

        def g(t, d=d, a=a, b=b, lv=lv, mu=mu):
            if d < 1:
                s = mp.sin(mu * t) / mu
                c = mp.cos(mu * t)
            elif d == 1:
                s, c = t, mp.mpf(1)
            else:
                s, c = mp.sinh(mu * t) / mu, mp.cosh(mu * t)
            return lv + mp.exp(-d * t) * (a * c + (b + d * a) * s)

        grid = [mp.mpf(k) / 50 for k in range(1, 50 * 60)]
        prev, found = mp.mpf(0), None
        for t in grid:
            if g(t) <= 0:
                found = mp.findroot(g, (prev, t), solver="anderson")
                break
            prev = t
        if found is None:
            assert tau[i] == np.inf or tau[i] > 60.0, i
        else:
            assert tau[i] == pytest.approx(float(found), rel=1e-11), i


@pytest.mark.parametrize("D", [1 + 1e-9, 1 + 1e-7, 1 + 1e-5, 1 - 1e-7])
def test_paper_force_condition_next_to_critical_damping_matches_mpmath(D):
    # z = e^{-D t} sinh(mu t)/mu (sin below D = 1), released where 2 D z' + z = 0
    mp.mp.dps = 40
    d = mp.mpf(D)
    mu = mp.sqrt(abs(1 - d * d))
    if d > 1:
        z = lambda t: mp.exp(-d * t) * mp.sinh(mu * t) / mu  # noqa: E731
    else:
        z = lambda t: mp.exp(-d * t) * mp.sin(mu * t) / mu  # noqa: E731
    force = lambda t: 2 * d * mp.diff(z, t) + z(t)  # noqa: E731
    ref = mp.findroot(force, mp.mpf(2))
    got = float(linear_release(D, 0.0, 0.0).contact_time)
    assert got == pytest.approx(float(ref), rel=1e-13)
