"""The loaded section-2 oscillator (impactsym.contact.release) against independent references."""

from __future__ import annotations

import math

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
