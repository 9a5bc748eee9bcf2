"""Discrete Drake designs read off tables of exact designs (one per end state, and per
plateau between two), each confirmed by one exact evaluation that also gives its phase
summary.

Checked by what did not make them, on the tables' own output (not through
``point_contact_for``, whose safety net would design a miss again): a fresh exact
``predict`` at each design (the phase summary's root search and its own Gauss pieces,
not the change's equations), and the designs of the same targets with the tables turned
off (the per-call table of phase means and Broyden's steps).
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.contact.lawtable import chebyshev_points
from impactsym.engines import drake
from impactsym.engines.drake import change_table, chebyshev_tables, step_table
from impactsym.engines.drake.change_table import (
    MIN_SERVED,
    MIN_STEPS,
    MIN_TARGETS,
    NODES,
    NODES_E,
    NODES_PHASE,
    PHASES,
    PHASES_PRESSED,
    table_designs,
)
from impactsym.engines.drake.jump_means import jump_holds, jump_means
from impactsym.engines.drake.prediction import summary_prediction
from impactsym.engines.drake.step_table import stepped_designs

H, V, M = 1e-3, 1.0, 0.1


def _targets(base, n, rng, phases=(0.0, 1.0)):
    """``n`` targets of one end state ``base``: e 0.3..0.6, the change anywhere in
    ``phases``."""
    e = rng.uniform(0.3, 0.6, n)
    q = base + 0.5 + rng.uniform(*phases, n)
    return e, q


def _read_off(e, size, gravity, size_name):
    """Where ``stepped_designs`` read the targets off a table (they came with a summary),
    the prediction they came with, and a fresh ``predict`` of those designs."""
    one = np.ones(e.size)
    ok, k, d, summaries = stepped_designs(e, V * one, M * one, gravity * one, size, H,
                                          "lagged", size_name)  # fmt: skip
    read = np.isfinite(summaries[0])
    assert ok[read].all()
    k, d = k[read], d[read]
    fresh = drake.predict(stiffness=k, dissipation=d, mass=M, speed=V, gravity=gravity,
                          time_step=H)  # fmt: skip
    rest = [a[read] for a in (M * one, V * one, gravity * one)]
    mine = summary_prediction(summaries[:, read], k, d, *rest, H, "lagged", (k.size,), False)
    return read, mine, fresh


def _same_prediction(mine, fresh):
    """The prediction a table's design came with (its one evaluation) is the searched
    phase summary's: the means to rounding, the restitution's range to its sampling,
    the rest alike."""
    np.testing.assert_allclose(mine.restitution, fresh.restitution, rtol=0, atol=2e-13)
    np.testing.assert_allclose(mine.contact_time, fresh.contact_time, rtol=1e-12)
    np.testing.assert_allclose(mine.contact_time_range, fresh.contact_time_range, rtol=1e-12)
    np.testing.assert_array_equal(mine.max_penetration, fresh.max_penetration)
    np.testing.assert_array_equal(mine.sticks, fresh.sticks)
    np.testing.assert_array_equal(mine.stick_fraction, fresh.stick_fraction)
    # (both sampled bounds, searched where their samples show an extreme inside a
    # piece or just inside its ends: each was up to 5e-7 short before; jump_summary's
    # can be 4e-13 short next to a change evaluated off the true one)
    np.testing.assert_allclose(mine.restitution_range, fresh.restitution_range, rtol=0,
                               atol=1e-12)  # fmt: skip


def _spy(monkeypatch):
    """Records ``(targets, designed here)`` of every call of ``table_designs``."""
    seen = []

    def spy(e, *args, **options):
        out = table_designs(e, *args, **options)
        seen.append((e.size, int(out[0].sum())))
        return out

    monkeypatch.setattr(step_table, "table_designs", spy)
    return seen


@pytest.mark.parametrize(("gravity", "base"), [(0.0, 29), (9.81, 22)])
def test_designs_off_the_tables_meet_their_targets_by_a_fresh_prediction(gravity, base):
    rng = np.random.default_rng(37)
    e, q = _targets(base, MIN_SERVED + 64, rng, PHASES_PRESSED[0] if gravity else PHASES[0])
    read, mine, fresh = _read_off(e, q * H, gravity, "contact_time")
    assert read.all()  # every target read off its table
    assert np.abs(fresh.restitution - e).max() <= 1.05e-12  # the designs' tolerance
    assert np.abs(fresh.contact_time / (q * H) - 1.0).max() <= 1.05e-10
    assert not np.any(fresh.sticks)
    _same_prediction(mine, fresh)


@pytest.mark.parametrize(
    ("base", "q", "gravity"),
    [(30, 30.5, 5.0), (30, 31.0, 5.0), (40, 40.5, 5.0), (30, 31.0 - 1e-12, 5.0),
     (20, np.nextafter(20.75, 21.0), 7.0)],
)  # fmt: skip
def test_a_change_at_or_next_to_a_grid_phase_gives_the_whole_restitution_range(base, q, gravity):
    """At ``phi*`` on (or within 1e-12 of) ``k/8`` a Gauss node or a side of the change
    falls on a grid phase, and at 0 the empty piece's side on the other's: the search
    around the least restitution needs its neighbours apart, else it searched one side
    only (the least was up to 1e-5 too high; reviews; a contact time of 0.0029 s at
    ``h = 1e-4`` lands 1e-14 below a half step)."""
    rng = np.random.default_rng(50)
    e = rng.uniform(0.3, 0.6, 1100)
    q = np.full(e.size, q)
    read, mine, fresh = _read_off(e, q * H, gravity, "contact_time")
    assert read.mean() > 0.7  # (at B = 40, phi* = 0: 78 %)
    _same_prediction(mine, fresh)


@pytest.mark.parametrize("phases", [(0.0, 0.02), (0.98, 1.0)])
def test_designs_next_to_the_phase_ends_under_gravity_come_off_the_table_extrapolated(phases):
    """Under gravity the tables cover the change's phases 0.02-0.98 (closer to the ends
    a second change can appear); a target beyond is read off its table extrapolated, and
    its evaluation keeps it where the one change holds there (before: none, all took
    the caller's path)."""
    rng = np.random.default_rng(38)
    e, q = _targets(22, MIN_SERVED + 64, rng, phases)
    read, mine, fresh = _read_off(e, q * H, 9.81, "contact_time")
    assert read.mean() > 0.3
    assert np.abs(fresh.restitution - e[read]).max() <= 1.05e-12  # the designs' tolerance
    assert np.abs(fresh.contact_time / (q[read] * H) - 1.0).max() <= 1.05e-10
    assert not np.any(fresh.sticks)
    _same_prediction(mine, fresh)


@pytest.mark.parametrize(("gravity", "depth"), [(0.0, 9.9e-3), (9.81, 6e-3), (9.81, 8e-3)])
def test_designs_by_largest_overlap_off_the_tables_meet_their_targets(gravity, depth, monkeypatch):
    """The overlap is the deepest state's; which state that is changes over a table, so
    each state's overlap has its own table and a target's phase is where their largest
    meets it. (Under gravity the coarse table that tells each target its likely end state
    reached none of these before its box was widened by the pressing number.)"""
    rng = np.random.default_rng(42)
    e, x = rng.uniform(0.45, 0.47, 1200), rng.uniform(depth, 1.01 * depth, 1200)
    monkeypatch.setattr(change_table, "MIN_TARGETS", 100)  # (these span a few end states)
    read, mine, fresh = _read_off(e, x, gravity, "max_penetration")
    assert read.mean() > 0.8
    assert np.abs(fresh.restitution - e[read]).max() <= 1.05e-12  # the designs' tolerance
    assert np.abs(fresh.max_penetration / x[read] - 1.0).max() <= 1.05e-10
    assert not np.any(fresh.sticks)
    _same_prediction(mine, fresh)


def test_designs_by_largest_overlap_on_a_plateau_are_read_off_its_own_table(monkeypatch):
    """Between the tables of two neighbouring end states lie the designs where every phase
    ends alike (their mean contact time rests at ``(N + 1/2) h``): a table of their own
    serves them."""
    rng = np.random.default_rng(45)
    e, x = rng.uniform(0.3, 0.35, 3000), rng.uniform(9e-3, 1e-2, 3000)  # (plateaus wider)
    monkeypatch.setattr(change_table, "MIN_TARGETS", 300)
    monkeypatch.setattr(change_table, "MIN_PLATEAU", 10**9)  # without the plateaus' tables
    without, _, _ = _read_off(e, x, 0.0, "max_penetration")
    monkeypatch.setattr(change_table, "MIN_PLATEAU", 32)
    read, mine, fresh = _read_off(e, x, 0.0, "max_penetration")
    assert np.abs(fresh.restitution - e[read]).max() <= 1.05e-12
    assert np.abs(fresh.max_penetration / x[read] - 1.0).max() <= 1.05e-10
    _same_prediction(mine, fresh)
    steps = fresh.contact_time / H - 0.5
    on_plateau = np.abs(steps - np.round(steps)) < 1e-9
    assert on_plateau.sum() > 0.03 * e.size
    assert not np.any(without[read][on_plateau])  # (the change's tables never give them)


def _from_the_starts(monkeypatch, e, size, size_name):
    """The designs of ``stepped_designs`` under gravity with the path of the targets the
    tables leave turned off (the tables' nodes, which it designs too, kept): ``(ok, k,
    d, summaries)``, the targets' rows that took the table's starts, and the number of
    exact phase means asked there."""
    monkeypatch.setattr(change_table, "MIN_TARGETS", 100)
    chunked, from_starts, means_rows = (
        step_table._chunked, step_table._from_starts, step_table._means_rows
    )  # fmt: skip
    seen, exact = [], []

    def leftovers_refused(e, *args, **options):
        if options:
            return chunked(e, *args, **options)
        return np.zeros(e.size, bool), np.full(e.size, np.nan), np.full(e.size, np.nan)

    def spy(e, *args):
        seen.append(e)
        exact.append(0)
        return from_starts(e, *args)

    def counted(*args):  # the exact phase means asked in _from_starts
        mean = means_rows(*args)

        def count(s, w, rows, **options):
            if exact:
                exact[-1] += s.size
            return mean(s, w, rows, **options)

        return count

    monkeypatch.setattr(step_table, "_chunked", leftovers_refused)
    monkeypatch.setattr(step_table, "_from_starts", spy)
    monkeypatch.setattr(step_table, "_means_rows", counted)
    one = np.ones(e.size)
    out = stepped_designs(e, V * one, M * one, 9.81 * one, size, H, "lagged", size_name)
    return out, np.flatnonzero(np.isin(e, np.concatenate(seen))), sum(exact)


def test_targets_by_overlap_their_evaluation_refuses_are_designed_from_the_tables_start(
    monkeypatch,
):
    """Under gravity a target by overlap whose change lies next to an end of the phase
    interval can have a second change there: its one evaluation refuses the table's
    design, which is still close (the restitution ~1e-4 off), and Broyden's steps from
    it design it (before: the per-call table of phase means, twice the cost), most on
    the equations of two changes (:mod:`~impactsym.engines.drake.two_changes`), the
    others on the exact phase means with the table's Jacobian. Checked with that table
    turned off for them, by a fresh ``predict``."""
    rng = np.random.default_rng(51)
    e, x = rng.uniform(0.5, 0.6, 2000), rng.uniform(6e-3, 7e-3, 2000)
    (ok, k, d, summaries), rows, exact = _from_the_starts(monkeypatch, e, x, "max_penetration")
    assert rows.size >= 20
    assert ok[rows].all()
    assert np.isnan(summaries[0, rows]).all()  # (no summary: not read off a table)
    # most by the equations of two changes: exact phase means for a few (6 each at most)
    assert exact <= 6 * 0.1 * rows.size
    fresh = drake.predict(stiffness=k[rows], dissipation=d[rows], mass=M, speed=V,
                          gravity=9.81, time_step=H)  # fmt: skip
    assert np.abs(fresh.restitution - e[rows]).max() <= 1.05e-12
    assert np.abs(fresh.max_penetration / x[rows] - 1.0).max() <= 1.05e-10
    assert not np.any(fresh.sticks)


def test_targets_by_contact_time_their_evaluation_refuses_are_designed_on_two_changes(
    monkeypatch,
):
    """By contact time under gravity the targets whose contact lasts close to a whole
    number of steps have a change next to each end of the phase interval: the evaluation
    refuses the table's design, Broyden's steps on the equations of two changes from it
    design them (before: the per-call table of phase means, ten times the cost), with
    the path of the others turned off. Checked by a fresh ``predict``."""
    rng = np.random.default_rng(52)
    e, t = rng.uniform(0.3, 0.6, 3000), rng.uniform(2e-2, 3e-2, 3000)
    (ok, k, d, summaries), rows, exact = _from_the_starts(monkeypatch, e, t, "contact_time")
    assert rows.size >= 20
    assert exact == 0  # (by contact time no exact phase means: they stall there)
    assert ok[rows].mean() >= 0.9
    rows = rows[ok[rows]]
    assert np.isnan(summaries[0, rows]).all()  # (no summary: not read off a table)
    fresh = drake.predict(stiffness=k[rows], dissipation=d[rows], mass=M, speed=V,
                          gravity=9.81, time_step=H)  # fmt: skip
    assert np.abs(fresh.restitution - e[rows]).max() <= 1.05e-12
    assert np.abs(fresh.contact_time / t[rows] - 1.0).max() <= 1.05e-10
    assert not np.any(fresh.sticks)


def test_the_evaluation_in_parts_is_the_evaluation_at_once(monkeypatch):
    """``_confirmed`` evaluates the designs in parts (their arrays below NumPy's huge-page
    size): held and summaries the same, bit for bit, as one evaluation of them all."""
    rng = np.random.default_rng(52)
    e, q = _targets(24, MIN_SERVED, rng)
    one = np.ones(e.size)
    _, k, d, _ = stepped_designs(e, V * one, M * one, 0 * one, q * H, H, "lagged",
                                 "contact_time")  # fmt: skip
    rows = (M * one, 0 * one, V * one, e, q, q)
    whole = change_table._confirmed(k, d, *rows, H, False)
    monkeypatch.setattr(change_table, "_EVALUATED", 97)  # (parts that do not divide it)
    parts = change_table._confirmed(k, d, *rows, H, False)
    assert whole[0].mean() > 0.9
    np.testing.assert_array_equal(parts[0], whole[0])
    np.testing.assert_array_equal(parts[1], whole[1])


def test_a_slightly_wrong_table_designs_nothing():
    """Where the table is off by 1e-10 (the exact designs' damping so biased), the one
    exact evaluation refuses every target instead of passing the table's design on."""
    rng = np.random.default_rng(47)
    e, q = _targets(24, MIN_SERVED, rng)
    one = np.ones(e.size)

    def design(e_n, q_n):
        c = drake.point_contact_for(restitution=e_n, contact_time=q_n * H, speed=V, mass=M,
                                    time_step=H)  # fmt: skip
        s = c.hunt_crossley_dissipation * V
        return (1.0 + 1e-10) * s, H * np.sqrt(c.point_contact_stiffness / M)

    ok, _, _, _, _ = table_designs(e, V * one, M * one, 0 * one, q, H, design)
    assert not ok.any()


def test_designs_off_the_tables_are_those_without_them(monkeypatch):
    rng = np.random.default_rng(38)
    e, q = _targets(25, MIN_SERVED, rng)
    c = drake.point_contact_for(restitution=e, contact_time=q * H, speed=V, mass=M,
                                time_step=H)  # fmt: skip
    seen = _spy(monkeypatch)
    monkeypatch.setattr(change_table, "MIN_TARGETS", 10**9)  # no table: Broyden's steps
    x = drake.point_contact_for(restitution=e, contact_time=q * H, speed=V, mass=M,
                                time_step=H)  # fmt: skip
    assert seen == []  # (no table to fill: not even asked)
    # two designs that each meet the tolerances (1e-12 in e) are as close as those allow
    np.testing.assert_allclose(c.hunt_crossley_dissipation, x.hunt_crossley_dissipation,
                               rtol=2e-11)  # fmt: skip
    np.testing.assert_allclose(c.point_contact_stiffness, x.point_contact_stiffness, rtol=2e-10)


def test_an_end_state_with_too_few_targets_gets_no_table(monkeypatch):
    rng = np.random.default_rng(39)
    e1, q1 = _targets(24, MIN_SERVED, rng)
    e2, q2 = _targets(33, MIN_TARGETS - 1, rng)
    e, q = np.concatenate([e1, e2]), np.concatenate([q1, q2])
    one = np.ones(e.size)

    def design(e_n, q_n):  # a stand-in for the caller's path: the nodes' exact designs
        # (by the nested iteration, to its tolerance of 1e-12: a table a little coarser)
        c = drake.point_contact_for(restitution=e_n, contact_time=q_n * H, speed=V, mass=M,
                                    time_step=H)  # fmt: skip
        s = c.hunt_crossley_dissipation * V
        return s, H * np.sqrt(c.point_contact_stiffness / M)

    ok, k, d, _, _ = table_designs(e, V * one, M * one, 0 * one, q, H, design)
    assert ok[: e1.size].mean() > 0.9
    assert not ok[e1.size :].any()
    assert np.isnan(k[e1.size :]).all()
    assert np.isnan(d[e1.size :]).all()


def test_a_table_with_a_node_left_undesigned_designs_nothing(monkeypatch):
    monkeypatch.setattr(change_table, "MIN_TARGETS", 600)  # (halves of 512: too few)
    rng = np.random.default_rng(40)
    e, q = _targets(24, MIN_SERVED, rng)
    one = np.ones(e.size)
    asked = []

    def design(e_n, q_n):  # as if the caller's path left one node to its iteration
        asked.append(e_n.size)
        s, w = 1.0 + 0 * e_n, 0.1 + 0 * e_n
        s[7] = np.nan
        return s, w

    ok, k, _, _, _ = table_designs(e, V * one, M * one, 0 * one, q, H, design)
    assert asked == [NODES_E * NODES_PHASE]  # (no window of phases helps it; its halves
    # would serve too few targets to be tried)
    assert not ok.any()
    assert np.isnan(k).all()


def test_a_wrong_table_designs_nothing():
    """Where the table is off (here: every node the same design), the one exact
    evaluation refuses each target instead of passing the table's value on."""
    rng = np.random.default_rng(41)
    e, q = _targets(24, MIN_SERVED, rng)
    one = np.ones(e.size)

    def design(e_n, q_n):
        return 1.0 + 0 * e_n, 0.13 + 0 * e_n

    ok, _, _, _, _ = table_designs(e, V * one, M * one, 0 * one, q, H, design)
    assert not ok.any()


def test_a_table_across_a_second_change_is_refused_for_a_narrower_window(monkeypatch):
    """Under gravity, near the ends of the phase interval, the larger restitutions' designs
    change a second time: a table over those phases has a tail of ~1e-6 and is built
    again over the next window of phases."""
    rng = np.random.default_rng(43)
    e, q = _targets(22, MIN_SERVED, rng)
    e = 0.5 + 0.1 * (e - 0.3) / 0.3  # 0.5..0.6
    monkeypatch.setattr(change_table, "PHASES_PRESSED", ((0.005, 0.995), (0.05, 0.95)))
    one = np.ones(e.size)
    asked = []

    def design(e_n, q_n):
        asked.append(q_n - 22.5)
        c = drake.point_contact_for(restitution=e_n, contact_time=q_n * H, speed=V, mass=M,
                                    gravity=9.81, time_step=H)  # fmt: skip
        return c.hunt_crossley_dissipation * V, H * np.sqrt(c.point_contact_stiffness / M)

    ok, k, d, _, _ = table_designs(e, V * one, M * one, 9.81 * one, q, H, design)
    assert len(asked) == 2  # the wide window's table refused
    assert asked[1].min() > 0.05
    assert asked[1].max() < 0.95
    phase = q - 22.5
    inside = (phase >= 0.05) & (phase < 0.95)
    assert ok[inside].mean() > 0.8
    # beyond the window the table is extrapolated, its designs kept where their
    # evaluation holds (across the second change it does not: it misses the target)
    beyond = ok & ~inside
    assert 0 < np.count_nonzero(beyond) < np.count_nonzero(~inside)
    fresh = drake.predict(stiffness=k[beyond], dissipation=d[beyond], mass=M, speed=V,
                          gravity=9.81, time_step=H)  # fmt: skip
    assert np.abs(fresh.restitution - e[beyond]).max() <= 1.05e-12
    assert np.abs(fresh.contact_time / (q[beyond] * H) - 1.0).max() <= 1.05e-10


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_the_evaluations_few_gauss_nodes_give_the_mean_to_rounding(gravity):
    """The one evaluation takes ``NODES`` Gauss nodes per panel: on contacts of at least
    ``MIN_STEPS`` steps whose change holds, the same mean as 16 nodes to rounding."""
    rng = np.random.default_rng(44)
    e, q = rng.uniform(0.3, 0.6, 300), rng.uniform(MIN_STEPS, 60.0, 300) + 0.5
    c = drake.point_contact_for(restitution=e, contact_time=q * H, speed=V, mass=M,
                                gravity=gravity, time_step=H)  # fmt: skip
    k, d, one = c.point_contact_stiffness, c.hunt_crossley_dissipation, np.ones(e.size)
    rows = (k, d, M * one, gravity * one, V * one)
    held = jump_holds(*rows, H, q)
    assert held.mean() > 0.9
    few = jump_means(*rows, H, q, nodes=NODES).restitution
    many = jump_means(*rows, H, q, nodes=16).restitution
    assert np.abs(few - many)[held].max() <= 1e-15


def test_a_table_with_nodes_left_at_one_end_is_built_again_in_halves(monkeypatch):
    """Where the caller's path leaves nodes at one end of a box undesigned (or the
    one-change structure breaks there), the box is built again as two halves, and the
    other half serves its targets."""
    rng = np.random.default_rng(46)
    e, q = rng.uniform(0.3, 0.5, 1000), 25.5 + rng.uniform(0.0, 1.0, 1000)
    monkeypatch.setattr(change_table, "MIN_TARGETS", 400)
    monkeypatch.setattr(change_table, "MIN_SERVED", 400)
    boxes = []

    def design(e_n, q_n):  # as if the caller's path left the nodes below 0.35
        boxes.append((round(float(e_n.min()), 2), round(float(e_n.max()), 2)))
        c = drake.point_contact_for(restitution=e_n, contact_time=q_n * H, speed=V, mass=M,
                                    time_step=H)  # fmt: skip
        s = np.where(e_n < 0.35, np.nan, c.hunt_crossley_dissipation * V)
        return s, H * np.sqrt(c.point_contact_stiffness / M)

    one = np.ones(e.size)
    ok, k, d, _, _ = table_designs(e, V * one, M * one, 0 * one, q, H, design)
    assert len(boxes) == 2  # the whole box, then its halves together
    assert not ok[e < 0.4].any()
    assert ok[e > 0.4].mean() > 0.9
    p = drake.predict(stiffness=k[ok], dissipation=d[ok], mass=M, speed=V, time_step=H)
    assert np.abs(p.restitution - e[ok]).max() <= 1.05e-12
    assert np.abs(p.contact_time / (q[ok] * H) - 1.0).max() <= 1.05e-10


def test_a_call_too_small_for_a_table_builds_no_coarse_table_for_it(monkeypatch):
    """By overlap, the coarse table that tells targets their likely end states is built
    only where the call could fill a table (it cost 30 % of a call of 512 for nothing):
    here 512 targets spread over contacts of 24-73 steps, ~10 per step."""
    asked = []
    monkeypatch.setattr(step_table, "_likely_steps", lambda *args: asked.append(1))
    rng = np.random.default_rng(48)
    e, x = rng.uniform(0.3, 0.6, 512), rng.uniform(6e-3, 1.2e-2, 512)
    one = np.ones(e.size)
    ok, _, _, summaries = stepped_designs(e, V * one, M * one, 0 * one, x, H, "lagged",
                                          "max_penetration")  # fmt: skip
    assert asked == []
    assert ok.mean() > 0.9  # (by the per-call table of phase means)
    assert np.isnan(summaries).all()


def test_the_few_targets_the_tables_leave_are_designed_by_the_table_of_means():
    """Targets no table serves, however few, take the per-call table of phase means
    (cheaper than the caller's iteration even for one: 0.06-0.26 s for 1-250 targets,
    against 0.1-1.2 s):
    before, fewer than 256 were left to the caller."""
    rng = np.random.default_rng(49)
    e, q = _targets(24, MIN_SERVED, rng)
    e = np.concatenate([e, rng.uniform(0.15, 0.2, 20)])  # below the tables' restitutions
    q = np.concatenate([q, 24.5 + rng.uniform(0.0, 1.0, 20)])
    one = np.ones(e.size)
    ok, k, d, summaries = stepped_designs(e, V * one, M * one, 0 * one, q * H, H, "lagged",
                                          "contact_time")  # fmt: skip
    assert np.isfinite(summaries[0, :-20]).mean() > 0.8  # the table's
    assert np.isnan(summaries[0, -20:]).all()  # the table of means'
    assert ok[-20:].all()
    fresh = drake.predict(stiffness=k[-20:], dissipation=d[-20:], mass=M, speed=V, time_step=H)
    assert np.abs(fresh.restitution - e[-20:]).max() <= 1.05e-12
    assert np.abs(fresh.contact_time / (q[-20:] * H) - 1.0).max() <= 1.05e-10


def test_whether_a_call_may_fill_a_table_counts_per_end_state():
    """``may_fill_a_table`` counts the targets of each end state ``floor(q - 1/2)``: one
    stray target elsewhere neither splits them (bins from the call's shortest contact
    did: 300 of one end state fell into two of ~150) nor costs memory by its distance
    (a bin per step up to a stray at 3e7 steps took 480 MB; review)."""
    rng = np.random.default_rng(51)
    e = rng.uniform(0.3, 0.6, 1100)
    q = np.concatenate([25.5 + rng.uniform(0.0, 1.0, 300), rng.uniform(40.0, 120.0, 800)])
    for stray in (12.0, 3e7):
        q[-1] = stray
        assert change_table.may_fill_a_table(e, q, by_overlap=False)
    q[:300] = rng.uniform(40.0, 120.0, 300)  # spread: ~14 per end state
    assert not change_table.may_fill_a_table(e, q, by_overlap=False)
    assert not change_table.may_fill_a_table(e[:MIN_SERVED - 1], q[:MIN_SERVED - 1],
                                             by_overlap=False)  # fmt: skip


def _made_tables():
    """Keys and tables of end states 20-22 as ``table_designs`` holds them, from
    polynomials (the reading needs no physics): state 21 in two boxes that overlap (a
    target in both reads the first), 20 and 22 wider, so that the targets of 21 beyond
    its boxes ask both neighbours; ``J`` of 1-3 overlaps, two windows of phases."""
    x, y = np.meshgrid(chebyshev_points(NODES_E), chebyshev_points(8), indexing="ij")
    layout = [(20, (0.3, 0.65), 2, (0.0, 1.0)), (21, (0.3, 0.5), 3, (0.02, 0.98)),
              (21, (0.4, 0.6), 1, (0.0, 1.0)), (22, (0.3, 0.65), 2, (0.02, 0.98))]  # fmt: skip
    keys, tables = [], []
    for i, (b, box, j, window) in enumerate(layout):
        s = 1.0 + 0.1 * x + 0.2 * y + 0.05 * i * x * y
        w = 0.1 + 0.01 * x * y + 0.002 * i * y**2
        over = [b + 0.5 + 1.1 * y + 0.1 * k * x - 0.05 * k * (y - 0.2 * k) ** 2 for k in range(j)]
        coef, overlaps = (chebyshev_tables.fit(np.stack(a), 1e-9) for a in ([s, w], over))
        keys.append((b, box, None))
        tables.append((window, coef, overlaps))
    return keys, tables


def test_the_tables_read_in_turn_are_those_read_one_at_a_time():
    """``table_designs`` reads each offset group's tables in turns, every table of a turn
    in one phase solve: each target's start, change and table are those of asking the
    tables one at a time in their order (the loop it replaced), to rounding; the
    Jacobians of all tables' starts at once are each table's alone. Targets or tables
    out of line would be off by the tables' spread (0.01-0.2)."""
    rng = np.random.default_rng(53)
    keys, tables = _made_tables()
    n = 3000
    e, likely = rng.uniform(0.3, 0.7, n), rng.choice([20.0, 21.0, 22.0], n)
    q = likely + 0.5 + rng.uniform(-1.6, 1.6, n)
    keys = [(b, box, (e >= box[0]) & (e <= box[1]) & (np.abs(likely - b) <= 1)) for b, box, _
            in keys]  # fmt: skip
    served = [np.flatnonzero(serves) for _, _, serves in keys]
    offsets = ((0.0,), (-1.0, 1.0))
    turns = [np.full(n, np.nan) for _ in range(3)] + [np.full(n, -1)]
    for group in offsets:
        change_table._read_in_turn(group, likely, keys, tables, served, e, q, True, turns)
    alone = [np.full(n, np.nan) for _ in range(3)] + [np.full(n, -1)]
    s, w, change, source = alone
    for group in offsets:  # (one table at a time, as before)
        for index, ((b, box, serves), table) in enumerate(zip(keys, tables, strict=True)):
            rows = np.flatnonzero(serves & np.isin(b - likely, group) & np.isnan(s))
            read = change_table._read([(b, box, table, e[rows], q[rows])], True)[0]
            s[rows], w[rows], change[rows] = read
            source[rows[np.isfinite(read[0])]] = index
    np.testing.assert_array_equal(turns[3], source)
    for mine, theirs in zip(turns[:3], alone[:3], strict=True):
        np.testing.assert_array_equal(np.isnan(mine), np.isnan(theirs))
        np.testing.assert_allclose(mine, theirs, rtol=1e-13, atol=0)
    # every kind of target: its likely table's, a neighbour's, both boxes', none
    assert np.isin(np.arange(4), source).all()
    assert np.count_nonzero(source < 0) > 100
    asked_both = (e >= 0.4) & (e <= 0.5) & (likely == 21)
    assert np.count_nonzero(asked_both & (source == 1)) > 50
    assert np.count_nonzero((likely == 21) & np.isin(source, [0, 3])) > 50
    rows = np.flatnonzero(source >= 0)[::3]
    together = change_table._target_slopes(keys, tables, source[rows], e[rows], q[rows],
                                           s[rows], w[rows])  # fmt: skip
    assert np.isfinite(together).all(axis=(1, 2)).mean() > 0.9
    for index, ((b, box, _), table) in enumerate(zip(keys, tables, strict=True)):
        some = rows[source[rows] == index]
        de, dq = 1e-6 * (box[1] - box[0]), 1e-6 * q[some]  # (the table's own differences)
        moved = [(b, box, table, e[some] + de, q[some]), (b, box, table, e[some], q[some] + dq)]
        (s_e, w_e, _), (s_q, w_q, _) = (change_table._read([read], True)[0] for read in moved)
        forward = np.moveaxis([[(s_e - s[some]) / de, (s_q - s[some]) / dq],
                               [(w_e - w[some]) / de, (w_q - w[some]) / dq]], 2, 0)  # fmt: skip
        fine = np.isfinite(forward).all(axis=(1, 2))
        np.testing.assert_allclose(together[source[rows] == index][fine],
                                   np.linalg.inv(forward[fine]), rtol=1e-8, atol=0)  # fmt: skip
