"""Continuous varying-impedance designs (impactsym.engines.mujoco.varying_design): many
targets of one contact start from a table of their designs; the designs are those of
the flat start to the Newton tolerance, hit their targets to 1e-9 and are what SciPy's
event integration of MuJoCo's contact law gives."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.mujoco import predict, solref_for
from impactsym.engines.mujoco import varying_design as vd
from tests.references.mujoco_law import mujoco_contact

DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


def _counting(monkeypatch):
    """Count the elements the design's Runge-Kutta contact evaluates."""
    count = [0]
    inner = vd.varying_phase

    def counted(coeffs, simp, rho, g, v0):
        count[0] += np.size(v0)
        return inner(coeffs, simp, rho, g, v0)

    monkeypatch.setattr(vd, "varying_phase", counted)
    return count


@pytest.mark.parametrize("contact_time", [None, 0.02])
def test_table_started_designs_are_the_flat_started_ones(monkeypatch, contact_time):
    e = np.linspace(0.3, 0.9, 1500)
    options = {"speed": 1.0, "gravity": 9.81, "contact_time": contact_time}
    count = _counting(monkeypatch)
    tabled = solref_for(restitution=e, **options)
    with_table = count[0]
    monkeypatch.setattr(vd, "_MIN_GROUP", 10**9)  # every target from the flat design
    count[0] = 0
    flat = solref_for(restitution=e, **options)
    # the table pays: the flat start costs each target several evaluations (one
    # Newton step and more), the table's start mostly one
    assert with_table < 0.5 * count[0]
    assert with_table < 2.5 * e.size
    for a, b in zip(tabled.solref, flat.solref, strict=True):
        np.testing.assert_allclose(a, b, rtol=5e-8)
    # each design hits its target as the Newton tolerance promises (predict's own
    # integration, in the time unit)
    assert np.max(np.abs(tabled.prediction.restitution - e)) < 1.5e-9
    if contact_time is not None:
        assert np.max(np.abs(tabled.prediction.contact_time / contact_time - 1)) < 1.5e-9


def test_table_designs_are_what_event_integration_gives():
    # targets of two contacts (speeds) in one call, each a table group
    rng = np.random.default_rng(3)
    e = rng.uniform(0.25, 0.9, 1200)
    speed = np.repeat([0.5, 2.0], 600)
    design = solref_for(restitution=e, speed=speed, gravity=9.81, contact_time=0.015)
    for i in rng.choice(e.size, 4, replace=False):
        sr = (float(design.solref[0][i]), float(design.solref[1][i]))
        e_ref, t_ref, _ = mujoco_contact(sr, DEFAULT, float(speed[i]), 9.81)
        assert abs(e_ref - e[i]) < 5e-8
        assert t_ref == pytest.approx(0.015, rel=5e-8)


def test_rough_node_designs_are_not_interpolated():
    # node designs with a jump (two branches of solutions) between nodes 20 and 21
    e_n = np.linspace(0.3, 0.9, 41)
    u_n = np.log(0.3 + 0.2 * e_n)[None] + np.where(np.arange(41) > 20, 0.5, 0.0)
    e = np.linspace(0.3, 0.9, 4001)
    out = vd._interpolate(e_n, u_n, e)
    h = e_n[1] - e_n[0]
    near = np.abs(e - 0.5 * (e_n[20] + e_n[21])) < 2.4 * h
    far = np.abs(e - 0.5 * (e_n[20] + e_n[21])) > 4.5 * h
    assert np.all(np.isnan(out[0, near]))
    # elsewhere the cubic of the smooth branch, exact to its own fourth derivative
    exact = np.log(0.3 + 0.2 * e) + np.where(e > e_n[20], 0.5, 0.0)
    assert np.max(np.abs(out[0, far] - exact[far])) < 1e-7


def test_group_with_an_undesignable_node_starts_from_the_flat_design(monkeypatch):
    e = np.linspace(0.3, 0.9, 600)
    solve, refused = vd._solve, []

    def refusing(e_t, *args):
        if e_t.size < e.size:  # the nodes of the table
            refused.append(e_t.size)
            raise ValueError("no solref reaches this node")
        return solve(e_t, *args)

    monkeypatch.setattr(vd, "_solve", refusing)
    design = solref_for(restitution=e, speed=1.0, gravity=9.81)
    assert refused == [150]
    assert np.max(np.abs(design.prediction.restitution - e)) < 1.5e-9


def test_one_target_repeated_shares_one_node_design():
    design = solref_for(restitution=np.full(600, 0.6), speed=1.0, gravity=9.81)
    assert np.all(design.solref[1] == design.solref[1][0])
    alone = predict(solref=(0.02, float(design.solref[1][0])), speed=1.0, gravity=9.81)
    assert abs(alone.restitution - 0.6) < 1e-9
