"""Drake bridge: the point-contact predictions and designs, proven in Drake itself."""

from __future__ import annotations

import os

import numpy as np
import pytest

from impactsym.engines.drake import combine, point_contact_for, predict

if os.environ.get("CI") == "true":
    import pydrake  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("pydrake")

from impactsym.engines.drake.driver import drake_continuous, drake_phases

PHASES = np.array([0.0, 0.137, 0.5, 0.861, 0.999])


def _uniform(n):
    return (np.arange(n) + 0.5) / n


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_continuous_prediction_is_drakes_hunt_crossley(gravity):
    for k, d, v in ((1e4, 1.0, 1.0), (3e5, 0.3, 2.0), (1e4, 0.5, 0.5)):
        run = drake_continuous(stiffness=k, dissipation=d, mass=1.0, speed=v, gravity=gravity)
        p = predict(stiffness=k, dissipation=d, mass=1.0, speed=v, gravity=gravity)
        assert p.sticks == run["sticks"] is False
        assert abs(p.restitution - run["restitution"]) < 1e-9
        assert abs(p.contact_time / run["contact_time"] - 1.0) < 1e-9
        assert abs(p.max_penetration / run["max_penetration"] - 1.0) < 1e-8


@pytest.mark.parametrize("approximation", ["tamsi", "similar", "lagged", "sap"])
@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_discrete_update_per_phase_is_drakes(approximation, gravity):
    k, d, m, v, tau = 1e4, 0.5, 1.0, 1.0 if gravity == 0.0 else 0.4, 0.004
    run = drake_phases(stiffness=k, dissipation=d, mass=m, speed=v, gravity=gravity,
                       time_step=1e-3, approximation=approximation, phases=PHASES,
                       relaxation_time=tau)  # fmt: skip
    p = predict(stiffness=k, dissipation=d, mass=m, speed=v, gravity=gravity, time_step=1e-3,
                approximation=approximation, phase=PHASES, relaxation_time=tau)  # fmt: skip
    np.testing.assert_array_equal(p.sticks, run["sticks"])
    np.testing.assert_allclose(p.restitution, run["restitution"], atol=1e-8)
    np.testing.assert_allclose(p.contact_time, run["contact_time"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(p.max_penetration, run["max_penetration"], rtol=1e-8)


def test_default_is_lagged_and_sap_ignores_dissipation_in_drake():
    base = {"stiffness": 1e4, "mass": 1.0, "speed": 1.0, "time_step": 1e-3, "phases": [0.3]}
    lagged = drake_phases(dissipation=0.5, approximation="lagged", **base)
    sap = [drake_phases(dissipation=d, approximation="sap", **base) for d in (0.0, 5.0)]
    assert sap[0]["restitution"][0] == sap[1]["restitution"][0]
    p = predict(stiffness=1e4, dissipation=0.5, mass=1.0, speed=1.0, time_step=1e-3, phase=0.3)
    assert p.approximation == "lagged"
    assert abs(p.restitution - lagged["restitution"][0]) < 1e-8
    q = predict(stiffness=1e4, dissipation=5.0, mass=1.0, speed=1.0, time_step=1e-3, phase=0.3,
                approximation="sap")  # fmt: skip
    assert abs(q.restitution - sap[0]["restitution"][0]) < 1e-12  # default tau: 0.1 + 0.1


def test_phase_mean_and_range_hold_in_drake():
    phases = _uniform(64)
    run = drake_phases(stiffness=1e4, dissipation=0.5, mass=1.0, speed=1.0, time_step=1e-3,
                       phases=phases)  # fmt: skip
    p = predict(stiffness=1e4, dissipation=0.5, mass=1.0, speed=1.0, time_step=1e-3)
    lo, hi = p.restitution_range
    assert lo <= run["restitution"].min()
    assert run["restitution"].max() <= hi
    assert abs(run["restitution"].mean() / p.restitution - 1.0) < 1e-3  # 64-point midpoint
    assert abs(p.restitution - 0.658) < 1e-3
    assert abs(lo - 0.655) < 1e-3


def test_pair_rules_are_drakes():
    (ka, da), (kb, db) = (3e4, 0.2), (1.5e4, 1.1)
    k, d = combine(stiffness_a=ka, dissipation_a=da, stiffness_b=kb, dissipation_b=db)
    run = drake_phases(stiffness=None, dissipation=None, mass=1.0, speed=1.0, time_step=1e-3,
                       phases=PHASES, pair=((ka, da), (kb, db)))  # fmt: skip
    p = predict(stiffness=k, dissipation=d, mass=1.0, speed=1.0, time_step=1e-3, phase=PHASES)
    np.testing.assert_allclose(p.restitution, run["restitution"], atol=1e-8)
    cont = drake_continuous(stiffness=None, dissipation=None, mass=1.0, speed=1.0,
                            pair=((ka, da), (kb, db)))  # fmt: skip
    q = predict(stiffness=k, dissipation=d, mass=1.0, speed=1.0)
    assert abs(q.restitution - cont["restitution"]) < 1e-8


@pytest.mark.parametrize("time_step", [0.0, 1e-3])
def test_design_delivers_its_target_in_drake(time_step):
    target_e, target_t, m, v, g = 0.5, 0.03, 1.0, 1.0, 9.81
    c = point_contact_for(restitution=target_e, contact_time=target_t, mass=m, speed=v,
                          gravity=g, time_step=time_step)  # fmt: skip
    assert abs(c.restitution - target_e) < 1e-9
    assert abs(c.contact_time / target_t - 1.0) < 1e-9
    k, d = c.point_contact_stiffness, c.hunt_crossley_dissipation
    if time_step == 0.0:
        run = drake_continuous(stiffness=k, dissipation=d, mass=m, speed=v, gravity=g)
        e, t = run["restitution"], run["contact_time"]
    else:
        run = drake_phases(stiffness=k, dissipation=d, mass=m, speed=v, gravity=g,
                           time_step=time_step, phases=_uniform(32))  # fmt: skip
        e, t = run["restitution"].mean(), run["contact_time"].mean()
    assert abs(e / target_e - 1.0) < 5e-3
    assert abs(t / target_t - 1.0) < 5e-3


@pytest.mark.parametrize("time_step", [0.0, 1e-3])
def test_stick_verdict_is_drakes(time_step):
    # a slow ball, heavily damped, under gravity: it stays; a faster one leaves
    for v, d, sticks in ((0.05, 20.0, True), (0.5, 0.5, False)):
        p = predict(stiffness=1e4, dissipation=d, mass=1.0, speed=v, gravity=9.81,
                    time_step=time_step, phase=0.4 if time_step else None)  # fmt: skip
        if time_step:
            run = drake_phases(stiffness=1e4, dissipation=d, mass=1.0, speed=v, gravity=9.81,
                               time_step=time_step, phases=[0.4], max_steps=2000)  # fmt: skip
            got = bool(run["sticks"][0])
        else:
            got = drake_continuous(stiffness=1e4, dissipation=d, mass=1.0, speed=v,
                                   gravity=9.81, t_max=0.5)["sticks"]  # fmt: skip
        assert p.sticks is sticks
        assert got is sticks


@pytest.mark.parametrize("approximation", ["tamsi", "lagged"])
def test_a_creeping_contact_rests_where_drake_rests_it(approximation):
    # heavily damped under gravity: the body creeps up to its rest m g / k from below
    # (the model declares it at once, by the creep rule); Drake, stepped 2e4 updates,
    # sticks at every phase with its deepest overlap at the rest too: 3-5e-13 short of it
    # with TAMSI; SAP's solver tolerance ("lagged") lets it creep ~8e-7 past it
    tol = {"tamsi": 1e-12, "lagged": 2e-6}
    phases = np.array([0.0, 0.4, 0.8])
    for d in (50.0, 80.0):
        run = drake_phases(stiffness=1e4, dissipation=d, mass=1.0, speed=0.1, gravity=9.81,
                           time_step=1e-3, approximation=approximation, phases=phases,
                           max_steps=20_000)  # fmt: skip
        p = predict(stiffness=1e4, dissipation=d, mass=1.0, speed=0.1, gravity=9.81,
                    time_step=1e-3, approximation=approximation, phase=phases)  # fmt: skip
        assert run["sticks"].all()
        assert p.sticks.all()
        np.testing.assert_allclose(p.max_penetration, 9.81 / 1e4, rtol=1e-15)
        np.testing.assert_allclose(
            run["max_penetration"], p.max_penetration, rtol=tol[approximation]
        )
