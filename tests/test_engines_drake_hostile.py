"""Hostile input to the Drake bridge: clear errors naming the argument, never NaN."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.drake import combine, point_contact_for, predict

BASE = {"stiffness": 1e4, "dissipation": 0.5, "mass": 1.0, "speed": 1.0}


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"approximation": "sapp", "time_step": 1e-3}, ValueError, "approximation"),
        ({"time_step": -1e-3}, ValueError, "time_step"),
        ({"time_step": [1e-3, 2e-3]}, TypeError, "time_step"),
        ({"time_step": "0.001"}, TypeError, "time_step"),
        ({"time_step": 1e-3, "phase": 1.0}, ValueError, "phase"),
        ({"time_step": 1e-3, "phase": -0.1}, ValueError, "phase"),
        ({"stiffness": 0.0}, ValueError, "stiffness"),
        ({"dissipation": -1.0}, ValueError, "dissipation"),
        ({"mass": np.nan}, ValueError, "mass"),
        ({"speed": "1"}, TypeError, "speed"),
        ({"relaxation_time": -0.1, "time_step": 1e-3, "approximation": "sap"}, ValueError,
         "relaxation_time"),
    ],
)  # fmt: skip
def test_predict_refuses_bad_input(kwargs, error, match):
    with pytest.raises(error, match=match):
        predict(**{**BASE, **kwargs})


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({}, "exactly one of contact_time and max_penetration"),
        ({"contact_time": 0.03, "max_penetration": 0.01}, "exactly one"),
        ({"contact_time": 0.03, "restitution": 1.0}, "restitution must be < 1"),
        ({"contact_time": 0.03, "restitution": 0.0}, "restitution"),
        ({"contact_time": 1.5e-3, "time_step": 1e-3}, "at least two steps"),
        ({"contact_time": 4e-3, "time_step": 1e-3, "restitution": 0.99},
         "without dissipation the step itself restitutes"),
        ({"contact_time": 0.0308, "speed": 0.563, "gravity": 9.81, "restitution": 0.876,
          "time_step": 1e-3}, "without dissipation the contact restitutes 0.8[0-9]* under gravity"),
        ({"contact_time": 0.3, "speed": 0.01, "gravity": 9.81, "restitution": 0.05,
          "time_step": 1e-3}, "even without dissipation the body sticks"),
    ],
)  # fmt: skip
def test_design_says_why_a_target_is_out_of_reach(kwargs, match):
    args = {"restitution": 0.5, "speed": 1.0, "mass": 1.0}
    with pytest.raises(ValueError, match=match):
        point_contact_for(**{**args, **kwargs})


def test_combine_refuses_two_rigid_geometries():
    with pytest.raises(ValueError, match="both inf"):
        combine(stiffness_a=np.inf, dissipation_a=0.1, stiffness_b=np.inf, dissipation_b=0.1)
    with pytest.raises(ValueError, match="dissipation_b"):
        combine(stiffness_a=1e4, dissipation_a=0.1, stiffness_b=1e4, dissipation_b=-1.0)
