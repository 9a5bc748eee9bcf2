"""Result records of the contact wing (impactsym.records.ArrayRecord): == compares the
arrays they hold element by element and equal results hash alike -- never the obscure
'truth value of an array is ambiguous'."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from impactsym.contact import bounce_map, bounce_sequence, physical_bounce, physical_contact
from impactsym.contact.release import linear_release
from impactsym.records import ArrayRecord, values_equal

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
def test_equal_results_hash_alike_and_collapse_in_a_set(name):
    first, again, other = RESULTS[name](0.2), RESULTS[name](0.2), RESULTS[name](0.05)
    assert hash(first) == hash(again)
    assert len({first, again, other}) == 2


def test_arrays_of_other_shape_or_values_differ():
    assert values_equal(np.array([np.nan, 1.0]), np.array([np.nan, 1.0]))
    assert not values_equal(np.array([1.0, 2.0]), np.array([[1.0, 2.0]]))
    assert not values_equal(np.array([1, 2]), np.array([1, 3]))
    assert values_equal(np.array([True, False]), np.array([True, False]))
    assert values_equal(float("inf"), float("inf"))
    assert not values_equal("force", "position")
