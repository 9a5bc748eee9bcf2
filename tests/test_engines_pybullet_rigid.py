"""PyBullet's rigid contact with velocity restitution against PyBullet itself, at 240 Hz.

The model (:mod:`impactsym.engines.pybullet.rigid`) is the exact one-row map without
contact stiffness, read with the rigid rule (the contact ends where the body separates);
per phase it agrees with the engine to rounding. The phase mean is checked against the
closed form of the speculative row and against dense phase sampling.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.pybullet import predict_rigid
from impactsym.engines.pybullet.stepping import DEFAULT_SLOP

pytest.importorskip("pybullet")

from impactsym.engines.pybullet.driver import pybullet_steps

PHASES = np.array([0.0, 0.001, 0.2, 0.45, 0.5, 0.55, 0.8, 0.999])
H = 1 / 240


def _agree(engine, model):
    np.testing.assert_array_equal(engine.sticks, model.sticks)
    np.testing.assert_allclose(engine.restitution, model.restitution, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(engine.contact_time, model.contact_time, rtol=1e-12)


@pytest.mark.parametrize(
    "settings",
    [
        {},
        {"gravity": 9.81},
        {"gravity": 9.81, "speed": 0.3},
        {"processing_threshold": 0.0},
        {"processing_threshold": 0.0, "gravity": 9.81},
        {"restitution_threshold": 0.5, "speed": 0.6},
        {"substeps": 2, "gravity": 9.81},
    ],
    ids=[
        "default",
        "gravity",
        "slow-gravity",
        "no-speculative",
        "no-speculative-gravity",
        "threshold",
        "substeps",
    ],
)
def test_each_phase_is_exact_at_240_hz(settings):
    kw = {"speed": 1.0, **settings}
    engine = pybullet_steps(stiffness=None, damping=None, mass=1.0, phase=PHASES,
                            restitution=(0.5, 1.0), **kw)  # fmt: skip
    model = predict_rigid(restitution=0.5, phase=PHASES, **kw)
    _agree(engine, model)
    assert np.all(model.restitution >= 0.0)


def test_the_push_out_bias_alone_and_the_product_rule():
    # no restitution: what leaves is the push-out bias erp (x - s)/h, up to 0.08 v;
    # restitution 0.8 on the sphere and 0.625 on the plane act as their product 0.5
    kw = {"speed": 1.0, "processing_threshold": 0.0}
    engine = pybullet_steps(stiffness=None, damping=None, mass=2.0, phase=PHASES, **kw)
    model = predict_rigid(restitution=0.0, phase=PHASES, **kw)
    _agree(engine, model)
    late = PHASES > 0.01
    np.testing.assert_allclose(model.restitution[late], 0.08 * (PHASES[late] - DEFAULT_SLOP / H))
    engine = pybullet_steps(stiffness=None, damping=None, mass=1.0, phase=PHASES, speed=1.0,
                            restitution=(0.8, 0.625))  # fmt: skip
    _agree(engine, predict_rigid(restitution=0.5, phase=PHASES, speed=1.0))


@pytest.mark.parametrize(
    "solver",
    [{"useSplitImpulse": 0}, {"useSplitImpulse": 1, "splitImpulsePenetrationThreshold": 1.0},
     {"numSolverIterations": 1}],
    ids=["no-split", "split-always", "one-iteration"],
)  # fmt: skip
def test_solver_settings_that_do_not_change_the_answer(solver):
    engine = pybullet_steps(
        stiffness=None,
        damping=None,
        mass=1.0,
        phase=PHASES,
        speed=1.0,
        restitution=(0.5, 1.0),
        processing_threshold=0.0,
        solver=solver,
    )
    _agree(engine, predict_rigid(restitution=0.5, phase=PHASES, speed=1.0,
                                 processing_threshold=0.0))  # fmt: skip


def test_the_phase_mean_is_the_closed_form_and_the_dense_average():
    r, v = 0.5, 1.0
    mean = predict_rigid(restitution=r, speed=v)
    closed = 0.5 * (r - DEFAULT_SLOP / (v * H)) ** 2  # e(p) = max(0, p - 1 + r - s/(v h))
    assert mean.restitution == pytest.approx(closed, rel=1e-12)
    assert mean.stick_fraction == pytest.approx(1.0 - r + DEFAULT_SLOP / (v * H), rel=1e-12)
    assert mean.restitution_range[0] == 0.0
    dense = (np.arange(4000) + 0.5) / 4000
    for kw in ({"gravity": 9.81}, {"processing_threshold": 0.0, "gravity": 9.81}):
        m = predict_rigid(restitution=r, speed=v, **kw)
        at = predict_rigid(restitution=r, speed=v, phase=dense, **kw)
        assert m.restitution == pytest.approx(at.restitution.mean(), abs=2e-4)
        assert m.restitution_range[0] <= at.restitution.min()
        assert at.restitution.max() <= m.restitution_range[1]


def test_bad_input_is_refused_by_name():
    with pytest.raises(ValueError, match="speed"):
        predict_rigid(restitution=0.5, speed=0.0)
    with pytest.raises(ValueError, match="contact_erp"):
        predict_rigid(restitution=0.5, speed=1.0, contact_erp=1.5)
    with pytest.raises(ValueError, match="restitution"):
        predict_rigid(restitution=-0.1, speed=1.0)
    with pytest.raises(ValueError, match="phase"):
        predict_rigid(restitution=0.5, speed=1.0, phase=1.0)


def test_contact_erp_is_the_setting_that_sets_the_bias():
    # setPhysicsEngineParameter(contactERP=0.2) changes the push-out bias as contact_erp
    # says; the joint error reduction erp does not touch the contact row
    kw = {"speed": 1.0, "processing_threshold": 0.0}
    for solver, erp in (({"contactERP": 0.2}, 0.2), ({"erp": 0.5}, 0.08)):
        engine = pybullet_steps(stiffness=None, damping=None, mass=1.0, phase=PHASES,
                                restitution=(0.5, 1.0), solver=solver, **kw)  # fmt: skip
        _agree(engine, predict_rigid(restitution=0.5, phase=PHASES, contact_erp=erp, **kw))
