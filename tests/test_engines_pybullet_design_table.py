"""pybullet.contact_for from a table of the phase means (many targets of one contact).

A call with ``TABLE_GROUP`` or more targets of one contact starts each design from the
inverse of a tabulated phase mean and refines it on the exact phase means; the table
never decides a design. The designs are checked against a fresh ``predict`` (the exact
phase summary of the returned body values, not the evaluations the design accepted),
against the textbook path's designs of the same targets, and one design that Newton from
the textbook start misses is run in PyBullet itself, phase by phase.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from impactsym.engines import pybullet as pyb
from impactsym.engines.pybullet.design import TABLE_GROUP

H = 1 / 240
BASE = {"speed": 1.0, "mass": 0.1}


def _miss(d, e, t, gravity=0.0):
    """Largest relative miss of a fresh prediction of the designs ``d``."""
    p = pyb.predict(stiffness=d.stiffness, damping=d.damping, gravity=gravity, **BASE)
    assert not np.any(p.sticks)
    return np.max(np.abs(p.restitution / e - 1.0)), np.max(np.abs(p.contact_time / t - 1.0))


@pytest.mark.parametrize("steps", [(10.0, 40.0), None])
def test_random_targets_from_the_table_hit_a_fresh_prediction(steps):
    rng = np.random.default_rng(7)
    n = TABLE_GROUP + 44
    e = rng.uniform(0.2, 0.5, n)
    t = None if steps is None else rng.uniform(*steps, n) * H
    d = pyb.contact_for(restitution=e, contact_time=t, **BASE)
    miss_e, miss_t = _miss(d, e, 10 * H if t is None else t)
    # accepted at 1e-9 in e and ln t (as the textbook path); predict agrees to ~1e-13
    assert miss_e < 1.1e-9
    assert miss_t < 1.1e-9


def test_table_designs_are_the_textbook_paths_designs():
    rng = np.random.default_rng(8)
    e = rng.uniform(0.2, 0.5, TABLE_GROUP)
    t = rng.uniform(10.0, 30.0, TABLE_GROUP) * H
    table = pyb.contact_for(restitution=e, contact_time=t, **BASE)
    # the first 20 alone: below TABLE_GROUP, Newton from the textbook start
    alone = pyb.contact_for(restitution=e[:20], contact_time=t[:20], **BASE)
    # both hit the targets to 1e-9; the map's Jacobian is of order one, so the designs
    # agree to a few 1e-9
    np.testing.assert_allclose(table.stiffness[:20], alone.stiffness, rtol=2e-8)
    np.testing.assert_allclose(table.damping[:20], alone.damping, rtol=2e-8)


def test_small_calls_do_not_depend_on_their_neighbours():
    rng = np.random.default_rng(9)
    n = TABLE_GROUP - 1  # the largest call without a table
    e = rng.uniform(0.2, 0.5, n)
    t = rng.uniform(10.0, 40.0, n) * H
    d = pyb.contact_for(restitution=e, contact_time=t, **BASE)
    for i in (0, 77, n - 1):
        one = pyb.contact_for(restitution=e[i], contact_time=t[i], **BASE)
        assert one.stiffness == d.stiffness[i]
        assert one.damping == d.damping[i]


def test_a_table_serves_only_the_contact_it_was_built_for():
    rng = np.random.default_rng(10)
    e = rng.uniform(0.25, 0.45, TABLE_GROUP + 3)
    speed = np.full(e.size, 1.0)
    speed[-3:] = 2.0  # three targets of another contact: the textbook path
    d = pyb.contact_for(restitution=e, speed=speed, mass=0.1)
    p = pyb.predict(stiffness=d.stiffness, damping=d.damping, speed=speed, mass=0.1)
    assert np.max(np.abs(p.restitution / e - 1.0)) < 1.1e-9
    assert np.max(np.abs(p.contact_time / (10 * H) - 1.0)) < 1.1e-9
    alone = pyb.contact_for(restitution=e[-3:], speed=2.0, mass=0.1)
    np.testing.assert_array_equal(d.stiffness[-3:], alone.stiffness)


def test_gravity_targets_the_textbook_start_misses_are_designed():
    rng = np.random.default_rng(11)
    n = TABLE_GROUP
    e = rng.uniform(0.4, 0.45, n)
    t = rng.uniform(9.8, 10.2, n) * H
    d = pyb.contact_for(restitution=e, contact_time=t, gravity=9.81, **BASE)
    miss_e, miss_t = _miss(d, e, t, gravity=9.81)
    assert miss_e < 1.1e-9
    assert miss_t < 1.1e-9


def test_pybullet_runs_a_design_the_textbook_start_missed_as_predicted():
    if os.environ.get("CI") != "true":  # CI installs the engine: there it must run
        pytest.importorskip("pybullet")
    from impactsym.engines.pybullet.driver import pybullet_steps

    # e = 0.4431 at 10 steps under gravity: Newton from the textbook start breaks off
    # (the phases stick at its damping); the table's start finds the pair
    g = {"gravity": 9.81, **BASE}
    d = pyb.contact_for(restitution=0.4431, contact_time=10 * H, **g)
    assert abs(d.restitution / 0.4431 - 1.0) < 1e-9
    assert abs(d.contact_time / (10 * H) - 1.0) < 1e-9
    phases = np.array([0.0, 0.25, 0.5, 0.75, 0.999])
    engine = pybullet_steps(stiffness=d.stiffness, damping=d.damping, phase=phases, **g)
    model = pyb.predict(stiffness=d.stiffness, damping=d.damping, phase=phases, **g)
    assert not engine.sticks.any()
    np.testing.assert_allclose(engine.restitution, model.restitution, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(engine.contact_time, model.contact_time, rtol=1e-12)


def test_an_unreachable_target_in_a_large_call_is_refused_by_name():
    rng = np.random.default_rng(12)
    e = rng.uniform(0.25, 0.45, TABLE_GROUP)
    t = np.full(e.size, 20 * H)
    e[100], t[100] = 0.31, 2 * H  # two steps: no PyBullet contact at this step
    with pytest.raises(ValueError, match=r"restitution = 0\.31 with contact_time.*element 100,"):
        pyb.contact_for(restitution=e, contact_time=t, **BASE)


@pytest.mark.parametrize("setting", [{"processing_threshold": 0.0}, {"substeps": 2}])
def test_table_designs_under_other_engine_settings_hit_a_fresh_prediction(setting):
    rng = np.random.default_rng(13)
    e = rng.uniform(0.25, 0.45, TABLE_GROUP)
    t = rng.uniform(12.0, 20.0, TABLE_GROUP) * H
    d = pyb.contact_for(restitution=e, contact_time=t, **BASE, **setting)
    p = pyb.predict(stiffness=d.stiffness, damping=d.damping, **BASE, **setting)
    assert np.max(np.abs(p.restitution / e - 1.0)) < 1.1e-9
    assert np.max(np.abs(p.contact_time / t - 1.0)) < 1.1e-9


def test_a_target_designed_alone_is_designed_beside_others():
    # element 73 is designed alone; beside the other 99 Newton misses it and the table
    # shared with another miss did too (its box and grid depend on the targets)
    rng = np.random.default_rng(4)
    e, t = rng.uniform(0.38, 0.46, 256), rng.uniform(9, 12, 256) * H
    options = {"speed": 1.0, "mass": 0.1, "gravity": 9.81}
    alone = pyb.contact_for(restitution=e[73], contact_time=t[73], **options)
    among = pyb.contact_for(restitution=e[:100], contact_time=t[:100], **options)
    assert among.stiffness[73] == pytest.approx(alone.stiffness, rel=1e-7)
    assert abs(among.restitution[73] - e[73]) < 1e-9
    assert among.contact_time[73] == pytest.approx(t[73], rel=1e-9)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_the_prediction_of_table_designs_is_a_fresh_predict(gravity):
    """Designs from a table report the summary of their accepting exact evaluation (no
    second evaluation): every field must be what ``predict`` computes afresh from the
    returned body values (pair rules applied again, ranges included)."""
    rng = np.random.default_rng(12)
    e = rng.uniform(0.4, 0.45, TABLE_GROUP) if gravity else rng.uniform(0.2, 0.5, TABLE_GROUP)
    t = (rng.uniform(9.8, 10.2, TABLE_GROUP) if gravity else rng.uniform(10, 40, TABLE_GROUP)) * H
    d = pyb.contact_for(restitution=e, contact_time=t, gravity=gravity, **BASE)
    p = pyb.predict(stiffness=d.stiffness, damping=d.damping, gravity=gravity, **BASE)
    for name in ("pair_stiffness", "pair_damping", "stick_fraction"):
        np.testing.assert_array_equal(getattr(d, name), getattr(p, name), err_msg=name)
    for name in ("restitution", "contact_time", "restitution_range", "contact_time_range"):
        np.testing.assert_allclose(getattr(d, name), getattr(p, name), rtol=1e-12, err_msg=name)
    assert not np.any(d.sticks)


def test_tables_holding_sticking_points_design_without_warnings(monkeypatch):
    # under gravity the coarse tables hold sticking points (contact time inf); their
    # stencils are masked, and the interpolation's inf * 0 must not warn (the suite turns
    # warnings into errors, as a user's -W error does)
    from impactsym.engines.pybullet import design_table

    seen = []
    init = design_table._Table.__init__

    def recording(self, *args):
        init(self, *args)
        seen.append(bool(np.all(np.isfinite(self.values))))

    monkeypatch.setattr(design_table._Table, "__init__", recording)
    rng = np.random.default_rng(0)
    e, t = rng.uniform(0.3, 0.5, 300), rng.uniform(10, 30, 300) / 240
    d = pyb.contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1, gravity=9.81)
    assert not all(seen)  # a table held sticking points
    np.testing.assert_allclose(d.restitution, e, rtol=1e-9)


def test_table_designs_without_gravity_hit_their_targets_by_the_bisection():
    """Designs of a contact-time array without gravity (their exact evaluations from one
    phase interval where every phase ends final) checked by the grid-and-bisection
    phase summary of the plain map, which shares neither the roots nor that proof: both
    targets to the acceptance's 1e-9 (rounding aside), the reported prediction to 1e-11."""
    from impactsym.engines.pybullet.phases import phase_summary
    from impactsym.engines.pybullet.stepping import step_pattern

    rng = np.random.default_rng(13)
    e = rng.uniform(0.2, 0.5, TABLE_GROUP)
    t = rng.uniform(10.0, 40.0, TABLE_GROUP) * H
    d = pyb.contact_for(restitution=e, contact_time=t, **BASE)
    pick = rng.choice(TABLE_GROUP, 40, replace=False)
    bisected = phase_summary(d.pair_stiffness[pick], d.pair_damping[pick], BASE["mass"],
                             BASE["speed"], 0.0, H, substeps=1, slop=1e-5,
                             processing_threshold=np.inf, pattern=step_pattern)  # fmt: skip
    assert np.max(np.abs(bisected.restitution / e[pick] - 1.0)) < 1.1e-9
    assert np.max(np.abs(np.log(bisected.contact_time / t[pick]))) < 1.1e-9
    np.testing.assert_allclose(d.restitution[pick], bisected.restitution, rtol=1e-11)
    np.testing.assert_allclose(d.contact_time[pick], bisected.contact_time, rtol=1e-11)


def _known_map(u, z):
    """A map with a known inverse (``e = exp(-zeta)``, ``ln t = -u/2 + z/10``), ``inf``
    contact time (a sticking point) where ``zeta > 2``."""
    return np.exp(-np.exp(z)), np.where(z > np.log(2.0), np.inf, -0.5 * u + 0.1 * z)


def test_the_tables_inverse_in_passes_gives_each_target_its_own_numbers():
    # at and invert run in passes of _PASS columns: every column's numbers are those of
    # a call of its own, and the interpolant meets the known map to its cubic's error
    from impactsym.engines.pybullet import design_table as dt

    table = dt._Table(_known_map, np.array([4.0, -2.0]), np.array([7.0, 1.0]), (24, 24))
    rng = np.random.default_rng(3)
    n = 2 * dt._PASS + 37
    x = np.stack([rng.uniform(4.0, 7.0, n), rng.uniform(-2.0, 1.0, n)])
    val, jac = table.at(x)
    e, lnt = _known_map(*x)
    ok = np.isfinite(val[0])
    assert ok.sum() > n / 2
    assert not np.any(ok & (x[1] > np.log(2.0)))  # sticking: nan
    np.testing.assert_allclose(val[0, ok], e[ok], rtol=1e-4)
    np.testing.assert_allclose(val[1, ok], lnt[ok], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(jac[1, 0, ok], -0.5, rtol=1e-9)
    target = np.stack([e, lnt])
    target[1] = np.where(np.isfinite(lnt), lnt, -2.5)
    full = table.invert(target, table.nearest(target))
    assert np.isfinite(full[0]).sum() > n / 2
    for cols in (rng.choice(n, 5, replace=False), np.arange(dt._PASS - 2, dt._PASS + 3)):
        alone = np.concatenate([table.invert(target[:, [i]], table.nearest(target[:, [i]]))
                                for i in cols], axis=1)  # fmt: skip
        np.testing.assert_array_equal(alone, full[:, cols])
        np.testing.assert_array_equal(np.concatenate([table.at(x[:, [i]])[1] for i in cols], -1),
                                      jac[..., cols])  # fmt: skip


@pytest.mark.parametrize("last", [False, True])
def test_the_coarse_box_grows_as_the_inverse_of_every_target_says(last):
    # the coarse table inverts its edge targets first and stops once no further growth
    # can show; the growth (and, where the box stays or the table is the last, the
    # designs) are those of the whole inverse, by the rule applied to every target
    from impactsym.engines.pybullet import design_table as dt

    rng = np.random.default_rng(4)
    n = 3 * dt._PASS
    # designs below the first box's z, then (after the first pass) a few beyond its u
    u = np.concatenate([rng.uniform(5.2, 5.8, n), rng.uniform(6.5, 7.0, 20)])
    z = np.log(np.concatenate([rng.uniform(0.3, 0.42, n), rng.uniform(0.6, 1.0, 20)]))
    target = np.stack(_known_map(u, z))
    for lo, hi in (([5.0, -0.8], [6.0, 0.3]), ([3.0, -2.0], [8.0, 1.0])):  # grows; stays
        table = dt._Table(_known_map, np.array(lo), np.array(hi), (dt._COARSE, dt._COARSE))
        nearest = table.nearest(target)
        full = table.invert(target, nearest)
        grid = np.stack(np.unravel_index(nearest, table.shape))[:, ~np.all(np.isfinite(full), 0)]
        x, low, high = dt._coarse_designs(table, target, last=last)
        np.testing.assert_array_equal(low, np.any(grid == 0, axis=1))
        np.testing.assert_array_equal(high, np.any(grid == dt._COARSE - 1, axis=1))
        if low.any() or high.any():  # the growth shows in the first pass and after it
            assert low[1]
            assert high[0]
            assert grid.shape[1] > dt._PASS
        if last or not (low.any() or high.any()):
            np.testing.assert_array_equal(x, full)
        else:
            assert x is None
