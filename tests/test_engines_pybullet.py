"""PyBullet itself against impactsym.engines.pybullet: a sphere dropped on a plane at 240 Hz.

The driver runs the engine (DIRECT mode) and reads the contact state by state with the
touch-phase definitions; the model is the exact one-contact map, so per phase the two
agree to rounding (asserted to 1e-9, the 0.5 % of the issue is far looser).
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import pybullet as pyb

pytest.importorskip("pybullet")

from impactsym.engines.pybullet.driver import pybullet_steps

PHASES = np.array([0.0, 0.001, 0.3, 0.7, 0.999])
BALL = {"stiffness": 1e4, "damping": 40.0, "mass": 1.0, "speed": 1.0}  # zeta = 0.2


def _agree(engine, model):
    np.testing.assert_array_equal(engine.sticks, model.sticks)
    np.testing.assert_allclose(engine.restitution, model.restitution, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(engine.contact_time, model.contact_time, rtol=1e-12)


@pytest.mark.parametrize(
    "settings",
    [
        {},
        {"gravity": 9.81},
        {"slop": 0.0, "processing_threshold": 0.0},
        {"slop": 0.0, "processing_threshold": 0.0, "gravity": 9.81},
        {"substeps": 2, "gravity": 9.81},
    ],
    ids=["default", "gravity", "no-speculative", "no-speculative-gravity", "substeps"],
)
def test_each_phase_is_exact_at_240_hz(settings):
    engine = pybullet_steps(**BALL, phase=PHASES, **settings)
    model = pyb.predict(**BALL, phase=PHASES, **settings)
    _agree(engine, model)
    assert not engine.sticks.any()


def test_both_bodies_compliant_combine_in_series_and_sum():
    # ball (2e4, 20) on a plane (2e4, 20): the pair is (1e4, 40)
    ball = {**BALL, "stiffness": 2e4, "damping": 20.0}
    engine = pybullet_steps(**ball, phase=PHASES, plane=(2e4, 20.0))
    model = pyb.predict(**ball, phase=PHASES, other_stiffness=2e4, other_damping=20.0)
    _agree(engine, model)
    np.testing.assert_allclose(model.pair_stiffness, 1e4, rtol=1e-15)
    np.testing.assert_array_equal(model.pair_damping, 40.0)


def test_the_issue_measurements_at_240_hz():
    # k = 1e4, zeta = 0.2, m = 1, 1 m/s: e = 0.33 with the engine's defaults; 0.43 in the
    # range without speculative contacts; numSubSteps = 2 gives 0.430
    default = pyb.predict(**BALL)
    assert default.restitution == pytest.approx(0.33, abs=0.005)
    plain = pyb.predict(**BALL, slop=0.0, processing_threshold=0.0)
    assert plain.restitution_range[0] < 0.43 < plain.restitution_range[1]
    assert pyb.predict(**BALL, substeps=2).restitution == pytest.approx(0.430, abs=0.002)
    engine = pybullet_steps(**BALL, phase=np.array([0.5]))
    assert engine.restitution[0] == pytest.approx(0.33, abs=0.01)


def test_a_design_delivers_its_targets_in_the_engine():
    design = pyb.contact_for(restitution=0.5, speed=1.0, mass=0.1, contact_time=0.05, gravity=9.81)
    assert design.restitution == pytest.approx(0.5, rel=1e-6)
    assert design.contact_time == pytest.approx(0.05, rel=1e-6)
    phases = (np.arange(32) + 0.5) / 32
    engine = pybullet_steps(
        stiffness=design.stiffness,
        damping=design.damping,
        mass=0.1,
        speed=1.0,
        gravity=9.81,
        phase=phases,
    )
    model = pyb.predict(
        stiffness=design.stiffness,
        damping=design.damping,
        mass=0.1,
        speed=1.0,
        gravity=9.81,
        phase=phases,
    )
    _agree(engine, model)
    assert engine.restitution.mean() == pytest.approx(0.5, rel=5e-3)
    assert engine.contact_time.mean() == pytest.approx(0.05, rel=5e-3)
    lo, hi = design.restitution_range
    assert lo <= engine.restitution.min()
    assert engine.restitution.max() <= hi


def test_the_stick_verdict():
    # at 240 Hz with gravity a soft contact sticks: k = 1e4, zeta = 0.1, 0.3 m/s
    soft = {"stiffness": 1e4, "damping": 20.0, "mass": 1.0, "speed": 0.3, "gravity": 9.81}
    engine = pybullet_steps(**soft, phase=np.array([0.2, 0.8]))
    assert engine.sticks.all()
    assert pyb.predict(**soft).sticks
    assert pyb.predict(**soft, phase=0.2).sticks
    free = {**soft, "gravity": 0.0}
    engine = pybullet_steps(**free, phase=np.array([0.2, 0.8]))
    assert not engine.sticks.any()
    _agree(engine, pyb.predict(**free, phase=np.array([0.2, 0.8])))


@pytest.mark.parametrize("gravity", [0.0, 9.81])
@pytest.mark.parametrize("threshold", [None, 0.5])
def test_velocity_restitution_is_the_product_and_has_its_threshold(gravity, threshold):
    engine = pybullet_steps(
        **BALL,
        phase=PHASES,
        gravity=gravity,
        restitution=(0.5, 0.8),
        restitution_threshold=threshold,
    )
    kw = {} if threshold is None else {"restitution_threshold": threshold}
    model = pyb.predict(**BALL, phase=PHASES, gravity=gravity, velocity_restitution=0.4, **kw)
    _agree(engine, model)


@pytest.mark.parametrize(
    "solver",
    [
        {"numSolverIterations": 1},
        {"useSplitImpulse": 0},
        {"useSplitImpulse": 1, "splitImpulsePenetrationThreshold": 1.0},
        {"numSolverIterations": 200, "solverResidualThreshold": 0.0},
    ],
    ids=["one-iteration", "no-split", "split-always", "many-iterations"],
)
def test_solver_settings_that_do_not_change_the_answer(solver):
    # one row is solved in the first Gauss-Seidel sweep; the multibody solver never splits
    engine = pybullet_steps(**BALL, phase=PHASES, gravity=9.81, solver=solver)
    _agree(engine, pyb.predict(**BALL, phase=PHASES, gravity=9.81))
