"""The whole phase summary of a Drake contact whose end state changes once, from one
evaluation of the change's equations and the phase grid (``jump_summary``).

Checked against what did not make it: ``phase_summary``, which samples its own grid,
searches for the change by the end margin's root, integrates quarter pieces with
7 nodes and searches its own interior extremes; and, where their bounds differ,
the contacts run at 2^16 phases.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import drake
from impactsym.engines.drake import jump_means as jump_means_module
from impactsym.engines.drake import jump_range, phases
from impactsym.engines.drake.jump_means import jump_holds, jump_summary
from impactsym.engines.drake.phases import phase_summary
from impactsym.engines.drake.stepping import contact_ends, end_state

_RELATIVE = ("contact_time", "contact_time_min", "contact_time_max")


def _designs(n, gravity, step, seed):
    """Designs ``(k, d)`` of 0.1 kg at 1 m/s for random reachable targets of 3-60 steps
    (``point_contact_for``), and their target contact times; targets it refuses (rare)
    are dropped (halving the batch until the rest are met)."""
    rng = np.random.default_rng(seed)
    steps = np.exp(rng.uniform(np.log(3.0), np.log(60.0), n))
    k0 = 0.1 * (np.pi / (steps * step)) ** 2
    e0 = drake.predict(stiffness=k0, dissipation=0.0, mass=0.1, speed=1.0, gravity=gravity,
                       time_step=step).restitution  # fmt: skip
    # (strongly damped contacts of under 5 steps are often out of reach, and those of
    # under 3 without gravity: test_random_short_contacts_at_their_means has them)
    frac = rng.uniform(np.where(steps < 5.0, 0.45, 0.1), 0.95)
    e, t = frac * np.minimum(e0, 0.97), steps * step

    def solve(i):
        try:
            c = drake.point_contact_for(restitution=e[i], contact_time=t[i], speed=1.0,
                                        mass=0.1, gravity=gravity, time_step=step)  # fmt: skip
        except ValueError:
            if i.size == 1:
                return []
            return solve(i[: i.size // 2]) + solve(i[i.size // 2 :])
        return [(np.atleast_1d(c.point_contact_stiffness),
                 np.atleast_1d(c.hunt_crossley_dissipation), t[i])]  # fmt: skip

    k, d, t = (np.concatenate(a) for a in zip(*solve(np.arange(n)), strict=True))
    return k, d, t


def _agree(s, held, exact, rows, step):
    """``jump_summary``'s fields ``s`` equal ``phase_summary``'s where ``held``; where a
    restitution bound is further out than ``phase_summary``'s (its sampled bound of a
    smooth extreme lying next to its quarters' ends), the dense phases confirm ours."""
    assert np.all(np.isfinite(exact.contact_time[held]))
    assert np.all(s.stick_fraction[held] == 0.0)
    assert np.all(exact.stick_fraction[held] == 0.0)
    np.testing.assert_allclose(s.restitution[held], exact.restitution[held], rtol=0, atol=1e-13)
    for name in _RELATIVE:
        np.testing.assert_allclose(getattr(s, name)[held], getattr(exact, name)[held],
                                   rtol=1e-12, atol=0)  # fmt: skip
    np.testing.assert_allclose(s.max_penetration[held], exact.max_penetration[held],
                               rtol=1e-15, atol=0)  # fmt: skip
    lo, hi = s.restitution_min, s.restitution_max
    assert np.all(lo[held] <= exact.restitution_min[held] + 1e-12)
    assert np.all(hi[held] >= exact.restitution_max[held] - 1e-12)
    out = np.flatnonzero(held & ((lo < exact.restitution_min - 1e-12) |
                                 (hi > exact.restitution_max + 1e-12)))  # fmt: skip
    assert out.size <= max(2, held.sum() // 50)
    if out.size:
        p = (np.arange(2**16) + 0.5) / 2**16
        dense = contact_ends(*(a[out, None] for a in rows), step, p[None, :])
        np.testing.assert_allclose(lo[out], dense.restitution.min(axis=1), rtol=0, atol=1e-12)
        np.testing.assert_allclose(hi[out], dense.restitution.max(axis=1), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("gravity", "step"), [(0.0, 1e-3), (9.81, 1e-3), (0.0, 1e-4),
                                               (9.81, 1e-4)])  # fmt: skip
def test_at_and_near_designs_the_summary_is_the_searched_one(gravity, step):
    k, d, t = _designs(32, gravity, step, 31 + int(gravity))
    one = np.ones(k.size)
    rows = (k, d, 0.1 * one, gravity * one, one)
    exact = phase_summary(k, d, 0.0, 0.1, gravity, 1.0, step, approximation="lagged")
    # at the design (the size the design meets) and near it (the exact mean's size)
    for q in (t / step, exact.contact_time / step):
        s, held = jump_summary(*rows, step, q)
        assert held.mean() > 0.6
        _agree(s, held, exact, rows, step)
        assert np.all(np.isnan(s.restitution[~held]))
        with_depth, held_deep = jump_summary(*rows, step, q, deepest_last=True)
        assert np.all(held_deep <= held)
        assert held_deep.mean() > 0.6
        np.testing.assert_array_equal(with_depth.max_penetration[held_deep],
                                      exact.max_penetration[held_deep])  # fmt: skip


@pytest.mark.parametrize(("gravity", "seed"), [(0.0, 32), (9.81, 33)])
def test_random_short_contacts_at_their_means(gravity, seed):
    # 2-12 steps, damping numbers d v up to 6: q from the contact's own phase mean
    rng = np.random.default_rng(seed)
    n, step = 1500, 1e-3
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    k = m * (np.pi / np.exp(rng.uniform(np.log(2.0), np.log(12.0), n)) / step) ** 2
    d, g = rng.uniform(0.0, 6.0, n) / v, np.full(n, gravity)
    exact = phase_summary(k, d, 0.0, m, g, v, step, approximation="lagged")
    q = np.where(np.isfinite(exact.contact_time), exact.contact_time / step, 5.3)
    s, held = jump_summary(k, d, m, g, v, step, q)
    assert held.sum() > 300
    _agree(s, held, exact, (k, d, m, g, v), step)
    # at least as strict as the structure's grid check
    assert np.all(held <= jump_holds(k, d, m, g, v, step, q))


def test_on_a_plateau_s_edge_every_phase_ends_alike():
    # the design of exactly 42.5 steps under gravity (test_engines_drake_jump_means): its
    # change lies 1.6e-10 of a phase below 0, every phase ends at state 42
    k, d, m, g, v, h = 942.1623157116445, 2.380937093254077, 0.1, 9.81, 1.0, 1e-3
    rows = [np.array([x]) for x in (k, d, m, g, v)]
    s, held = jump_summary(*rows, h, np.array([42.5]))
    assert held[0]
    exact = phase_summary(*rows[:2], 0.0, *rows[2:], h, approximation="lagged")
    _agree(s, held, exact, rows, h)


def test_the_structure_is_refused_where_it_does_not_hold():
    one = np.ones(1)
    # a loaded contact that sticks
    assert not jump_summary(1e3 * one, 50.0 * one, one, 9.81 * one, 0.1 * one, 1e-3,
                            30.5 * one)[1][0]  # fmt: skip
    # the change put a third of a phase from where it lies (contacts of 5-60 steps)
    rng = np.random.default_rng(34)
    n = 300
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    k = m * (np.pi / rng.uniform(5.0, 60.0, n) / 1e-3) ** 2
    rows = (k, rng.uniform(0.0, 3.0, n) / v, m, np.zeros(n), v)
    exact = phase_summary(*rows[:2], 0.0, *rows[2:], 1e-3, approximation="lagged", bounds=False)
    q = exact.contact_time / 1e-3
    assert jump_summary(*rows, 1e-3, q)[1].mean() > 0.6
    moved = np.where(q - np.floor(q) < 0.5, q + 0.3, q - 0.3)
    assert not jump_summary(*rows, 1e-3, moved)[1].any()
    # a hidden pair: the end state 4 dips to 3 over phases 0.3258-0.3607 (found by
    # review), between two grid phases; at its own mean the grid refuses it, and at
    # q = 4.5 (every phase ending at 4) the grid and the nodes next to the change take
    # it (jump_holds) where the margins between the nodes do not
    k, d, m, g, v, h = 1246279.851682075, 3.5044304066552017, 1.0, 9.81, 1.0, 1e-3
    rows = [np.array([x]) for x in (k, d, m, g, v)]
    dense = contact_ends(k, d, m, g, v, h, (np.arange(2**16) + 0.5) / 2**16)
    assert np.count_nonzero(np.diff(np.rint(dense.contact_time / h))) >= 2
    exact = phase_summary(k, d, 0.0, m, g, v, h, approximation="lagged")
    s, held = jump_summary(*rows, h, np.array([exact.contact_time / h]))
    assert not held[0]
    assert np.isnan(s.restitution[0])
    assert jump_holds(*rows, h, np.array([4.5]))[0]
    assert not jump_summary(*rows, h, np.array([4.5]))[1][0]


def test_a_summary_costs_one_evaluation_and_the_grid(monkeypatch):
    # updates stepped per contact (states of end_state, end_margin; contact runs to
    # their end state) on contacts of 20-40 steps at their own mean: one evaluation
    # (24 states: 10 + 12 nodes and 2 at phi*, state B + 1 there one update on from B),
    # one side at the change (the other one update on) and the grid (9 runs), about 34
    # contact lengths; phase_summary's search, pieces and checks about 57
    rng = np.random.default_rng(35)
    n, step = 300, 1e-3
    m, v = np.full(n, 0.1), np.ones(n)
    k = m * (np.pi / rng.uniform(20.0, 40.0, n) / step) ** 2
    d, g = rng.uniform(0.0, 1.5, n), np.zeros(n)
    count = [0]

    def runs(f):
        def spy(*args, **kwargs):
            r = f(*args, **kwargs)
            ends = np.rint(r.contact_time / args[5] - args[6])
            count[0] += int(np.where(np.isfinite(ends), ends + 1, 0).sum())
            return r

        return spy

    def states(f):
        def spy(*args, **options):  # (ends: the state's end test, one update more)
            steps = np.broadcast_to(args[-1], np.shape(args[6])) + options.get("ends", False)
            count[0] += int(np.sum(steps))
            return f(*args, **options)

        return spy

    def ended(f):  # (the grid: to the state expected to end it, and one update on)
        def spy(*args):
            count[0] += int(np.sum(np.broadcast_to(args[-1], np.shape(args[6])) + 1))
            return f(*args)

        return spy

    monkeypatch.setattr(phases, "contact_ends", runs(contact_ends))
    monkeypatch.setattr(phases, "end_margin", states(phases.end_margin))
    monkeypatch.setattr(jump_means_module, "contact_ends", runs(contact_ends))
    monkeypatch.setattr(jump_means_module, "end_state", states(jump_means_module.end_state))
    monkeypatch.setattr(jump_means_module, "ended_at", ended(jump_means_module.ended_at))
    exact = phase_summary(k, d, 0.0, m, g, v, step, approximation="lagged")
    full, count[0] = count[0], 0
    _, held = jump_summary(k, d, m, g, v, step, exact.contact_time / step)
    assert held.mean() > 0.9
    length = np.mean(exact.contact_time) / step
    # measured: 34.5 contact lengths, 34.0 before the nodes' end test was one update
    # more in their runs (instead of two root evaluations each, uncounted; 35.7 with
    # three panels of 8 nodes, 37.7 before)
    assert count[0] < 35.0 * length * n
    assert count[0] < 0.62 * full  # measured: 1040 updates per contact against 1727


def _dense_range(rows, h, base, change):
    """Least and largest restitution over the two pieces ``[0, change]`` (state ``B +
    1``) and ``[change, 1)`` (state ``B``) of each contact, from the states themselves
    (``end_state``): 1025 phases per piece, then 12 rounds of 9 phases around the best
    (the bracket 4 times narrower each), to about ``1e-10`` of a phase."""
    n = base.size
    lo, hi = np.full(n, np.inf), np.full(n, -np.inf)
    one = np.ones(9)
    for state, (a0, c0) in ((base + 1, (np.zeros(n), change)),
                            (base, (change, np.full(n, 1.0 - 1e-15)))):  # fmt: skip
        for sign in (-1.0, 1.0):

            def f(p, state=state, sign=sign):
                steps = np.broadcast_to(state[:, None], p.shape).ravel()
                _, u, _, _ = end_state(*(a[:, None] for a in rows), h, p, steps)
                return sign * -u.reshape(p.shape) / rows[4][:, None]

            p = a0[:, None] + (c0 - a0)[:, None] * np.linspace(0.0, 1.0, 1025)
            val = f(p)
            best = val.max(axis=1)
            width = (c0 - a0) / 1024
            for _ in range(12):
                mid = np.take_along_axis(p, np.argmax(val, axis=1)[:, None], axis=1)[:, 0]
                p = np.clip(mid[:, None] + width[:, None] * np.linspace(-1.0, 1.0, 9),
                            a0[:, None] * one, c0[:, None] * one)  # fmt: skip
                val = f(p)
                best = np.fmax(best, val.max(axis=1))
                width = width / 4
            if sign < 0:
                lo = np.fmin(lo, -best)
            else:
                hi = np.fmax(hi, best)
    return lo, hi


@pytest.mark.parametrize(("step", "speed"), [(1e-3, 1.0), (1e-4, 0.1)])
def test_the_range_s_searches_reach_the_dense_extremes(step, speed, monkeypatch):
    # contacts of 20-40 steps at their own mean under gravity, 5 nodes per panel (the
    # change tables' designs; without gravity no search moved a bound of theirs: 0 of
    # 10^4; the same g h / v at the smaller step), whose interior extremes are searched
    # by parabolic steps from the samples: against the pieces' states at 1025 phases
    # refined to 1e-10 of a phase, where the search moved a bound and at 100 others
    rng = np.random.default_rng(36)
    n = 1500
    m, v = np.full(n, 0.1), np.full(n, speed)
    k = m * (np.pi / rng.uniform(20.0, 40.0, n) / step) ** 2
    d, g = rng.uniform(0.4, 3.0, n) / speed, np.full(n, 9.81)
    exact = phase_summary(k, d, 0.0, m, g, v, step, approximation="lagged", bounds=False)
    q = exact.contact_time / step
    s, held = jump_summary(k, d, m, g, v, step, q, nodes=5)
    assert held.mean() > 0.9
    bounds = {}
    for steps in (0, 1):  # the samples alone, one step
        monkeypatch.setattr(jump_range, "_STEPS", steps)
        r, _ = jump_summary(k, d, m, g, v, step, q, nodes=5)
        bounds[steps] = r.restitution_min, r.restitution_max
    moved = held & ((bounds[0][0] - s.restitution_min > 1e-13) |
                    (s.restitution_max - bounds[0][1] > 1e-13))  # fmt: skip
    assert moved.sum() >= 20
    check = np.flatnonzero(moved | np.isin(np.arange(n), rng.choice(np.flatnonzero(held), 100)))
    base = np.floor(q[check] - 0.5).astype(np.int64)
    change = s.contact_time_min[check] / step - base
    assert np.all(change > 0.0)
    lo, hi = _dense_range([a[check] for a in (k, d, m, g, v)], step, base, change)
    # never beyond the extreme (a sampled value), within 1e-14 of it
    for mine, dense, sign in ((s.restitution_min[check], lo, -1.0),
                              (s.restitution_max[check], hi, 1.0)):  # fmt: skip
        assert np.all(sign * (mine - dense) <= 2e-15)
        np.testing.assert_allclose(mine, dense, rtol=0, atol=1e-14)
    # (the check can fail: one step, or the samples alone, fall short)
    for steps in (0, 1):
        short = np.maximum(bounds[steps][0][check] - lo, hi - bounds[steps][1][check])
        assert short.max() > 1e-12


def test_no_contacts_give_empty_summaries():
    empty = np.zeros(0)
    s, held = jump_summary(*(empty,) * 5, 1e-3, empty, nodes=5)
    assert held.shape == (0,)
    assert s.stacked().shape == (8, 0)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_the_next_state_is_end_state_s_next_bit_for_bit(gravity):
    # the states B + 1 at phi* and at the change are one update on from state B, instead
    # of a run from touch: the very numbers of end_state's run, at any phase and step
    rng = np.random.default_rng(37)
    n = 4000
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    k = m * (np.pi / rng.uniform(2.0, 60.0, n) / 1e-3) ** 2
    d, g, phase = rng.uniform(0.0, 6.0, n) / v, np.full(n, gravity), rng.random(n)
    step = rng.integers(0, 70, n)  # (past the end too: free updates)
    d[:200] = 0.0  # (no damping: the update's other form)
    x, u, _, flat = end_state(k, d, m, g, v, 1e-3, phase, step)
    x_next, u_next = jump_means_module._next_state(x, u, *flat)
    x_run, u_run, _, _ = end_state(k, d, m, g, v, 1e-3, phase, step + 1)
    np.testing.assert_array_equal(u_next, u_run)
    np.testing.assert_array_equal(x_next, x_run)


def test_an_extreme_just_inside_the_change_is_searched(monkeypatch):
    # a design of the change tables under gravity (found measuring the rule of 12 nodes):
    # the least restitution lies 3.8e-5 of a phase before the change, 3.9e-12 below the
    # side there; the quadratic through the piece's last three samples put its vertex
    # just past the side (no search; the former layout's samples, 2e-6 inside: luck),
    # the one-sided slope at the change says it lies inside
    k, d, m, g, v, h = 1415.2762012126586, 1.4172687282155165, 0.1, 9.81, 1.0, 1e-3
    rows = [np.array([x]) for x in (k, d, m, g, v)]
    q = np.array([30.484875403334836])
    exact = phase_summary(*rows[:2], 0.0, *rows[2:], h, approximation="lagged")
    base = np.array([29])
    results = []
    for beside in (jump_range._beside, lambda *args: args[5]):  # (without: short)
        monkeypatch.setattr(jump_range, "_beside", beside)
        s, held = jump_summary(*rows, h, q, deepest_last=True, nodes=5)
        assert held[0]
        lo, _ = _dense_range(rows, h, base, s.contact_time_min / h - base)
        results.append(s.restitution_min[0] - lo[0])
    assert abs(results[0]) < 1e-14
    assert results[1] > 1e-12
    monkeypatch.undo()
    _agree(jump_summary(*rows, h, q, nodes=5)[0], np.array([True]), exact, rows, h)


def _all_in_full(monkeypatch):
    """``jump_means.ended_at`` made to decide nothing (status 0 everywhere): every phase of
    the grid and next to the change run in full by ``contact_ends``, as before the runs
    to the expected end states."""
    ended_at = jump_means_module.ended_at

    def nothing(*args):
        r, status = ended_at(*args)
        return r, np.zeros_like(status)

    monkeypatch.setattr(jump_means_module, "ended_at", nothing)


@pytest.mark.parametrize("gravity", [0.0, 9.81, 30.0])
@pytest.mark.parametrize("step", [1e-3, 1e-4])
def test_the_grid_run_to_its_end_states_is_the_full_contacts_bit_for_bit(gravity, step,
                                                                         monkeypatch):  # fmt: skip
    # random contacts of 2-70 steps (a sixth soft and heavily damped: under gravity many
    # stick at some phase; without it some coast out), at their own mean or a third of a
    # phase off: every field and held the same as with the grid's contacts run in full
    rng = np.random.default_rng(int(gravity) + int(1e4 * step))
    n = 700
    m, v, g = np.full(n, 0.1), np.full(n, 1.0), np.full(n, gravity)
    steps = np.exp(rng.uniform(np.log(2.0), np.log(70.0), n))
    k = m * (np.pi / (steps * step)) ** 2
    d = rng.uniform(0.0, 3.0, n) ** 2
    soft = rng.random(n) < 0.17
    k[soft] /= rng.uniform(1.0, 50.0, soft.sum())
    d[soft] *= rng.uniform(5.0, 200.0, soft.sum())
    runs = contact_ends(*(a[:, None] for a in (k, d, m, g, v)), step, (np.arange(8) + 0.5) / 8)
    q = np.where(runs.sticks, np.nan, runs.contact_time / step).mean(axis=1)
    q = np.where(np.isfinite(q), q, steps) + (rng.random(n) < 0.3) * rng.uniform(-0.3, 0.3, n)
    rows = (k, d, m, g, v, step, np.maximum(q, 0.6))
    calls = [lambda: jump_summary(*rows, nodes=5, deepest_last=True), lambda: jump_summary(*rows),
             lambda: (jump_holds(*rows, deepest_last=True),)]  # fmt: skip
    ours = [c() for c in calls]
    with monkeypatch.context() as patch:
        _all_in_full(patch)
        full = [c() for c in calls]
    for a, b in zip(ours, full, strict=True):
        np.testing.assert_array_equal(a[-1], b[-1])  # held
        if len(a) == 2:
            np.testing.assert_array_equal(a[0].stacked().view(np.uint64),
                                          b[0].stacked().view(np.uint64))  # fmt: skip
    held = ours[0][1]
    assert 0.05 < held.mean() < 0.5
    if gravity > 0.0:
        assert runs.sticks.any(axis=1).mean() > 0.05
    # (the check can fail: a grid that takes its runs' states as the end states, without
    # asking whether they end there, holds more)
    ended_at = jump_means_module.ended_at
    monkeypatch.setattr(jump_means_module, "ended_at",
                        lambda *a: (ended_at(*a)[0], np.ones(np.size(a[-1]), np.int8)))  # fmt: skip
    assert np.count_nonzero(jump_holds(*rows, deepest_last=True) != ours[2][0]) > 10
