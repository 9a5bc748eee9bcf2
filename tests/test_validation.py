"""The one gate for inputs (:mod:`impactsym.validation`): strings never reach SymPy's
parser, numbers are real, finite and named when refused, shapes are named.

The string refusals are checked where users meet them, at the entrances of every wing
that takes symbolic input (multibody, symbolic, rod); all of them go through
:func:`~impactsym.validation.as_sympy` / :func:`~impactsym.validation.as_sympy_matrix`.
Every test runs in a fresh temporary working directory: the strings carrying code would
create the file ``PWNED`` there if SymPy's parser ever saw them (docs/security.md).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from conftest import CODE

from impactsym.validation import as_sympy, as_sympy_matrix, broadcast, real_array, renamed

NOT_NUMBERS = (None, True, object(), {"a": 1}, [1.0])


pytestmark = pytest.mark.usefixtures("no_code_runs")


def test_a_matrix_carrying_code_is_refused_by_name():
    # the wings' own tests feed CODE to every public function that takes SymPy input
    with pytest.raises(TypeError, match=r"^M\b.*string"):
        as_sympy_matrix("M", np.array([[CODE]]))


def test_strict_sympify_of_a_dict_would_run_code_so_as_sympy_scans_first():
    # the reason for the scan: SymPy parses dict keys even with strict=True
    with pytest.raises(TypeError, match="string"):
        as_sympy("values", {CODE: 1})


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_as_sympy_refuses_non_expressions(value):
    with pytest.raises(TypeError, match="^kappa "):
        as_sympy("kappa", value)


@pytest.mark.parametrize(
    "value",
    [range(3), sp.Array([1, 2]), sp.FiniteSet(1, 2), (i for i in (1, 2)), sp.Tuple(1)],
    ids=["range", "Array", "FiniteSet", "generator", "Tuple"],
)
def test_as_sympy_refuses_every_container(value):
    with pytest.raises(TypeError, match="^kappa must be a single number"):
        as_sympy("kappa", value)


@pytest.mark.parametrize("value", [bytearray(b"2"), memoryview(b"2"), b"2"])
def test_bytes_are_refused_like_strings(value):
    # SymPy would read bytearray(b"2") as its character code: Matrix([[50]])
    with pytest.raises(TypeError, match=r"^M must not contain strings"):
        as_sympy_matrix("M", [value])
    with pytest.raises(TypeError, match="^D must be a real number"):
        real_array("D", value)


@pytest.mark.parametrize(
    "value", [[True, 2], [1.5, np.True_], [[1, 2], [3, False]], (False,), [np.bool_(True)]]
)
def test_real_array_refuses_booleans_inside_arrays_as_for_scalars(value):
    with pytest.raises(TypeError, match="^D must be a real number.*bool"):
        real_array("D", value)
    with pytest.raises(TypeError, match="^D must be a real number"):
        real_array("D", True)


@pytest.mark.parametrize("value", [10**400, -(10**400)], ids=["huge", "minus_huge"])
def test_real_array_names_an_integer_beyond_the_float_range(value):
    with pytest.raises(ValueError, match="^D must be a finite float.*401 digits"):
        real_array("D", value)


def test_broadcast_names_every_argument():
    with pytest.raises(ValueError, match=r"^a \(shape \(2,\)\), b \(shape \(3,\)\) and c"):
        broadcast(a=np.zeros(2), b=np.zeros(3), c=np.zeros(4))


# -- the gate's functions one by one ---------------------------------------------------------


def test_check_condition_accepts_the_two_names_only():
    from impactsym.validation import check_condition

    assert check_condition("force") == "force"
    assert check_condition("position") == "position"
    for bad in ("Force", "velocity", "", None, 1):
        with pytest.raises((ValueError, TypeError), match="condition"):
            check_condition(bad)


def test_real_array_bounds_name_the_first_offending_entry():
    with pytest.raises(ValueError, match=r"^f must be >= 0, got -2\.0 \(at index \(1,\)"):
        real_array("f", [1.0, -2.0, -3.0], lower=0.0)
    with pytest.raises(ValueError, match=r"^alpha must be > 0, got 0\.0$"):
        real_array("alpha", 0.0, lower=0.0, strict=True)
    with pytest.raises(ValueError, match="^kappa must be"):
        real_array("kappa", np.inf, lower=0.0, strict=True)
    arr, scalar = real_array("kappa", np.inf, lower=0.0, strict=True, allow_inf=True)
    assert scalar
    assert arr == np.inf
    arr, scalar = real_array("t", [[0, 1], [2, 3]])
    assert not scalar
    assert arr.dtype == np.float64
    assert arr.shape == (2, 2)
    with pytest.raises(ValueError, match="^t must be finite"):
        real_array("t", [0.0, np.nan])


def test_finish_gives_floats_for_scalars_and_float_arrays_otherwise():
    from impactsym.validation import finish

    assert type(finish(np.asarray(2), True)) is float
    out = finish(np.arange(3), False)
    assert out.dtype == np.float64
    assert out.tolist() == [0.0, 1.0, 2.0]


def test_reject_strings_names_where_the_string_hides():
    from impactsym.validation import reject_strings

    reject_strings("M", [[1, 2], (3, {4: 5.0})])  # numbers anywhere: fine
    with pytest.raises(TypeError, match=r"at M\[1\]\[0\] key 'k'$"):
        reject_strings("M", [1, [{"k": 2}]])
    with pytest.raises(TypeError, match=r"at M\[0\]\[1\]$"):
        reject_strings("M", np.array([[1, "x"]], dtype=object))


def test_as_sympy_finite_refuses_infinities_inside_expressions():
    y = sp.Symbol("y")
    assert as_sympy("g", 2 * y + 1) == 2 * y + 1
    with pytest.raises(ValueError, match="^g "):
        as_sympy("g", y + sp.oo, finite=True)
    with pytest.raises(ValueError, match=r"^M "):
        as_sympy_matrix("M", [[1, sp.nan]], finite=True)
    assert as_sympy_matrix("M", [1, 2]).shape == (2, 1)


def test_inputs_named_adds_the_inputs_to_a_deep_failure():
    from impactsym.validation import inputs_named

    deep = r"^design\(k = <array of shape \(2,\)>, e = 0\.5\): x$"
    with pytest.raises(ValueError, match=deep), inputs_named("design", k=np.ones(2), e=0.5):
        raise ArithmeticError("x")
    # not a numerical failure: passed through
    with pytest.raises(KeyError), inputs_named("design", k=1.0):
        raise KeyError("k")


def test_a_renamed_keyword_takes_either_name_or_the_default_but_never_both():
    assert renamed("t_max", 3.0, "t_end", None, 40.0) == 3.0
    assert renamed("t_max", None, "t_end", 5.0, 40.0) == 5.0
    assert renamed("t_max", None, "t_end", None, 40.0) == 40.0
    # equal values are refused as well: the call names the same thing twice
    with pytest.raises(TypeError, match="^give t_max or its former name t_end, not both$"):
        renamed("t_max", 5.0, "t_end", 5.0, 40.0)
