"""Hostile input to the contact wing: every public entry point probed with text, code,
None, booleans, complex numbers, NaN, infinities, negative values, empty arrays, shapes
that do not broadcast and caps beyond any meaning. Each refusal is a ValueError or
TypeError raised before any work whose message starts with the argument's name (or
names the inputs that led there); nothing is run as code."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from conftest import CODE

from impactsym.contact import (
    bounce_map,
    bounce_sequence,
    contact_surface,
    contact_time,
    physical_bounce,
    physical_contact,
    regime_of,
    restitution,
    stick_boundary,
)
from impactsym.contact.derivation import SpringDamperContact
from impactsym.contact.flight import free_flight
from impactsym.contact.release import linear_release, release_margin

pytestmark = pytest.mark.usefixtures("no_code_runs")

NAN, INF = math.nan, math.inf
#: (value, error, how the message goes on after "<name> must ")
BAD_REAL = [
    (CODE, TypeError, "be a real number"),
    (None, TypeError, "be a real number"),
    (True, TypeError, "be a real number"),
    (np.bool_(False), TypeError, "be a real number"),
    (1j, TypeError, "be a real number"),
    ([0.1, True], TypeError, "be a real number"),
    (NAN, ValueError, "be finite, got nan"),
    (INF, ValueError, "be finite, got inf"),
    (-INF, ValueError, "be finite, got -inf"),
    (-1e-300, ValueError, "be >= 0"),
    (10**400, ValueError, "be a finite float"),
]
BAD_CONDITION = [
    (CODE, ValueError),
    ("Force", ValueError),
    ("", ValueError),
    (None, TypeError),
    (True, TypeError),
    (b"force", TypeError),
]
BAD_CAP = [
    (0, ValueError, "be >= 1"),
    (-5, ValueError, "be >= 1"),
    (10**7 + 1, ValueError, r"be <= 1e\+07"),
    (10**9, ValueError, r"be <= 1e\+07"),
    (10**400, ValueError, r"be <= 1e\+07"),
    (True, TypeError, "be an integer"),
    (2.0, TypeError, "be an integer"),
    ("10", TypeError, "be an integer"),
    (CODE, TypeError, "be an integer"),
    (None, TypeError, "be an integer"),
]


def _calls(name, value):
    """Every entry point with the argument ``name`` set to ``value`` (else valid)."""
    c = {"condition": "force"}
    valid = {"D": 0.3, "f": 0.2}
    section2 = {
        "contact_time": lambda a: contact_time(a["D"], a["f"], **c),
        "restitution": lambda a: restitution(a["D"], a["f"], **c),
        "contact_surface": lambda a: contact_surface(a["D"], a["f"], **c),
        "bounce_map": lambda a: bounce_map(a["D"], a["f"], **c),
        "bounce_sequence": lambda a: bounce_sequence(a["D"], a["f"], **c),
    }
    if name == "f":
        section2["stick_boundary"] = lambda a: stick_boundary(a["f"], **c)
    if name == "D" and value != INF:  # regime_of(inf) is "overdamped" (a limit, allowed)
        section2["regime_of"] = lambda a: regime_of(a["D"])
    args = {**valid, name: value}
    return {key: (lambda call=call: call(args)) for key, call in section2.items()}


@pytest.mark.parametrize("name", ["D", "f"])
@pytest.mark.parametrize(("value", "error", "message"), BAD_REAL)
def test_section2_entry_points_refuse_a_bad_real_by_name(name, value, error, message):
    for function, call in _calls(name, value).items():
        with pytest.raises(error, match=f"^{name} must {message}"):
            call()
        assert function  # every entry point of the section-2 plane was probed


@pytest.mark.parametrize(("value", "error"), BAD_CONDITION)
def test_every_entry_point_refuses_a_bad_condition_by_name(value, error):
    calls = [
        lambda: contact_time(0.3, 0.2, condition=value),
        lambda: restitution(0.3, 0.2, condition=value),
        lambda: stick_boundary(0.2, condition=value),
        lambda: contact_surface(0.3, 0.2, condition=value),
        lambda: physical_contact(1.0, 1.0, 1.0, 1.0, condition=value),
        lambda: bounce_sequence(0.3, 0.2, condition=value),
        lambda: bounce_map(0.3, 0.2, condition=value),
        lambda: physical_bounce(1.0, 1.0, 1.0, 1.0, 1.0, condition=value),
    ]
    for call in calls:
        with pytest.raises(error, match="^condition must be"):
            call()


@pytest.mark.parametrize(("value", "error", "message"), BAD_CAP)
def test_bounce_entry_points_refuse_a_bad_cap_at_once(value, error, message):
    """A cap too large to bound anything is refused by name before any work (10^9
    asked for 40 GB up front and raised a MemoryError that named nothing)."""
    calls = [
        lambda: bounce_sequence(0.3, 0.2, condition="force", max_contacts=value),
        lambda: bounce_map([0.3, 0.1], 0.2, condition="position", max_contacts=value),
        lambda: physical_bounce(1.0, 1.0, 1.0, 1.0, 1.0, condition="force", max_contacts=value),
    ]
    for call in calls:
        start = time.perf_counter()
        with pytest.raises(error, match=f"^max_contacts must {message}"):
            call()
        assert time.perf_counter() - start < 1.0


def test_regime_of_infinite_damping_is_the_overdamped_limit():
    assert regime_of(INF) == "overdamped"


def test_numpy_integer_caps_are_integers():
    seq = bounce_sequence(0.3, 0.2, condition="force", max_contacts=np.int64(2))
    assert seq.n_contacts == 2
    assert bounce_map(0.3, 0.2, condition="force", max_contacts=np.uint8(2)).n_contacts == 2


def test_empty_arrays_give_empty_results_of_their_shape():
    empty, grid = np.array([]), np.zeros((0, 3))
    c = {"condition": "position"}
    assert contact_time(empty, 0.2, **c).shape == (0,)
    assert restitution(grid, 0.2, **c).shape == (0, 3)
    assert stick_boundary(empty, **c).shape == (0,)
    assert all(a.shape == (0,) for a in contact_surface(empty, empty, **c))
    assert physical_contact(empty, 1.0, 1.0, 1.0, **c).contact_time.shape == (0,)
    result = bounce_map(grid, 0.2, **c)
    assert result.n_contacts.shape == result.sticks.shape == (0, 3)
    assert linear_release(empty, empty, empty).contact_time.shape == (0,)
    assert release_margin(empty, 0.0, 0.0).shape == (0,)


@pytest.mark.parametrize("value", [np.array([]), [0.1, 0.2], np.zeros((1, 1))])
def test_bounce_sequence_refuses_arrays_and_points_to_the_map(value):
    with pytest.raises(TypeError, match=r"^D must be a scalar \(use bounce_map for arrays\)"):
        bounce_sequence(value, 0.2, condition="force")
    with pytest.raises(TypeError, match=r"^f must be a scalar \(use bounce_map"):
        bounce_sequence(0.2, value, condition="force")


def test_shapes_that_do_not_broadcast_are_named():
    pattern = r"^D \(shape \(3,\)\) and f \(shape \(2,\)\) cannot be broadcast"
    with pytest.raises(ValueError, match=pattern):
        bounce_map(np.ones(3), np.ones(2), condition="force")
    pattern = r"^D \(shape \(3,\)\) and load \(shape \(2,\)\) cannot be broadcast"
    with pytest.raises(ValueError, match=pattern):
        linear_release(np.ones(3), np.ones(2), 0.0)


PHYSICAL = ("m", "k", "d", "v0", "F")


@pytest.mark.parametrize("name", PHYSICAL)
@pytest.mark.parametrize(("value", "error", "message"), BAD_REAL)
def test_physical_entry_points_refuse_a_bad_input_by_name(name, value, error, message):
    args = dict(zip(PHYSICAL, (1.0, 1.0, 1.0, 1.0, 0.5), strict=True)) | {name: value}
    for function in (physical_bounce, physical_contact):
        with pytest.raises(error, match=f"^{name} must "):
            function(**args, condition="force")


@pytest.mark.parametrize("name", ["m", "k", "v0"])
def test_physical_inputs_must_be_positive(name):
    args = dict(zip(PHYSICAL, (1.0, 1.0, 1.0, 1.0, 0.5), strict=True)) | {name: 0.0}
    for function in (physical_bounce, physical_contact):
        with pytest.raises(ValueError, match=f"^{name} must be > 0, got 0.0"):
            function(**args, condition="force")


@pytest.mark.parametrize(
    ("args", "names"),
    [
        ((5e-324, 1e308, 1.0, 1.0, 0.0), "m, k"),  # omega0 overflows
        ((1.0, 1.0, 1e-200, 1e-200, 1e200), "F, d, v0"),  # f = F/(d v0) overflows
        ((1.0, 1.0, 0.0, 1.0, 1e-300), r"b = F/\(sqrt\(k m\) v0\) = 1e-300"),  # flights
    ],
)
def test_physical_bounce_names_the_inputs_that_leave_double_precision(args, names):
    with pytest.raises(ValueError, match=names):
        physical_bounce(*args, condition="position", max_contacts=3)


def test_physical_bounce_at_extreme_magnitudes_matches_physical_contact():
    """m = k = d = F = 1e160 (D = 1/2, f = 1): sqrt(k m) no longer overflows."""
    for args in [(1e160, 1e160, 1e160, 1.0, 0.0), (1e-200, 1e-200, 1e-200, 1.0, 0.0)]:
        bounce = physical_bounce(*args, condition="force")
        contact = physical_contact(*args, condition="force")
        assert bounce.D == contact.D == 0.5
        assert bounce.departure_speed[0] == contact.restitution
        assert bounce.end[0] == contact.contact_time


@pytest.mark.parametrize(
    ("tau", "error", "message"),
    [
        (CODE, TypeError, "^tau must be a real number"),
        (True, TypeError, "^tau must be a real number"),
        ([NAN], ValueError, "^tau must be finite, got nan"),
        (INF, ValueError, "^tau must be finite, got inf"),
        (-1.0, ValueError, "^tau must be >= 0, got -1.0"),
    ],
)
def test_trajectory_refuses_a_bad_time_by_name(tau, error, message):
    seq = bounce_sequence(0.1, 0.2, condition="force", max_contacts=3)
    with pytest.raises(error, match=message):
        seq.trajectory(tau)


def test_trajectory_of_no_times_is_empty():
    z, element = bounce_sequence(0.1, 0.2, condition="force").trajectory(np.array([]))
    assert z.shape == element.shape == (0,)


@pytest.mark.parametrize("name", ["D", "load", "offset"])
@pytest.mark.parametrize(("value", "error", "message"), BAD_REAL)
def test_loaded_oscillator_refuses_a_bad_input_by_name(name, value, error, message):
    args = {"D": 0.3, "load": 0.2, "offset": 0.1} | {name: value}
    for function in (linear_release, release_margin):
        with pytest.raises(error, match=f"^{name} must {message}"):
            function(args["D"], args["load"], args["offset"])


@pytest.mark.parametrize("flag", ["force", "position", "extremes"])
@pytest.mark.parametrize("value", ["no", 0, None, np.array([True])])
def test_loaded_oscillator_flags_must_be_booleans(flag, value):
    """``force="no"`` was truthy: the threshold stayed on."""
    with pytest.raises(TypeError, match=f"^{flag} must be True or False"):
        linear_release(0.3, 0.2, 0.0, **{flag: value})


def test_derivation_objects_refuse_unknown_names_without_running_them():
    with pytest.raises(ValueError, match="^regime must be one of"):
        SpringDamperContact(CODE)
    with pytest.raises(ValueError, match="^name must be one of"):
        free_flight().latex(CODE)
    with pytest.raises(ValueError, match="^condition must be"):
        free_flight().latex("psi", condition=CODE)
