"""Result records of the contact wing (impactsym.contact.records): == compares the arrays
they hold element by element, hash is refused plainly -- never the obscure
'truth value of an array is ambiguous'."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from impactsym.contact import bounce_map, bounce_sequence, physical_bounce, physical_contact
from impactsym.contact.records import ArrayRecord, same_value
from impactsym.contact.release import linear_release

C = {"condition": "force"}
RESULTS = {
    "BounceSequence": lambda x: bounce_sequence(0.1, x, **C),
    "BounceMap": lambda x: bounce_map([0.1, 0.3], x, **C),
    "PhysicalBounce": lambda x: physical_bounce(0.01, 1e3, 2.0, 0.5, x, **C),
    "PhysicalContact (arrays)": lambda x: physical_contact([1.0, 2.0], 1.0, 1.0, 1.0, x, **C),
    "PhysicalContact (scalars)": lambda x: physical_contact(1.0, 1.0, 1.0, 1.0, x, **C),
    "LinearRelease": lambda x: linear_release(np.array([0.2, 0.5]), np.array([x, x]), 0.0),
    "LinearRelease (NaN extremes)": lambda x: linear_release(
        np.array([0.2, 0.5]), np.array([x, x]), 0.0, extremes=False
    ),
}


@pytest.mark.parametrize("name", sorted(RESULTS))
def test_equal_results_compare_equal_and_different_ones_do_not(name):
    make = RESULTS[name]
    first, again, other = make(0.2), make(0.2), make(0.05)
    assert isinstance(first, ArrayRecord)
    assert first == again
    assert first != other
    assert first != dataclasses.astuple(first)  # another type: not equal, no error
    assert first is not None


@pytest.mark.parametrize("name", sorted(RESULTS))
def test_results_refuse_hash_by_their_own_name(name):
    result = RESULTS[name](0.2)
    with pytest.raises(TypeError, match=f"^unhashable type: '{type(result).__name__}'$"):
        hash(result)
    with pytest.raises(TypeError, match="unhashable"):
        {result}  # noqa: B018


def test_arrays_of_other_shape_or_values_differ():
    assert same_value(np.array([np.nan, 1.0]), np.array([np.nan, 1.0]))
    assert not same_value(np.array([1.0, 2.0]), np.array([[1.0, 2.0]]))
    assert not same_value(np.array([1, 2]), np.array([1, 3]))
    assert same_value(np.array([True, False]), np.array([True, False]))
    assert same_value(float("inf"), float("inf"))
    assert not same_value("force", "position")
