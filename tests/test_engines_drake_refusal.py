"""A big discrete design call holding one target out of reach: refused quickly, naming
that target, and the others designed once it is gone.

Before: under gravity the step table's box reached heavily damped soft corners that
settle without turning back, each stepped to ``MAX_STEPS`` (2e6 updates of the Python
loop per call: 256 targets over 8-100 steps took 136 s of table), and where the
iteration refused the targets the table left, the whole call was iterated again. The
work is counted here (the loop's updates per call, the targets iterated), not timed.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import drake
from impactsym.engines.drake import design, jump_means, phases, stepping
from impactsym.engines.drake.stepping import contact_ends, end_state

H = 1e-3
BAD = 7


def _call():
    """257 lagged targets under gravity, 8 to 100 steps of contact; one out of reach (a
    restitution the undamped step does not give at its contact time)."""
    rng = np.random.default_rng(5)
    e = rng.uniform(0.3, 0.6, 257)
    t = rng.uniform(8.0, 100.0, 257) * H
    e[BAD] = 0.999
    return e, t


def _counted_updates(monkeypatch):
    """The updates of the step loop (``stepping._update``: the phase summaries' runs and
    ``end_margin``'s, and the runs of the change's equations, ``jump_means``) in a list
    with one entry per run of the phase summaries or the change's equations (all
    blocks), each update counted on the last run begun (a phase summary always runs its
    grid before any end margin)."""
    updates, lean_update = [], stepping._update

    def counting(run):
        def counted(*args, **options):
            updates.append(0)
            return run(*args, **options)

        return counted

    def update(*args, **options):
        updates[-1] += 1
        return lean_update(*args, **options)

    monkeypatch.setattr(phases, "contact_ends", counting(contact_ends))
    monkeypatch.setattr(jump_means, "contact_ends", counting(contact_ends))
    monkeypatch.setattr(jump_means, "end_state", counting(end_state))
    monkeypatch.setattr(stepping, "_update", update)
    return updates


def test_one_target_out_of_reach_is_refused_quickly_and_named(monkeypatch):
    e, t = _call()
    with pytest.raises(ValueError, match="out of reach") as alone:
        drake.point_contact_for(restitution=e[BAD], contact_time=t[BAD], speed=1.0, mass=0.1,
                                gravity=9.81, time_step=H)  # fmt: skip
    updates, iterated = _counted_updates(monkeypatch), []

    def spy(*args):
        iterated.append(args[0].size)
        return iterate(*args)

    iterate = design._iterate
    monkeypatch.setattr(design, "_iterate", spy)
    with pytest.raises(ValueError, match="out of reach") as many:
        drake.point_contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1, gravity=9.81,
                                time_step=H)  # fmt: skip
    assert str(many.value) == str(alone.value)  # the target out of reach, and its reason
    # the table's calls: a few hundred updates each (a settled corner took 2e6 before)
    assert sum(updates) < 2e5, sum(updates)
    assert max(updates) < 5_000
    # only the targets the table left are iterated, never the whole call again
    assert iterated
    assert max(iterated) < e.size // 4


def test_without_it_the_same_call_is_designed():
    e, t = _call()
    keep = np.arange(e.size) != BAD
    c = drake.point_contact_for(restitution=e[keep], contact_time=t[keep], speed=1.0, mass=0.1,
                                gravity=9.81, time_step=H)  # fmt: skip
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=0.1, speed=1.0, gravity=9.81, time_step=H)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e[keep], rtol=1e-11)
    np.testing.assert_allclose(p.contact_time, t[keep], rtol=1e-9)
    assert not np.any(p.sticks)


def test_designs_by_max_penetration_do_not_step_settled_corners_either(monkeypatch):
    # the same call by largest overlap: its table ran with the peaks of sticking phases
    # wanted, so the settled corners were stepped to 2e6 updates (142 s; found by review)
    rng = np.random.default_rng(5)
    e, x = rng.uniform(0.3, 0.6, 257), rng.uniform(8.0, 100.0, 257) * H / np.pi
    updates = _counted_updates(monkeypatch)
    c = drake.point_contact_for(restitution=e, max_penetration=x, speed=1.0, mass=0.1,
                                gravity=9.81, time_step=H)  # fmt: skip
    assert max(updates) < 5_000, max(updates)
    monkeypatch.undo()
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=0.1, speed=1.0, gravity=9.81, time_step=H)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e, rtol=1e-11)
    np.testing.assert_allclose(p.max_penetration, x, rtol=1e-9)
    assert not np.any(p.sticks)
