"""The root search of Drake's phase summary (``phases._roots``) against the multisection
on the full contact's end state, and its cost.

Checked on random contacts of 2 to 100 steps with damping numbers ``d v`` to 8 (the
impulse floor above 5.5, which it leaves to the multisection, included): every change
it reports is one of
``step_contact``'s own (the slow exact path, not the margin: its end state at ``a`` is
the left one, at ``c`` another, ``c - a`` within the width), it lies where the
independent multisection on the end state puts it, up to the band where rounding flips
the end state back and forth, and it misses none the multisection finds; on smooth
contacts it spends about 9 margin runs per change (the former search: 18), and small
batches few calls.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.drake import phases
from impactsym.engines.drake.stepping import step_contact


def _designs(n, seed, dv_hi=8.0):
    """Random contacts of 2 to 100 steps, damping numbers ``d v`` up to ``dv_hi``, half
    under gravity, steps of 1 ms and 0.1 ms."""
    rng = np.random.default_rng(seed)
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.5, 3.0, n)
    w = np.pi / rng.uniform(2.0, 100.0, n)
    d = rng.uniform(0.0, dv_hi, n) / v
    g = np.where(rng.uniform(size=n) < 0.5, 0.0, 9.81)
    h = np.where(rng.uniform(size=n) < 0.5, 1e-3, 1e-4)
    return m * (w / h) ** 2, d, m, g, v, h


def _searches(monkeypatch, designs, approximation):
    """The root search's arguments in a phase summary of ``designs`` (all its changes)."""
    seen = []
    search = phases._roots

    def spy(*args):
        seen.append(tuple(x.copy() if isinstance(x, np.ndarray) else x for x in args))
        return search(*args)  # (the summary writes the brackets found into a and c)

    monkeypatch.setattr(phases, "_roots", spy)
    k, d, m, g, v, h = designs
    phases.phase_summary(k, d, 0.0, m, g, v, h, approximation=approximation, bounds=False)
    monkeypatch.undo()
    return seen[0]  # the base grid's (elements redone on a finer grid search again)


def _end_state(k, d, m, g, v, h, p, approximation):
    """The end state of ``step_contact`` (the step it ends at, ``-1`` sticking)."""
    r = step_contact(k, d, 0.0, m, g, v, h, p, approximation=approximation, stuck_peaks=False)
    with np.errstate(invalid="ignore"):
        return np.where(r.sticks, -1, np.rint(r.contact_time / h - p))


@pytest.mark.parametrize(("approximation", "seed"), [("lagged", 1), ("tamsi", 2)])
def test_the_changes_found_are_the_multisections(approximation, seed, monkeypatch):
    designs = _designs(1200, seed)
    flat, run, key, ii, a, c, left, right = _searches(monkeypatch, designs, approximation)
    found, a_r, c_r, _ = phases._roots(flat, run, key, ii, a, c, left, right)
    d_b, v_b = flat[1][ii], flat[5][ii]
    floor = d_b * v_b > phases._FLOOR  # (there, and sticking, the multisection's)
    searched = (np.minimum(left, right) >= 0) & ~floor
    assert searched.sum() > 600
    assert floor.sum() > 150  # the impulse floor is in the sample, and left alone
    assert not found[floor].any()
    assert np.all(found[searched])  # it gives up on none here (the old search: 2 in 2000)
    a_m = phases._multisection(run, key, ii, a.copy(), c.copy(), left)[0]
    # each a change of step_contact's own end state, within the width
    assert np.all(c_r[found] - a_r[found] <= phases._WIDTH)
    assert np.all((a_r[found] >= a[found]) & (c_r[found] <= c[found]))
    k, d, m, g, v, h = (x[ii[found]] for x in designs)
    at_a = _end_state(k, d, m, g, v, h, a_r[found], approximation)
    at_c = _end_state(k, d, m, g, v, h, c_r[found], approximation)
    np.testing.assert_array_equal(at_a, left[found])
    assert np.all(at_c != left[found])
    # where the multisection puts it, up to the rounding band of the end state (measured
    # for both searches against it: up to 1e-12 of a phase for d v < 2, 2e-11 to 5.5;
    # a wrong change would be ~1e-3 away)
    dv = d * v
    gap = np.abs(a_r[found] - a_m[found])
    assert np.mean(gap <= 1e-12) > 0.75  # (measured 0.85-0.88; half within 2 widths)
    assert np.all(gap[dv < 2.0] < 3e-12)
    assert np.all(gap < 5e-11)


def _counted(monkeypatch):
    """Margin runs and calls of ``end_margin`` in the phase summaries."""
    count = {"runs": 0, "calls": 0}
    margin = phases.end_margin

    def counted(*args):
        count["runs"] += np.size(args[6])
        count["calls"] += 1
        return margin(*args)

    monkeypatch.setattr(phases, "end_margin", counted)
    return count


def test_a_change_costs_about_nine_margins(monkeypatch):
    # large batches (one phase per bracket and call; here for all calls): 9-10 margins
    # per change measured; the former search, two phases per call, took 18 on these
    designs = _designs(2000, 3, dv_hi=4.0)
    flat, run, key, ii, a, c, left, right = _searches(monkeypatch, designs, "lagged")
    changes = np.sum(np.minimum(left, right) >= 0)
    monkeypatch.setattr(phases, "_FAN_ROWS", 0)
    count = _counted(monkeypatch)
    found = phases._roots(flat, run, key, ii, a, c, left, right)[0]
    assert found.sum() == changes > 1000
    assert count["runs"] < 11.0 * changes, count["runs"] / changes


def test_small_batches_take_few_calls(monkeypatch):
    # few brackets take a fan of phases per call (a call costs ~0.8 ms whatever its few
    # rows): the former search took 14-21 calls for 20 designs, 17-21 for 100
    count = _counted(monkeypatch)
    for n, most in ((20, 11), (100, 15)):
        k, d, m, g, v, h = _designs(n, n)
        count["calls"] = 0
        phases.phase_summary(k, d, 0.0, m, g, v, h, approximation="lagged")
        assert 0 < count["calls"] <= most, (n, count["calls"])


def test_on_the_impulse_floor_the_multisection_decides(monkeypatch):
    # a contact of 2.7 steps at d v = 18.8 whose end state goes 12 -> 13 -> 12 -> 11 inside
    # one grid interval: the margin of state 11 sees only the last change (found by
    # review: the mean contact time was 3.8e-3 steps off); above the floor the
    # multisection decides, which keeps the first change
    k, d, m, v, h = (
        3654750793.465937,
        130.60527999472777,
        0.27754566649521456,
        0.14394028457659697,
        1e-05,
    )
    assert d * v > phases._FLOOR
    summary = phases.phase_summary(k, d, 0.0, m, 0.0, v, h, approximation="lagged")
    search = phases._roots

    def none_found(flat, run, key, ii, a, c, left, right):
        found, a, c, at_found = search(flat, run, key, ii, a, c, left, right)
        return np.zeros_like(found), a, c, at_found

    monkeypatch.setattr(phases, "_roots", none_found)
    alone = phases.phase_summary(k, d, 0.0, m, 0.0, v, h, approximation="lagged")
    assert summary.contact_time == alone.contact_time
    assert summary.contact_time_max == alone.contact_time_max
