"""PyBullet's phase pieces from closed-form break points against the grid-and-bisection
search (phase_summary with an explicit ``pattern``, which takes that path) and against
the pattern itself read on either side of every root."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.pybullet.phase_means import root_summary
from impactsym.engines.pybullet.phases import phase_summary
from impactsym.engines.pybullet.stepping import step_pattern
from impactsym.engines.pybullet.tracking import tracked_pattern


def phase_means(*args, **settings):
    """The phase-mean restitution and contact time of :func:`root_summary`."""
    summary = root_summary(*args, **settings)
    return summary.restitution, summary.contact_time


RNG = np.random.default_rng(2040)
H = 1 / 240
BASE = {"slop": 1e-5, "processing_threshold": np.inf}


def _contacts(n, gravity):
    t = RNG.uniform(3.0, 40.0, n) * H
    zeta = RNG.uniform(0.0, 0.6, n)
    m, v = RNG.uniform(0.05, 1.0, n), RNG.uniform(0.3, 2.0, n)
    k = m * (np.pi / t) ** 2
    return k, 2.0 * zeta * np.sqrt(k * m), m, v, np.full(n, gravity)


@pytest.mark.parametrize(("gravity", "substeps"), [(0.0, 1), (9.81, 1), (9.81, 2)])
def test_means_and_ranges_are_those_of_the_bisection(gravity, substeps):
    k, c, m, v, g = _contacts(60, gravity)
    settings = {**BASE, "substeps": substeps}
    fast = phase_summary(k, c, m, v, g, H, **settings)
    bisected = phase_summary(k, c, m, v, g, H, **settings, pattern=step_pattern)
    e, t = phase_means(k, c, m, v, g, H, **settings)
    if gravity:
        assert np.isinf(bisected.contact_time).any()  # sticking phases are in the mix
    np.testing.assert_array_equal(np.isinf(fast.contact_time), np.isinf(bisected.contact_time))
    np.testing.assert_array_equal(np.isinf(t), np.isinf(bisected.contact_time))
    for name in ("restitution", "contact_time", "stick_fraction"):
        want = getattr(bisected, name)
        np.testing.assert_allclose(getattr(fast, name), want, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(e, bisected.restitution, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(t, bisected.contact_time, rtol=1e-11)
    for name in ("restitution_min", "restitution_max", "contact_time_min", "contact_time_max"):
        want = getattr(bisected, name)
        np.testing.assert_allclose(getattr(fast, name), want, rtol=1e-10, err_msg=name)


def test_the_pattern_holds_up_to_the_root_and_changes_there():
    k, c, m, v, g = _contacts(40, 0.0)
    p = RNG.uniform(0.0, 0.9, k.size)
    key, ahead, _ = tracked_pattern(k, c, m, v, g, H, p, substeps=1, **BASE)
    np.testing.assert_array_equal(key, step_pattern(k, c, m, v, g, H, p, substeps=1, **BASE)[1])
    has = p + ahead < 1.0
    assert has.sum() > 20
    k, c, m, v, g, p, key, ahead = (a[has] for a in (k, c, m, v, g, p, key, ahead))
    before = p[:, None] + ahead[:, None] * np.linspace(0.0, 1.0 - 1e-11, 30)[None, :]
    rows = np.repeat(np.arange(k.size), 30)
    args = (k[rows], c[rows], m[rows], v[rows], g[rows], H, before.ravel())
    same = step_pattern(*args, substeps=1, **BASE)[1].reshape(before.shape)
    np.testing.assert_array_equal(same, np.broadcast_to(key[:, None], before.shape))
    after = step_pattern(k, c, m, v, g, H, p + ahead + 1e-11, substeps=1, **BASE)[1]
    assert np.all(after != key)


def test_patterns_of_long_contacts_stay_exact():
    """The pattern record compares every count, however large (a float packing of the
    counts once overflowed to nan past 1024 sub-steps of one kind: nan equals nothing)."""
    from impactsym.engines.pybullet.stepping import pattern_code

    one = pattern_code(False, 5000, 0, 2000, 1500, 0)
    np.testing.assert_array_equal(one == pattern_code(False, 5000, 0, 2000, 1500, 0), True)
    np.testing.assert_array_equal(one == pattern_code(False, 5000, 0, 2000, 1501, 0), False)
    np.testing.assert_array_equal(one == pattern_code(True, 5000, 0, 2000, 1500, 0), False)


def test_long_contacts_have_the_dense_phase_mean():
    """Contacts over 1000 steps long (k = 8 N/m, m = 1 kg, dt = 1 ms): the phase means
    equal the average over 4000 evenly spread phases to its own sampling error (~1e-7;
    integrating across the end-state jumps, as the overflowed codes once did, was off by
    6e-6 in e and 2e-5 s in t), both by the closed-form break points and the bisection."""
    g = np.array([0.0, 0.5])
    settings = {**BASE, "substeps": 1}
    e, t = phase_means(8.0, 0.4, 1.0, 1.0, g, 1e-3, **settings)
    p = (np.arange(4000) + 0.5) / 4000
    dense, key = step_pattern(8.0, 0.4, 1.0, 1.0, g[:, None], 1e-3, p[None, :], **settings)
    assert key["pos"].max() > 1024
    np.testing.assert_allclose(e, dense.restitution.mean(axis=1), rtol=0, atol=5e-7)
    np.testing.assert_allclose(t, dense.contact_time.mean(axis=1), rtol=0, atol=5e-7)
    bisected = phase_summary(8.0, 0.4, 1.0, 1.0, g, 1e-3, **settings, pattern=step_pattern)
    np.testing.assert_allclose(bisected.restitution, e, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bisected.contact_time, t, rtol=0, atol=1e-12)


def test_passes_of_chunk_elements_give_every_element_its_own_numbers(monkeypatch):
    import impactsym.engines.pybullet.phase_means as means_module
    import impactsym.engines.pybullet.phases as phases_module

    rng = np.random.default_rng(3)
    n, h, m = 40, 1 / 240, 0.1
    k = m * (np.pi / (rng.uniform(4.0, 40.0, n) * h)) ** 2
    c = 2.0 * rng.uniform(0.02, 0.6, n) * np.sqrt(k * m)
    g = rng.choice([0.0, 9.81], n)
    opts = {"substeps": 1, "slop": 1e-5, "processing_threshold": np.inf}
    whole = phase_means(k, c, m, 1.0, g, h, **opts)
    summary = phase_summary(k, c, m, 1.0, g, h, **opts)
    monkeypatch.setattr(means_module, "CHUNK", 7)
    monkeypatch.setattr(phases_module, "CHUNK", 7)
    passes = phase_means(k.reshape(4, 10), c.reshape(4, 10), m, 1.0, g.reshape(4, 10), h, **opts)
    in_passes = phase_summary(k, c, m, 1.0, g, h, **opts)
    for a, b in zip(whole, passes, strict=True):
        np.testing.assert_array_equal(a, b.ravel())
    for name in ("restitution", "contact_time", "restitution_min", "contact_time_max"):
        np.testing.assert_array_equal(getattr(summary, name), getattr(in_passes, name))


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_the_tracked_end_speed_is_the_maps_restitution_up_to_the_root(gravity):
    """``root_summary`` integrates the quadratic ``-(w0 + w1 u + w2 u^2 / 2) / v`` that the
    tracked run at a phase carries: it must be the restitution the map itself gives at
    phases up to the first root ahead (fresh runs of ``step_pattern``)."""
    k, c, m, v, g = _contacts(80, gravity)
    p = RNG.uniform(0.0, 0.9, k.size)
    key, ahead, (w0, w1, w2) = tracked_pattern(k, c, m, v, g, H, p, substeps=1, **BASE)
    keep = (key["end"] >= 0) & (np.minimum(ahead, 1.0 - p) > 0.05)
    assert keep.sum() > 20
    k, c, m, v, g, p, ahead, w0, w1, w2 = (a[keep] for a in (k, c, m, v, g, p, ahead, w0, w1, w2))
    u = np.minimum(ahead, 1.0 - p) * np.linspace(0.0, 0.999, 7)[:, None]
    run = step_pattern(k, c, m, v, g, H, p + u, substeps=1, **BASE)[0]
    quadratic = -(w0 + w1 * u + 0.5 * w2 * u * u) / v
    np.testing.assert_allclose(quadratic, run.restitution, rtol=1e-11, atol=1e-13)


def test_pieces_tile_the_phase_and_searched_changes_are_tight(monkeypatch):
    """Every element's pieces cover [0, 1) in order; where two pieces do not meet at a
    root the change was searched (15 phases a round, 11 rounds): the gap is at most
    2^-44 of a grid interval, and the map's pattern differs across it. The roots see
    every change of these contacts (the sticks after the end state included), so every
    third root solve is dropped here: the changes they miss are searched."""
    import impactsym.engines.pybullet.tracking as tracking_module
    from impactsym.engines.pybullet.phase_means import break_pieces

    solves = []

    def some_roots(*args, solve=tracking_module.quadratic_roots_ahead):
        solves.append(None)
        return solve(*args) if len(solves) % 3 else ()

    monkeypatch.setattr(tracking_module, "quadratic_roots_ahead", some_roots)

    rng = np.random.default_rng(1)  # (200 contacts: changes the roots miss are rare)
    t, zeta = rng.uniform(3.0, 40.0, 200) * H, rng.uniform(0.0, 0.6, 200)
    m, v = rng.uniform(0.05, 1.0, 200), rng.uniform(0.3, 2.0, 200)
    k, g = m * (np.pi / t) ** 2, np.full(200, 9.81)
    c = 2.0 * zeta * np.sqrt(k * m)
    p0, p1, s0, s1, own, key, _ = break_pieces(k, c, m, v, g, H, substeps=1, **BASE)
    first = np.r_[True, own[1:] != own[:-1]]
    last = np.r_[own[1:] != own[:-1], True]
    assert np.all(p0[first] == 0.0)
    assert np.all(p1[last] == np.nextafter(1.0, 0.0))
    gap = p0[1:][~first[1:]] - p1[:-1][~last[:-1]]
    assert np.all(gap >= 0.0)
    assert np.all(gap <= 2.0**-44 / 8 * 1.01)
    searched = np.flatnonzero(~last[:-1])[gap > 0]
    assert searched.size > 0
    i = own[searched]
    before = step_pattern(k[i], c[i], m[i], v[i], g[i], H, s1[searched], substeps=1, **BASE)[1]
    after = step_pattern(k[i], c[i], m[i], v[i], g[i], H, s0[searched + 1], substeps=1, **BASE)[1]
    np.testing.assert_array_equal(before, key[searched])
    np.testing.assert_array_equal(after, key[searched + 1])
    assert np.all(before != after)


@pytest.mark.parametrize("substeps", [1, 2])
def test_tracked_runs_that_stop_at_a_separating_end_keep_the_maps_pattern(substeps):
    """Without gravity a tracked run ends where the contact ends separating (no later
    impulse can come back), unless leaving the overlap could outlast the step budget:
    heavily damped, slow contacts that stick by the budget are in the mix, and every
    pattern must be the full run's of ``step_pattern``."""
    rng = np.random.default_rng(4)
    n = 3000
    t = rng.uniform(1.0, 40.0, n) * H
    zeta = np.exp(rng.uniform(np.log(0.5), np.log(200.0), n))
    m, v = rng.uniform(0.05, 1.0, n), np.exp(rng.uniform(np.log(1e-4), np.log(2.0), n))
    k = m * (np.pi / t) ** 2
    c, p = 2.0 * zeta * np.sqrt(k * m), rng.uniform(0.0, 1.0, n)
    key, _, _ = tracked_pattern(k, c, m, v, 0.0, H, p, substeps=substeps, **BASE)
    run, full = step_pattern(k, c, m, v, 0.0, H, p, substeps=substeps, **BASE)
    assert run.sticks.sum() > 100
    np.testing.assert_array_equal(key, full)


def _free_contacts(n, seed):
    """Contacts without gravity from light to heavily damped, fast to crawling: most end
    separating at every phase, some hover (a zero force while still approaching) or
    leave too slowly for their step budget, so they stick at some phases."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(1.0, 40.0, n) * H
    zeta = np.exp(rng.uniform(np.log(0.01), np.log(5.0), n))
    m, v = rng.uniform(0.05, 1.0, n), np.exp(rng.uniform(np.log(1e-5), np.log(2.0), n))
    k = m * (np.pi / t) ** 2
    return k, 2.0 * zeta * np.sqrt(k * m), m, v


@pytest.mark.parametrize("substeps", [1, 2])
def test_pieces_without_gravity_from_one_interval_are_the_maps(monkeypatch, substeps):
    """Without gravity the pieces are searched from one phase interval and kept where
    every phase provably ends final; the others are searched on the 8-interval grid.
    Both kinds are in the mix, and at random phases inside every piece the map itself
    (a full ``step_pattern`` run) has the piece's pattern."""
    import impactsym.engines.pybullet.phase_means as means_module

    calls = []
    grid_pieces = means_module._grid_pieces

    def counted(flat, settings, intervals, **budget):
        calls.append((intervals, flat[0].size))
        return grid_pieces(flat, settings, intervals, **budget)

    monkeypatch.setattr(means_module, "_grid_pieces", counted)
    k, c, m, v = _free_contacts(200, 5)
    opts = {**BASE, "substeps": substeps}
    p0, p1, _, _, own, key, _ = means_module.break_pieces(k, c, m, v, 0.0, H, **opts)
    sizes = dict(calls)
    assert sizes[1] == 200
    assert 5 <= sizes[8] <= 100  # the grid only for the unproved
    u = RNG.uniform(0.0, 1.0, (5, p0.size))
    inside = p0 + u * (p1 - p0)
    i = np.broadcast_to(own, inside.shape)
    run = step_pattern(k[i], c[i], m[i], v[i], 0.0, H, inside, **opts)[1]
    np.testing.assert_array_equal(run, np.broadcast_to(key, inside.shape))


def test_means_without_gravity_are_the_bisections_where_some_phases_stick():
    """The phase summary of contacts without gravity (most from one interval, the
    unproved on the grid, :func:`_free_contacts`) against the grid-and-bisection search
    of the plain map, which shares neither the roots nor the proof of finality. (One
    sub-step: with two, some of these contacts change pattern and back inside one of the
    bisection's grid intervals, which it cannot see.)"""
    k, c, m, v = _free_contacts(100, 6)
    settings = {**BASE, "substeps": 1}
    fast = root_summary(k, c, m, v, 0.0, H, **settings)
    bisected = phase_summary(k, c, m, v, 0.0, H, **settings, pattern=step_pattern)
    assert np.isinf(bisected.contact_time).any()  # sticking phases are in the mix
    np.testing.assert_array_equal(np.isinf(fast.contact_time), np.isinf(bisected.contact_time))
    for name in ("restitution", "contact_time", "stick_fraction"):
        want = getattr(bisected, name)
        np.testing.assert_allclose(getattr(fast, name), want, rtol=1e-11, atol=1e-13)
    for name in ("restitution_min", "restitution_max", "contact_time_min", "contact_time_max"):
        want = getattr(bisected, name)
        np.testing.assert_allclose(getattr(fast, name), want, rtol=1e-10, err_msg=name)


@pytest.mark.parametrize("substeps", [1, 2])
def test_one_interval_gives_the_grids_numbers(monkeypatch, substeps):
    """The summary from one interval where the ends are final is the 8-interval grid's
    (every element forced onto the grid) to rounding: the roots alone, without the grid's
    check, find the same pieces."""
    import impactsym.engines.pybullet.phase_means as means_module

    k, c, m, v = _free_contacts(200, 8)
    opts = {**BASE, "substeps": substeps}
    coarse = root_summary(k, c, m, v, 0.0, H, **opts)
    monkeypatch.setattr(means_module, "_ends_final", lambda pieces, budget, H: budget < 0)
    grid = root_summary(k, c, m, v, 0.0, H, **opts)
    for name in ("restitution", "contact_time", "stick_fraction", "restitution_min",
                 "restitution_max", "contact_time_min", "contact_time_max"):  # fmt: skip
        want = getattr(grid, name)
        np.testing.assert_allclose(getattr(coarse, name), want, rtol=1e-12, atol=1e-14)


def test_only_contacts_that_end_final_at_every_phase_skip_the_grid():
    """The proof that lets an element skip the grid (``_ends_final``) holds for none
    whose map, run at 400 phases, sticks or ends with the body still approaching at
    any of them, and for most of the others."""
    import impactsym.engines.pybullet.phase_means as means_module
    from impactsym.engines.pybullet.stepping import MAX_STEPS, step_budget

    k, c, m, v = _free_contacts(200, 9)
    flat = [k, c, m, v, np.zeros(k.size), np.full(k.size, H)]
    pieces, searched = means_module._grid_pieces(flat, (1, 1e-5, np.inf, 0.0, 0.2), 1)
    budget = np.minimum(step_budget(k, c, m, H), MAX_STEPS)
    sure = ~searched & means_module._ends_final(pieces, budget, flat[5])
    p = (np.arange(400) + 0.5) / 400
    run = step_pattern(k[:, None], c[:, None], m[:, None], v[:, None], 0.0, H, p, substeps=1,
                       **BASE)[0]  # fmt: skip
    unsafe = np.any(run.sticks | (run.restitution <= 0.0), axis=1)
    assert unsafe.sum() >= 5
    assert not np.any(sure & unsafe)
    assert sure.sum() >= 0.8 * (~unsafe).sum()


@pytest.mark.parametrize(("gravity", "substeps"), [(0.0, 1), (0.0, 2), (9.81, 1)])
def test_run_pattern_is_the_pattern_of_step_pattern(gravity, substeps):
    """The pattern-only run (no extremes; without gravity stopped at a final end) gives
    every record of the full run, sticking contacts included."""
    from impactsym.engines.pybullet.stepping import run_pattern

    k, c, m, v = _free_contacts(3000, 7)
    p = RNG.uniform(0.0, 1.0, k.size)
    full = step_pattern(k, c, m, v, gravity, H, p, substeps=substeps, **BASE)
    assert full[0].sticks.sum() > 50
    np.testing.assert_array_equal(
        run_pattern(k, c, m, v, gravity, H, p, substeps=substeps, **BASE), full[1]
    )


@pytest.mark.parametrize("substeps", [1, 2])
def test_a_contact_that_sticks_at_some_phases_leaves_the_one_interval_pass_at_once(
    monkeypatch, substeps
):
    """A slow, heavily damped contact without gravity sticks at some phases, so it is
    summed on the grid; the one-interval pass gives it up at its first end (a tracked run
    of a few steps) instead of running rounds to its step budget: ``break_pieces`` steps
    the map little more than the grid alone, and gives the grid's pieces."""
    import impactsym.engines.pybullet.phase_means as means_module
    import impactsym.engines.pybullet.stepping as stepping_module
    import impactsym.engines.pybullet.tracking as tracking_module
    from impactsym.engines.pybullet.stepping import DEFAULT_RESTITUTION_THRESHOLD

    steps = []
    run_live = stepping_module.run_live

    def counted(fixed, state, advance):
        def step(a, n, limit):
            steps.append(1)
            advance(a, n, limit)

        return run_live(fixed, state, step)

    monkeypatch.setattr(tracking_module, "run_live", counted)
    monkeypatch.setattr(stepping_module, "run_live", counted)
    args, opts = (1e3, 200.0, 0.1, 1e-3, 0.0, H), {**BASE, "substeps": substeps}
    assert root_summary(*args, **opts).stick_fraction > 0.0
    steps.clear()
    pieces = means_module.break_pieces(*args, **opts)
    both = len(steps)
    steps.clear()
    flat = [np.atleast_1d(float(a)) for a in args]
    settings = (substeps, BASE["slop"], np.inf, 0.0, DEFAULT_RESTITUTION_THRESHOLD)
    grid, _ = means_module._grid_pieces(flat, settings, 8)
    assert len(steps) > 1000  # (runs to the step budget)
    assert both <= len(steps) + 20
    for got, want in zip(pieces, means_module._merge(*grid[:6], grid[6][:3]), strict=True):
        np.testing.assert_array_equal(got, want)


def test_the_finality_proof_reads_both_ends_of_every_piece():
    """``_ends_final`` on hand-made pieces (end state linear in the phase): a piece that
    separates at its start but not at its end (``w = -1 + 1.5 u``), or that leaves at
    its end too slowly for the budget (``x / (-w H)`` calls from ``n_end = 5``), is
    refused; one separating fast at both ends is kept. (No contact of the map gives the
    first two: ``_ends_final``'s docstring says why; this pins the proof's end half.)"""
    from impactsym.engines.pybullet.phase_means import _ends_final
    from impactsym.engines.pybullet.stepping import PATTERN

    key = np.zeros(3, PATTERN)
    key["end"] = 5
    p0, p1, s0 = np.zeros(3), np.ones(3), np.zeros(3)
    w0, w1 = np.array([-1.0, -1.0, -1.0]), np.array([1.5, 0.0, 0.0])
    x0, x1 = np.array([-1e-3, 0.0, 0.0]), np.array([0.0, 1.0 * 50 * H, 0.0])
    state = np.stack([w0, w1, np.zeros(3), x0, x1])
    pieces = (p0, p1, s0, p1, key, np.arange(3), state)
    budget = np.full(3, 40.0)  # at the end x / (-w H) = 50 calls: past the budget
    np.testing.assert_array_equal(_ends_final(pieces, budget, np.full(3, H)), [False, False, True])


@pytest.mark.parametrize(("gravity", "substeps"), [(9.81, 1), (9.81, 2), (0.0, 1)])
def test_roots_sought_only_inside_the_interval_change_no_number(monkeypatch, gravity, substeps):
    # the tracked runs of the piece search seek the root ahead only up to twice what is
    # left of their interval: every piece, mean and range as with the roots sought a
    # whole phase ahead (the tracked runs without a horizon)
    from impactsym.engines.pybullet import phase_means as pm

    k, c, m, v, g = _contacts(300, gravity)
    settings = {**BASE, "substeps": substeps}
    near = root_summary(k, c, m, v, g, H, **settings)
    track = pm.tracked_run

    def whole_phase(*args, horizon, **options):
        assert np.all(horizon < 2.1)  # (the horizon is in use)
        return track(*args, **options)

    monkeypatch.setattr(pm, "tracked_run", whole_phase)
    far = root_summary(k, c, m, v, g, H, **settings)
    for name in ("restitution", "contact_time", "stick_fraction", "restitution_min",
                 "restitution_max", "contact_time_min", "contact_time_max"):  # fmt: skip
        np.testing.assert_array_equal(getattr(near, name), getattr(far, name), err_msg=name)


def _merged_by_lexsort(p0, p1, s0, s1, key, own, speed):
    """The pieces sorted by owner and start (``np.lexsort``) and joined, record arrays
    gathered as such: the merge as it was written first."""
    order = np.lexsort((p0, own))
    p0, p1, s0, s1, key, own = (a[order] for a in (p0, p1, s0, s1, key, own))
    speed = speed[:, order]
    joins = np.zeros(p0.size, bool)
    joins[1:] = (own[1:] == own[:-1]) & (key[1:] == key[:-1]) & (p0[1:] == p1[:-1])
    starts = np.flatnonzero(~joins)
    lasts = np.append(starts[1:], p0.size) - 1
    return p0[starts], p1[lasts], s0[starts], s1[lasts], own[starts], key[starts], speed[:, starts]


@pytest.mark.parametrize("gravity", [9.81, 0.0])
def test_the_merge_of_the_pieces_is_that_of_a_sort_by_owner_and_start(monkeypatch, gravity):
    # the merge sorts by owner and grid interval where that orders the starts (checked),
    # else by owner and start; both give the pieces of the plain sort, in the rounds'
    # order and shuffled
    from impactsym.engines.pybullet import phase_means as pm

    seen = []
    merge = pm._merge

    def recording(*pieces):
        seen.append(pieces)
        return merge(*pieces)

    monkeypatch.setattr(pm, "_merge", recording)
    k, c, m, v, g = _contacts(200, gravity)
    root_summary(k, c, m, v, g, H, **BASE, substeps=1)
    (pieces,) = seen
    shuffle = RNG.permutation(pieces[0].size)
    shuffled = [a[..., shuffle] for a in pieces]
    for args in (pieces, shuffled):
        assert np.any(np.diff(args[5]) < 0)  # (the owners come unsorted)
        for got, want in zip(merge(*args), _merged_by_lexsort(*args), strict=True):
            np.testing.assert_array_equal(got, want)
    if gravity:  # (the grid's pieces of one pattern were joined)
        assert merge(*pieces)[0].size < pieces[0].size


#: contacts that stick, under gravity, on a band of phases inside one of the grid's 8
#: intervals (the force comes back while the body coasts inside the overlap after the
#: end state): 0.2955-0.3684 and 0.1375-0.2000 (found by a random search; the summary
#: once reported stick fraction 0 and a finite mean contact time for both)
STICK_BANDS = [
    {"stiffness": 335093.8803170063, "damping": 93.36434620678274, "mass": 1.0,
     "speed": 1.049189963511849, "gravity": 9.81, "timestep": 1 / 240, "substeps": 1},
    {"stiffness": 74967.08992768759, "damping": 29.66742016455763, "mass": 1.0,
     "speed": 0.19181628889273175, "gravity": 9.81, "timestep": 1 / 240, "substeps": 2},
]  # fmt: skip


@pytest.mark.parametrize("case", STICK_BANDS)
def test_a_stick_band_inside_a_grid_interval_is_found(case):
    """The summary against the midpoint rule over 2^14 phases of the engine's own stepping
    (``predict`` at each phase): the stick fraction and the mean restitution agree
    within the rule's bound, ``|jump| / (2N)`` per change of the pattern between
    neighbouring midpoints (plus 1e-9 for the smooth parts), and the summary sticks."""
    from impactsym.engines.pybullet import predict

    n = 2**14
    p = (np.arange(n) + 0.5) / n
    dense = predict(**case, phase=p)
    summary = predict(**case)
    stuck = np.asarray(dense.sticks, bool)
    e = np.asarray(dense.restitution)
    changes = np.flatnonzero(stuck[1:] != stuck[:-1])
    assert 0.03 < stuck.mean() < 0.1
    assert changes.size == 2  # one band, inside a grid interval
    assert np.floor(8 * p[changes[0]]) == np.floor(8 * p[changes[1] + 1])
    assert summary.sticks
    assert np.isinf(summary.contact_time)
    assert np.isinf(summary.contact_time_range[1])
    lo, hi = summary.restitution_range  # (the sticking phases' 0 is among the samples)
    assert lo <= e.min() + 1e-12
    assert hi >= e.max() - 1e-12
    step = np.abs(np.diff(e)).max()  # (the samples are this far apart at most)
    np.testing.assert_allclose((lo, hi), (e.min(), e.max()), rtol=0, atol=step)
    np.testing.assert_allclose(summary.stick_fraction, stuck.mean(), rtol=0, atol=2 / (2 * n))
    jumps = np.abs(np.diff(e)[changes]).sum()
    bound = jumps / (2 * n) + 1e-9
    np.testing.assert_allclose(summary.restitution, e.mean(), rtol=0, atol=bound)


@pytest.mark.parametrize("case", STICK_BANDS)
def test_with_gravity_the_pattern_holds_up_to_the_root_ahead(case):
    """The root ahead of a tracked run under gravity (the coast after the end state
    watched too) is never past a change: at 24 phases between each of 256 phases and its
    root ahead the map's pattern is the run's (at the band's edges the roots tracked only
    up to the end state skipped the band)."""
    args = tuple(float(case[key]) for key in ("stiffness", "damping", "mass", "speed"))
    args += (case["gravity"], case["timestep"])
    k, c, m, v, g, h = args
    c += 0.1  # (the pair's damping, as ``predict`` combines it)
    opts = {**BASE, "substeps": case["substeps"]}
    p = (np.arange(256) + 0.5) / 256
    key, ahead, _ = tracked_pattern(k, c, m, v, g, h, p, **opts)
    assert np.any(key["end"] < 0)
    assert np.any(key["end"] >= 0)
    reach = np.minimum(ahead, np.nextafter(1.0, 0.0) - p)
    between = p[:, None] + reach[:, None] * np.linspace(0.0, 1.0 - 1e-9, 24)[None, :]
    same = step_pattern(k, c, m, v, g, h, between, **opts)[1]
    np.testing.assert_array_equal(same, np.broadcast_to(key[:, None], between.shape))


@pytest.mark.parametrize("substeps", [1, 2])
def test_with_gravity_random_short_contacts_hold_their_pattern_up_to_the_root(substeps):
    """As above over 150 random short contacts under gravity (stiffness 3e3-1e6 N/m,
    damping ratio 0.01-10, speed 0.01-5 m/s, m = 1 kg: some stick after the end state),
    64 phases each."""
    rng = np.random.default_rng(77 + substeps)
    n = 150
    k = np.exp(rng.uniform(np.log(3e3), np.log(1e6), n))
    c = 2.0 * np.exp(rng.uniform(np.log(0.01), np.log(10.0), n)) * np.sqrt(k)
    v = np.exp(rng.uniform(np.log(0.01), np.log(5.0), n))
    p = (np.arange(64) + rng.uniform(0.0, 1.0, 64)) / 64
    k, c, v, p = (a.ravel() for a in np.broadcast_arrays(k[:, None], c[:, None], v[:, None], p))
    opts = {**BASE, "substeps": substeps}
    key, ahead, _ = tracked_pattern(k, c, 1.0, v, 9.81, H, p, **opts)
    assert np.any(key["end"] < 0)
    reach = np.minimum(ahead, np.nextafter(1.0, 0.0) - p)
    between = p[:, None] + reach[:, None] * np.linspace(0.0, 1.0 - 1e-9, 12)[None, :]
    rows = (k[:, None], c[:, None], 1.0, v[:, None], 9.81, H, between)
    same = step_pattern(*rows, **opts)[1]
    np.testing.assert_array_equal(same, np.broadcast_to(key[:, None], between.shape))
