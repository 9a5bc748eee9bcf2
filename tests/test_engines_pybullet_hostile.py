"""Hostile inputs to impactsym.engines.pybullet: every bad argument is named early."""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym.engines import pybullet as pyb

OK = {"stiffness": 1e4, "damping": 40.0, "mass": 1.0, "speed": 1.0}


@pytest.mark.parametrize("bad", [0.0, -1e-3, math.nan, math.inf, [1e-3, 2e-3]])
def test_bad_timestep_is_named(bad):
    with pytest.raises(ValueError, match="timestep"):
        pyb.predict(**OK, timestep=bad)


@pytest.mark.parametrize(
    ("name", "bad"),
    [
        ("stiffness", 0.0),
        ("stiffness", -1.0),
        ("damping", -1.0),
        ("mass", 0.0),
        ("speed", 0.0),
        ("gravity", -9.81),
        ("phase", 1.0),
        ("phase", -0.1),
        ("slop", -1e-5),
        ("speed", math.nan),
    ],
)
def test_bad_values_are_named(name, bad):
    with pytest.raises(ValueError, match=name):
        pyb.predict(**{**OK, name: bad})


@pytest.mark.parametrize(("name", "bad"), [("substeps", 0), ("substeps", 10**6)])
def test_bad_substeps_are_named(name, bad):
    with pytest.raises(ValueError, match=name):
        pyb.predict(**OK, substeps=bad)


@pytest.mark.parametrize(
    ("name", "bad"), [("stiffness", "1e4"), ("substeps", 2.0), ("phase", "0.5")]
)
def test_wrong_types_are_named(name, bad):
    with pytest.raises(TypeError, match=name):
        pyb.predict(**{**OK, name: bad})


def test_options_are_keyword_only():
    with pytest.raises(TypeError):
        pyb.predict(1e4, 40.0, 1.0, 1.0)  # type: ignore[misc]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"restitution": 1.0}, "restitution"),
        ({"restitution": 0.0}, "restitution"),
        ({"contact_time": -1.0}, "contact_time"),
        ({"mass": -1.0}, "mass"),
    ],
)
def test_bad_design_targets_are_named(kwargs, match):
    target = {"restitution": 0.5, "speed": 1.0, "mass": 1.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        pyb.contact_for(**target)


def test_a_design_needing_less_damping_than_the_plane_brings_is_refused():
    with pytest.raises(ValueError, match="other body already brings"):
        pyb.contact_for(restitution=0.8, speed=1.0, mass=0.1, contact_time=0.1)


def test_a_timestep_too_fine_for_the_step_by_step_map_is_refused_with_one_that_works():
    with pytest.raises(ValueError, match=r"too fine .* use a timestep of at least"):
        pyb.predict(**OK, timestep=1e-6)
    with pytest.raises(ValueError, match="too fine"):
        pyb.contact_for(restitution=0.5, speed=1.0, mass=1.0, contact_time=0.1, timestep=1e-6)


@pytest.mark.parametrize(
    ("name", "bad"), [("velocity_restitution", -0.1), ("restitution_threshold", -1.0)]
)
def test_bad_restitution_settings_are_named(name, bad):
    with pytest.raises(ValueError, match=name):
        pyb.predict(**OK, **{name: bad})


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_empty_arrays_give_empty_results(gravity):
    # as the other engines do (MuJoCo, Drake): an empty call is no error
    designs = pyb.contact_for(restitution=np.array([]), contact_time=np.array([]),
                                   speed=1.0, mass=0.1, gravity=gravity)  # fmt: skip
    assert designs.stiffness.shape == designs.restitution.shape == (0,)
    p = pyb.predict(stiffness=np.zeros((0, 3)), damping=1.0, speed=1.0, mass=0.1,
                         gravity=gravity)  # fmt: skip
    assert p.restitution.shape == p.contact_time.shape == (0, 3)
