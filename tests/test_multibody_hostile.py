"""Hostile input to the multibody wing: every probe fails early, naming the argument.

The probes are cheap by construction: each is refused before any integration step, so a
regression to "work first, fail later" shows as a slow test, and one to "accept and
return nonsense" as a missing exception.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.multibody.design import damping_for_restitution, penalty_for_targets, stick_damping
from impactsym.multibody.examples import falling_bar
from impactsym.multibody.simulation import MAX_STEPS, convergence_study, simulate_contact


@pytest.fixture(scope="module")
def bar():
    return falling_bar()


def sim(bar, **options):
    return simulate_contact(bar, 1e3, 1.0, 0.5, **{"condition": "force", **options})


@pytest.mark.parametrize(
    ("options", "error", "message"),
    [
        ({"steps": 0}, ValueError, r"steps must be an integer in \[1, 1000000\], got 0"),
        ({"steps": -1}, ValueError, "steps must be an integer"),
        ({"steps": 2.5}, TypeError, "steps must be an integer, got 2.5"),
        ({"steps": 50.0}, TypeError, "steps must be an integer"),
        ({"steps": True}, TypeError, "steps must be an integer"),
        ({"steps": "5"}, TypeError, "steps must be an integer, got '5'"),
        ({"steps": 10**7}, ValueError, "steps must be an integer in"),
        ({"t_max": -1.0}, ValueError, "t_max must be > 0"),
        ({"t_max": float("nan")}, ValueError, "t_max must be finite"),
        ({"t_max": [1.0, 2.0]}, TypeError, "t_max must be one number"),
        ({"t_max": 1e12}, ValueError, r"t_max \* steps = 1e\+12 \* 50 asks for more than"),
        ({"tau_max": 1e12}, ValueError, r"t_max \* steps"),
        ({"condition": "Force"}, ValueError, "condition must be 'position' or 'force'"),
        ({"condition": ["force", 1]}, TypeError, "condition must be the string"),
        ({"condition": None}, TypeError, "condition must be the string"),
    ],
)
def test_simulation_budget_and_condition_are_checked_before_any_step(bar, options, error, message):
    with pytest.raises(error, match=message):
        sim(bar, **options)


def test_the_step_budget_is_what_the_check_says(bar):
    steps = 1000
    with pytest.raises(ValueError, match="asks for more than"):
        sim(bar, steps=steps, t_max=MAX_STEPS / steps * (1 + 1e-12))


@pytest.mark.parametrize(
    ("args", "error", "message"),
    [
        (("1e3", 1.0, 0.5), TypeError, "k must be a real number"),
        ((1e3, "1", 0.5), TypeError, "d must be a real number"),
        ((1e3, 1.0, "0.5"), TypeError, "speed must be a real number"),
        ((np.nan, 1.0, 0.5), ValueError, "k must be finite"),
        ((-1.0, 1.0, 0.5), ValueError, "k must be > 0"),
        ((True, 1.0, 0.5), TypeError, "k must be a real number"),
        ((np.ones(2), np.ones(3), 0.5), ValueError, r"cannot be broadcast"),
    ],
)
def test_simulation_inputs_are_checked_by_name(bar, args, error, message):
    with pytest.raises(error, match=message):
        simulate_contact(bar, *args, condition="force")


@pytest.mark.parametrize(
    ("omegas", "options", "error", "message"),
    [
        ([], {}, ValueError, "omegas must be a non-empty 1-d sequence"),
        ([-1.0], {}, ValueError, "omegas must be > 0"),
        (["1"], {}, TypeError, "omegas must be a real number"),
        ([[1e3]], {}, ValueError, "omegas must be a non-empty 1-d sequence"),
        ([1e3], {"steps": 0}, ValueError, "steps must be an integer"),
        ([1e3], {"condition": "both"}, ValueError, "condition must be"),
    ],
)
def test_convergence_study_checks_its_inputs_by_name(bar, omegas, options, error, message):
    with pytest.raises(error, match=message):
        convergence_study(bar, omegas, **{"condition": "position", **options})


@pytest.mark.parametrize(
    ("speed", "error", "message"),
    [
        ("1", TypeError, "speed must not contain strings"),
        (b"1", TypeError, "speed must not contain strings"),
        (float("nan"), ValueError, "must be finite"),
        (0.0, ValueError, "must be > 0 for an impact"),
        (-1.0, ValueError, "must be > 0 for an impact"),
    ],
)
def test_reduction_refuses_bad_impact_speeds(bar, speed, error, message):
    with pytest.raises(error, match=message):
        bar.reduce(1e3, 1.0, speed)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda r: stick_damping(r, "1", condition="force"), TypeError, "k must be a real"),
        (lambda r: stick_damping(r, -1.0, condition="force"), ValueError, "k must be > 0"),
        (lambda r: stick_damping(r, 1e3, condition="stick"), ValueError, "condition must be"),
        (
            lambda r: damping_for_restitution(r, 1e3, 1.5, condition="force"),
            ValueError,
            r"restitution must be a number in \(0, 1\)",
        ),
        (
            lambda r: damping_for_restitution(r, 1e3, "0.5", condition="force"),
            TypeError,
            "restitution must be a real number",
        ),
        (
            lambda r: damping_for_restitution(r, 1e3, np.nan, condition="force"),
            ValueError,
            "restitution must be finite",
        ),
        (
            lambda r: penalty_for_targets(r, restitution=0.5, contact_time=-1.0, condition="force"),
            ValueError,
            "contact_time must be > 0",
        ),
        (
            lambda r: penalty_for_targets(
                r, restitution=0.5, contact_time=1e300, condition="force"
            ),
            ValueError,
            "contact_time = 1e[+]300 is out of range",
        ),
    ],
)
def test_design_functions_refuse_by_name(bar, call, error, message):
    with pytest.raises(error, match=message):
        call(bar.reduce())


def test_empty_penalty_arrays_give_empty_results(bar):
    assert stick_damping(bar.reduce(), np.array([]), condition="force").shape == (0,)
    assert bar.reduce(np.array([]), 1.0, 0.5).contact_time("force").shape == (0,)
