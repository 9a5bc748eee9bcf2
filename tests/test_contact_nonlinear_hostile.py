"""Hostile input to impact() and damping_for(): refused early, naming the argument."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.contact import damping_for, impact

KW = {"stiffness": 2000.0, "damping": 0.3, "mass": 0.5, "speed": 1.5}
DESIGN = {"restitution": 0.5, "stiffness": 2000.0, "mass": 0.5, "speed": 1.5}


def test_unknown_law_lists_the_laws():
    laws = "'linear', 'hertz-linear', 'hunt-crossley', 'tsuji', 'viscoelastic'; got 'hertz'"
    with pytest.raises(ValueError, match=laws):
        impact("hertz", condition="force", **KW)
    with pytest.raises(ValueError, match="'viscoelastic'; got 'jkr'"):
        damping_for("jkr", condition="force", **DESIGN)


def test_condition_is_required_and_checked():
    with pytest.raises(TypeError, match="condition"):
        impact("tsuji", **KW)
    with pytest.raises(TypeError, match="condition"):
        damping_for("tsuji", **DESIGN)
    with pytest.raises(ValueError, match="condition must be one of 'position', 'force', 'clipped'"):
        impact("tsuji", condition="both", **KW)


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("stiffness", -1.0, "stiffness must be > 0"),
        ("mass", 0.0, "mass must be > 0"),
        ("speed", np.nan, "speed must be finite"),
        ("damping", -0.1, "damping must be >= 0"),
        ("force", -2.0, "force must be >= 0"),
        ("exponent", 0.5, "exponent must be >= 1"),
    ],
)
def test_bad_numbers_are_named(name, value, message):
    with pytest.raises(ValueError, match=message):
        impact("hunt-crossley", condition="position", **{**KW, name: value})


def test_strings_and_shapes_are_refused():
    with pytest.raises(TypeError, match="stiffness"):
        impact("tsuji", condition="force", **{**KW, "stiffness": "1e4"})
    with pytest.raises(ValueError, match="cannot be broadcast"):
        impact("tsuji", condition="force", **{**KW, "mass": np.ones(2), "speed": np.ones(3)})


@pytest.mark.parametrize(("target", "message"), [(0.0, "restitution must be > 0"),
                                                 (1.5, "restitution must be <= 1")])  # fmt: skip
def test_impossible_targets_are_refused(target, message):
    with pytest.raises(ValueError, match=message):
        damping_for("linear", condition="force", **{**DESIGN, "restitution": target})


def test_clipped_without_damping_never_coasts():
    """No damping: the force k d^p never pulls, so clipped is the position condition."""
    kw = {"stiffness": 2000.0, "damping": 0.0, "mass": 0.5, "speed": 1.5, "force": 3.0}
    for law in ("hertz-linear", "tsuji", "viscoelastic"):
        a = impact(law, condition="clipped", **kw)
        b = impact(law, condition="position", **kw)
        assert a.restitution == pytest.approx(b.restitution, rel=1e-12)
        assert a.contact_time == pytest.approx(b.contact_time, rel=1e-12)


def test_the_law_functions_name_the_three_conditions():
    from impactsym.contact import law_contact_map, law_stick_boundary

    message = "condition must be one of 'position', 'force', 'clipped'"
    with pytest.raises(ValueError, match=message):
        law_contact_map("tsuji", 0.3, 0.1, condition="clip")
    with pytest.raises(ValueError, match=message):
        law_stick_boundary("tsuji", 0.3, condition="limit_damping")
    with pytest.raises(TypeError, match="condition must be one of the strings"):
        damping_for("tsuji", condition=True, **DESIGN)


def test_bounce_sequences_name_the_three_conditions_and_stick_under_a_crushing_force():
    from impactsym.contact import bounce_map, bounce_sequence, physical_bounce

    message = "condition must be one of 'position', 'force', 'clipped'"
    for call in (bounce_sequence, bounce_map):
        with pytest.raises(ValueError, match=message):
            call(0.3, 0.1, condition="clip", law="tsuji")
        with pytest.raises(TypeError, match="condition must be one of the strings"):
            call(0.3, 0.1, condition=True)
    clipped = bounce_sequence(0.3, 1e6, condition="clipped", law="tsuji")
    assert (clipped.n_contacts, clipped.sticks, clipped.time_to_rest) == (1, True, 0.0)
    # physical_bounce is section 2's linear contact: position or force only
    with pytest.raises(ValueError, match="condition must be 'position' or 'force'"):
        physical_bounce(1.0, 1.0, 1.0, 1.0, 1.0, condition="clipped")
    seq = bounce_sequence(0.3, 1e6, condition="force", law="tsuji")
    assert seq.n_contacts == 1
    assert seq.sticks
    assert seq.time_to_rest == 0.0
    with pytest.raises(TypeError, match="exponent must be a scalar"):
        bounce_map([0.3], 0.1, condition="force", law="tsuji", exponent=[1.5, 2.0])
    with pytest.raises(ValueError, match="law must be one of"):
        bounce_map([0.3], 0.1, condition="force", law="hertz")
