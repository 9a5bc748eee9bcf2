"""The phase means of a Drake contact whose end state changes once, where the size puts
the change: the equations of the table's designs by contact time.

Checked against what did not make them: ``phase_summary``, which samples the phases,
searches for the change and integrates its own pieces.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import drake
from impactsym.engines.drake import design, step_table
from impactsym.engines.drake import jump_means as jump_means_module
from impactsym.engines.drake.jump_means import jump_holds, jump_means, last_overlap
from impactsym.engines.drake.phases import phase_summary
from impactsym.engines.drake.step_table import MIN_TARGETS, stepped_designs

H = 1e-3


def _meet_targets(k, d, e, size_name, size):
    """A fresh prediction of the designs ``(k, d)`` (0.1 kg at 1 m/s, no gravity) meets
    the restitutions ``e`` to 1e-12 and the sizes to 1e-10 relative."""
    p = drake.predict(stiffness=k, dissipation=d, mass=0.1, speed=1.0, time_step=H)
    np.testing.assert_allclose(p.restitution, e, rtol=0, atol=1e-12)
    np.testing.assert_allclose(getattr(p, size_name), size, rtol=1e-10)


def _contacts(n, gravity, seed, *, steps=(5.0, 60.0), h=H):
    """Random contacts of 5-60 ``steps``, damping numbers d v of 0-3, and their exact means
    (those that do not stick at any phase)."""
    rng = np.random.default_rng(seed)
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    w = np.pi / rng.uniform(*steps, n)  # the step in units of sqrt(m/k)
    k, d, g = m * (w / h) ** 2, rng.uniform(0.0, 3.0, n) / v, np.full(n, gravity)
    exact = phase_summary(k, d, 0.0, m, g, v, h, approximation="lagged", bounds=False)
    free = np.isfinite(exact.contact_time)
    return [a[free] for a in (k, d, m, g, v)], (exact.restitution[free], exact.contact_time[free])


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_at_the_change_the_means_are_the_searched_ones(gravity):
    rows, (e, t) = _contacts(1500, gravity, 11)
    q = t / H
    held = jump_holds(*rows, H, q)
    assert held.mean() > 0.75  # most contacts change their end state once
    r = jump_means(*rows, H, q)
    np.testing.assert_allclose(r.restitution[held], e[held], rtol=0,
                               atol=5e-14)  # fmt: skip
    np.testing.assert_allclose(r.size[held], q[held], rtol=0, atol=1e-11)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_off_the_change_the_means_are_right_to_second_order(gravity):
    # the target puts the change delta away from where it lies: the estimates miss the
    # searched means by O(delta^2), about 5 delta^2 in the size (steps), 0.1 delta^2 in e
    # (the restitution is continuous at the change without gravity; under it, the
    # offset's share h g/v per phase counts)
    rows, (e, t) = _contacts(1500, gravity, 12)
    q = t / H
    phi = q - 0.5 - np.floor(q - 0.5)
    held = jump_holds(*rows, H, q) & (phi > 0.05) & (phi < 0.95)
    assert held.sum() > 900
    for delta in (1e-2, 1e-3, 1e-4):
        r = jump_means(*rows, H, q + delta)
        assert np.max(np.abs(r.size - q)[held]) < 20.0 * delta**2
        assert np.max(np.abs(r.restitution - e)[held]) < 0.5 * delta**2 + 1e-13
        # first order would be off: the offset's share matters
        assert np.median(np.abs(r.size - q - delta)[held]) > 0.5 * delta


def test_the_structure_is_refused_where_it_does_not_hold():
    rows, (_, t) = _contacts(400, 0.0, 13)
    q = t / H
    held = jump_holds(*rows, H, q)
    # the change put a third of a phase away: a grid phase between sees the other end
    moved = jump_holds(*rows, H, np.where(q - np.floor(q) < 0.5, q + 0.3, q - 0.3))
    assert held.mean() > 0.75
    assert not moved[held].any()
    # a heavily damped contact under gravity that sticks at every phase
    one = np.ones(1)
    assert not jump_holds(1e3 * one, 50.0 * one, one, 9.81 * one, 0.1 * one, H, 30.5 * one)[0]


@pytest.mark.parametrize("jump", [True, False])
def test_designs_by_contact_time_from_the_change_or_the_searched_means(jump, monkeypatch):
    rng = np.random.default_rng(14)
    n = MIN_TARGETS
    e, t = rng.uniform(0.3, 0.6, n), rng.uniform(2e-2, 4e-2, n)
    calls = []

    def holds(*args, **check):
        calls.append(args[0].size)
        return jump_holds(*args, **check) & jump

    monkeypatch.setattr(step_table, "jump_holds", holds)
    one = np.ones(n)
    ok, k, d, _ = stepped_designs(e, one, 0.1 * one, 0 * one, t, H, "lagged", "contact_time")
    assert calls[0] > 0.9 * n  # the change's equations met nearly every target
    assert ok.mean() > 0.9
    _meet_targets(k[ok], d[ok], e[ok], "contact_time", t[ok])


def test_the_change_s_jacobian_lets_a_design_converge_in_few_evaluations(monkeypatch):
    # from the differences of the cheap rule Broyden's steps converge by ~1e3 each (the
    # table's cell, across the kinks, gives ~1e2: about 6 evaluations a design)
    rng = np.random.default_rng(15)
    n = 4 * MIN_TARGETS
    e, t = rng.uniform(0.3, 0.6, n), rng.uniform(2e-2, 4e-2, n)
    sizes = {"full": 0, "cheap": 0}

    def spy(*args, **rule):
        sizes["cheap" if rule else "full"] += args[0].size
        return jump_means(*args, **rule)

    monkeypatch.setattr(step_table, "jump_means", spy)
    one = np.ones(n)
    ok, _, _, _ = stepped_designs(e, one, 0.1 * one, 0 * one, t, H, "lagged", "contact_time")
    assert ok.mean() > 0.95
    assert sizes["full"] < 5.0 * n
    assert sizes["cheap"] <= 3 * n  # one start and two differences each


@pytest.mark.parametrize(("gravity", "step"), [(0.0, 1e-3), (9.81, 1e-3), (50.0, 1e-4)])
def test_the_last_grid_phase_overlaps_deepest(gravity, step):
    # the phase summary's largest overlap (sampled at its grid and nodes) is that of the
    # last grid phase: the deepest free penetration before the first force (measured on
    # 12000 random contacts, no exception); jump_holds checks it at the phases it runs
    rng = np.random.default_rng(16)
    n = 1500
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    k = m * (np.pi / rng.uniform(5.0, 100.0, n) / step) ** 2
    d, g = rng.uniform(0.0, 4.0, n) / v, np.full(n, gravity)
    exact = phase_summary(k, d, 0.0, m, g, v, step, approximation="lagged", bounds=False)
    free = np.isfinite(exact.contact_time)
    assert free.mean() > 0.15
    last = last_overlap(k, d, m, g, v, step)
    np.testing.assert_array_equal(last[free], exact.max_penetration[free])
    assert np.all(np.isfinite(last[free]))
    q = exact.contact_time / step
    held = jump_holds(*(a[free] for a in (k, d, m, g, v)), step, q[free], deepest_last=True)
    assert held.mean() > 0.75


def test_designs_by_largest_overlap_on_a_plateau_of_the_contact_time(monkeypatch):
    # targets whose designs last the same number of steps at every phase (no change of
    # the end state in the phase interval): the mean is one end state's integral
    rng = np.random.default_rng(17)
    n = 3000
    m, v = np.full(n, 0.1), np.ones(n)
    w, s = np.pi / rng.uniform(20.0, 40.0, n), rng.uniform(0.3, 1.5, n)
    k, d = m * (w / H) ** 2, s / v
    exact = phase_summary(k, d, 0.0, m, 0 * m, v, H, approximation="lagged", bounds=False)
    q = exact.contact_time / H
    flat = np.abs(q - 0.5 - np.rint(q - 0.5)) < 1e-12
    on = np.flatnonzero(flat)[: MIN_TARGETS // 2]
    pick = np.concatenate([on, np.flatnonzero(~flat)[: MIN_TARGETS - on.size]])
    assert np.count_nonzero(flat[pick]) > 40
    e, x = exact.restitution[pick], exact.max_penetration[pick]
    calls = []

    def holds(*args, **check):
        calls.append((args[-1], jump_holds(*args, **check)))
        return calls[-1][1]

    monkeypatch.setattr(step_table, "jump_holds", holds)
    one = np.ones(pick.size)
    ok, k_d, d_d, _ = stepped_designs(e, one, 0.1 * one, 0 * one, x, H, "lagged", "max_penetration")
    change, held = calls[0]
    assert np.count_nonzero(held & (change == np.rint(change - 0.5) + 0.5)) > 20  # plateaus
    assert ok.mean() > 0.95
    _meet_targets(k_d[ok], d_d[ok], e[ok], "max_penetration", x[ok])


def test_a_table_design_that_misses_is_designed_again(monkeypatch):
    # the prediction is the arbiter: a table design off its target (here made so) is
    # replaced by the exact iteration's
    rng = np.random.default_rng(18)
    e, t = rng.uniform(0.3, 0.6, MIN_TARGETS), rng.uniform(2e-2, 4e-2, MIN_TARGETS)

    def off(*args):
        ok, k, d, summaries = stepped_designs(*args)
        k[:3] *= 1.001
        summaries[:, :3] = np.nan  # (they were the designs' before)
        return ok, k, d, summaries

    monkeypatch.setattr(design, "stepped_designs", off)
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1,
                                time_step=H)  # fmt: skip
    np.testing.assert_allclose(c.restitution, e, rtol=0, atol=2e-12)
    np.testing.assert_allclose(c.contact_time, t, rtol=2e-10)
    alone = drake.point_contact_for(restitution=e[:3], contact_time=t[:3], speed=1.0, mass=0.1,
                                    time_step=H)  # fmt: skip
    np.testing.assert_array_equal(c.point_contact_stiffness[:3], alone.point_contact_stiffness)


def test_designs_on_a_plateau_s_edge_under_gravity():
    # contact times of exactly N + 1/2 steps put the change at phase 0; where the design's
    # estimate lies below it every phase ends at B and the offset adds nothing to the
    # restitution (unclipped it missed by 1.5e-12 at e = 0.2126, t = 0.0425 s, v = 1;
    # found by review)
    rng = np.random.default_rng(19)
    n = 2 * MIN_TARGETS
    e = rng.uniform(0.2, 0.6, n)
    t = (rng.integers(20, 45, n) + 0.5) * H
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1,
                                gravity=9.81, time_step=H)  # fmt: skip
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=0.1, speed=1.0, gravity=9.81, time_step=H)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p.contact_time, t, rtol=1e-10)
    # where the change's structure holds its means are the prediction's (elsewhere two
    # changes near 0 and 1 share the phase interval: those came from the exact steps)
    one = np.ones(n)
    rows = (c.point_contact_stiffness, c.hunt_crossley_dissipation, 0.1 * one, 9.81 * one, one)
    held = jump_holds(*rows, H, t / H)
    assert held.sum() > n // 4
    r = jump_means(*rows, H, t / H)
    np.testing.assert_allclose(r.restitution[held], p.restitution[held], rtol=0, atol=2e-13)


def test_below_a_plateau_s_edge_the_offset_adds_nothing():
    # the design of a target of exactly 42.5 steps under gravity (found by review): its
    # change lies 1.6e-10 of a phase below 0, so every phase ends at state 42 and the
    # mean is that state's integral; the offset's share unclipped added 1.56e-12
    k, d, m, g, v, q = 942.1623157116445, 2.380937093254077, 0.1, 9.81, 1.0, 42.5
    rows = [np.array([x]) for x in (k, d, m, g, v)]
    r = jump_means(*rows, H, np.array([q]))
    assert -1e-9 < r.size[0] - q < 0.0  # the change's estimate: just below phase 0
    assert jump_holds(*rows, H, np.array([q]))[0]
    exact = phase_summary(k, d, 0.0, m, g, v, H, approximation="lagged", bounds=False)
    assert abs(r.restitution[0] - exact.restitution) < 1e-13


def test_designs_of_short_contacts_by_largest_overlap_step_no_far_states(monkeypatch):
    # next to a plateau the margin is flat and the change's estimate has huge slopes:
    # moved along them unclipped it put states 10^5 steps on (a call of 600 targets of
    # 3.6-14.5 steps took 54 s instead of 0.4; found by review)
    rng = np.random.default_rng(20)
    n = 600
    m, v = 10 ** rng.uniform(-2, 1, n), rng.uniform(0.1, 5, n)
    w = np.pi / np.exp(rng.uniform(np.log(3), np.log(10), n)) * rng.uniform(0.7, 1, n)
    p = drake.predict(stiffness=m * (w / H) ** 2, dissipation=rng.uniform(0.3, 4, n) / v,
                      mass=m, speed=v, time_step=H)  # fmt: skip
    keep = np.isfinite(p.contact_time) & (p.restitution > 0.05)
    assert keep.sum() >= MIN_TARGETS
    deepest = [0]
    states = jump_means_module.end_state

    def spy(*args, **options):
        deepest[0] = max(deepest[0], int(np.max(args[-1])))
        return states(*args, **options)

    monkeypatch.setattr(jump_means_module, "end_state", spy)
    e, x = p.restitution[keep], p.max_penetration[keep]
    c = drake.point_contact_for(restitution=e, max_penetration=x, speed=v[keep], mass=m[keep],
                                time_step=H)  # fmt: skip
    assert 0 < deepest[0] <= 2 * np.max(p.contact_time[keep]) / H
    np.testing.assert_allclose(c.restitution, e, rtol=0, atol=1e-12)
    np.testing.assert_allclose(c.max_penetration, x, rtol=1e-10)


def _poly(c, p):
    """The polynomials of coefficients ``c`` (a row each, lowest first) at ``p`` (rows)."""
    return (c[:, None, :] * p[:, :, None] ** np.arange(c.shape[1])).sum(axis=2)


def test_the_rule_integrates_polynomials_of_its_degree_on_each_piece():
    # the shorter piece (at most half a phase) one Gauss panel of `nodes`, the longer one
    # of nodes + 2: exact to degrees 2 nodes - 1 and 2 nodes + 3 (the former layout, the
    # longer piece halved into two panels of `nodes`, is not exact to the latter)
    rng = np.random.default_rng(21)
    phi = np.concatenate([rng.random(300), [0.0, 0.25, 0.5, 0.75, 1.0 - 1e-12]])
    base = rng.integers(10, 60, phi.size)
    for nodes in (1, 5, 10):
        width = 2 * nodes + 2
        phases, weights, states = jump_means_module._layout(phi, base, nodes)
        assert phases.shape == weights.shape == states.shape == (phi.size, width)
        first = states == base[:, None] + 1  # the piece [0, phi*], then [phi*, 1] at B
        count = np.where(phi > 0.5, nodes + 2, nodes)
        np.testing.assert_array_equal(first, np.arange(width) < count[:, None])
        np.testing.assert_array_equal(
            states[~first], np.broadcast_to(base[:, None], first.shape)[~first]
        )
        assert np.all(np.where(first, phases <= phi[:, None], phases >= phi[:, None]))
        assert np.all(np.diff(phases, axis=1) >= 0.0)
        # a random polynomial per piece, of the degree its panel integrates exactly
        powers = np.arange(2 * nodes + 4)
        c0, c1 = rng.normal(size=(2, phi.size, powers.size))
        c0[powers > 2 * count[:, None] - 1] = 0.0
        c1[powers > 2 * (width - count)[:, None] - 1] = 0.0
        values = np.where(first, _poly(c0, phases), _poly(c1, phases))
        # the antiderivatives: p P(p) with the coefficients over k + 1
        a0, a1 = c0 / (powers + 1), c1 / (powers + 1)
        ends = np.column_stack([phi, np.ones_like(phi)])
        at = _poly(a0, ends[:, :1])[:, 0] * phi, _poly(a1, ends) * ends
        exact = at[0] + at[1][:, 1] - at[1][:, 0]
        np.testing.assert_allclose((weights * values).sum(axis=1), exact, rtol=0, atol=1e-13)


def _fine_integrals(rows, h, q):
    """The two pieces' integrals (state ``B + 1`` on ``[0, phi*]``, ``B`` on ``[phi*,
    1]``) by 8 equal panels of 8 Gauss-Legendre nodes each, from ``end_state`` alone."""
    k, d, m, g, v = rows
    base = np.floor(q - 0.5)
    phi, base = q - 0.5 - base, base.astype(np.int64)
    x, w = np.polynomial.legendre.leggauss(8)
    u01 = ((np.arange(8)[:, None] + 0.5 * (x + 1.0)) / 8).ravel()  # 64 points on [0, 1]
    w01 = np.tile(w / 16, 8)
    total = np.zeros(phi.size)
    r = np.repeat(np.arange(phi.size), u01.size)
    for a, b, state in ((0.0 * phi, phi, base + 1), (phi, 0.0 * phi + 1.0, base)):
        p = (a[:, None] + (b - a)[:, None] * u01).ravel()
        steps = np.repeat(state, u01.size)
        _, u, _, _ = jump_means_module.end_state(k[r], d[r], m[r], g[r], v[r], h, p, steps)
        total += (b - a) * ((-u / v[r]).reshape(phi.size, u01.size) @ w01)
    return total


@pytest.mark.parametrize(("gravity", "step"), [(0.0, 1e-3), (9.81, 1e-3), (9.81, 1e-4)])
def test_the_tables_rule_meets_a_fine_reference(gravity, step):
    # 5 nodes on the shorter piece, 7 on the longer (the change tables' rule, 12 runs)
    # on contacts of 10-20 steps at their own mean (the shortest the tables take, where
    # the rule does worst): the pieces' integrals to 1e-15 of 8 x 8 nodes a piece
    # (measured 7e-16 here, 1.9e-15 over 2*10^4 designs of 10-70 steps; the former 5
    # nodes on each of three panels, 15 runs: 2.5e-15 here, 4 on each 3.6e-13)
    rows, (_, t) = _contacts(2000, gravity, 22, steps=(10.0, 20.0), h=step)
    q = t / step
    held = jump_holds(*rows, step, q) & (q >= 10.0)
    assert held.sum() > 700
    rows, q = tuple(a[held] for a in rows), q[held]
    fine = _fine_integrals(rows, step, q)
    np.testing.assert_allclose(jump_means(*rows, step, q, nodes=5).fixed, fine, rtol=0, atol=1e-15)
    np.testing.assert_allclose(jump_means(*rows, step, q).fixed, fine, rtol=0, atol=1e-15)
