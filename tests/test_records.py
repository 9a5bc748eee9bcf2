"""Array-aware equality and hashing of result records (impactsym.records)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest

from impactsym.records import array_record, values_equal


@array_record
@dataclass(frozen=True)
class Pair:
    time: Any
    parts: Any = ()
    note: str = field(default="", compare=False)


@array_record
@dataclass(frozen=True)
class Other:
    time: Any
    parts: Any = ()


def test_equal_arrays_compare_equal_and_different_ones_do_not():
    a = Pair(np.array([1.0, np.inf, np.nan]), (np.arange(3),))
    assert a == Pair(np.array([1.0, np.inf, np.nan]), (np.arange(3),))
    assert a != Pair(np.array([1.0, np.inf, 2.0]), (np.arange(3),))
    assert a != Pair(np.array([1.0, np.inf, np.nan]), (np.arange(4),))  # shape counts
    assert a != Pair(np.array([[1.0, np.inf, np.nan]]), (np.arange(3),))
    assert a != Other(np.array([1.0, np.inf, np.nan]), (np.arange(3),))  # class counts
    assert a == Pair(a.time, a.parts, note="not compared")


def test_scalar_records_hash_like_their_values_and_array_records_refuse_by_field():
    assert hash(Pair(2.0, (1, 2))) == hash(Pair(2.0, (1, 2)))
    assert len({Pair(2.0), Pair(2.0), Pair(3.0)}) == 2
    with pytest.raises(TypeError, match="Pair is not hashable: its field 'parts'"):
        hash(Pair(1.0, (np.zeros(2),)))


def test_values_equal_on_nested_containers_and_mismatched_kinds():
    assert values_equal({"a": np.ones(2)}, {"a": np.ones(2)})
    assert not values_equal({"a": np.ones(2)}, {"b": np.ones(2)})
    assert not values_equal([np.ones(2)], (np.ones(2),))
    assert values_equal(float("nan"), float("nan"))
    assert not values_equal(np.array(["x"]), np.array([1.0]))


def test_the_multibody_results_compare_by_value():
    from impactsym.multibody.examples import falling_bar

    bar = falling_bar()
    k = np.array([1e3, 2e3])
    a, b = bar.reduce(k, 1.0, 0.5), bar.reduce(k, 1.0, 0.5)
    assert a == b and a != bar.reduce(k, 2.0, 0.5)
    with pytest.raises(TypeError, match="ReducedContact is not hashable"):
        hash(a)
    assert bar.reduce(1e3, 1.0, 0.5) == bar.reduce(1e3, 1.0, 0.5)
