"""Hostile and careless input to every public function: a clear error naming the argument,
or a correct limit value; never code run from a string, a silent NaN or a contradiction.

Every test runs in a fresh temporary working directory: the strings carrying code would
create the file ``PWNED`` there if SymPy's parser ever saw them.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, settings

from impactsym.cli import main
from impactsym.export import formula, latex_document, python_module
from impactsym.multibody import (
    damping_for_restitution,
    penalty_for_targets,
    reduce_contact,
    stick_damping,
)
from impactsym.rod import RodImpact, latex_formulas
from impactsym.rod import contact_force as rod_force
from impactsym.rod import contact_time as rod_contact_time
from impactsym.rod import displacement as rod_displacement
from impactsym.symbolic.laplace import (
    check_delay,
    geometric_delay_series,
    invert_rational,
    laplace_exp_poly,
)
from impactsym.validation import as_sympy, as_sympy_matrix, broadcast, real_array

CODE = "__import__('os').system('touch PWNED')"
STRINGS = (CODE, "1", "x", b"1")
NOT_NUMBERS = (None, True, object(), {"a": 1}, [1.0])
SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
x, v = sp.symbols("x v")
s, t = sp.symbols("s t")


@pytest.fixture(autouse=True)
def no_code_runs(tmp_path, monkeypatch):
    """Run in an empty directory; afterwards no string may have been executed."""
    monkeypatch.chdir(tmp_path)
    yield
    assert not (tmp_path / "PWNED").exists(), "a string input was run as code"


def _attempt(call):
    """``(value, None)``, or ``(None, error)`` for a ``ValueError``."""
    try:
        return call(), None
    except ValueError as exc:
        return None, exc


def particle(k=1.0, d=0.0, load=0.1):
    return reduce_contact([[1.0]], [load], x, [x], [v], {x: 0, v: 1}, k, d)


# -- strings never reach SymPy's parser ----------------------------------------------------


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: reduce_contact([[CODE]], [0], x, [x], [v], {x: 0, v: 1}, 1, 0), "M"),
        (lambda: reduce_contact([[1]], [CODE], x, [x], [v], {x: 0, v: 1}, 1, 0), "F"),
        (lambda: reduce_contact([[1]], [[0], [CODE]], x, [x], [v], {x: 0}, 1, 0), "F"),
        (lambda: reduce_contact([[1]], [0], [CODE], [x], [v], {x: 0, v: 1}, 1, 0), "g"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {CODE: 0, v: 1}, 1, 0), "at"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: CODE, v: 1}, 1, 0), "at"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, CODE, 0), "k"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, 1, [CODE]), "d"),
        (lambda: reduce_contact([[1]], [0], x, [CODE], [v], {x: 0, v: 1}, 1, 0), "q"),
        (lambda: invert_rational(CODE, s, t), "F"),
        (lambda: invert_rational(1 / s, CODE, t), "s"),
        (lambda: check_delay(CODE), "delay"),
        (lambda: check_delay(2 - x, {x: (0, CODE)}), "bounds"),
        (lambda: laplace_exp_poly(CODE, t, s), "g"),
        (lambda: geometric_delay_series([(0, CODE)], 1, -1 / (s + 1), 2, 3), "numerator"),
        (lambda: geometric_delay_series([(0, 1)], 1, CODE, 2, 3), "bp"),
        (lambda: RodImpact(kappa=CODE), "kappa"),
        (lambda: RodImpact(kappa=[CODE]), "kappa"),
        (lambda: RodImpact().residuals(1 / s, CODE), "Y"),
        (lambda: as_sympy_matrix("M", np.array([[CODE]])), "M"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()


@pytest.mark.parametrize("values", [{"k": "x"}, {sp.Symbol("k"): CODE}, {CODE: 1}])
def test_reduced_contact_subs_refuses_strings(values):
    k = sp.Symbol("k", positive=True)
    r = reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, k, 0)
    with pytest.raises(TypeError, match="values .*string"):
        r.subs(values)
    assert r.subs({k: 4}).omega0 == 2.0


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


# -- rod derivation and the rigid rod functions ----------------------------------------------


@pytest.mark.parametrize(
    ("kappa", "error", "pattern"),
    [
        (-math.inf, ValueError, "kappa must be > 0, got -inf"),
        (math.nan, ValueError, "kappa must be a positive number or inf, got nan"),
        (0.0, ValueError, "kappa must be > 0"),
        (sp.zoo, ValueError, "kappa must be > 0"),
        (sp.I, ValueError, "kappa must be > 0"),
        (True, TypeError, "kappa must be"),
        (None, TypeError, "kappa must be"),
    ],
)
def test_rod_impact_kappa_is_validated(kappa, error, pattern):
    with pytest.raises(error, match=pattern):
        RodImpact(kappa=kappa)


def test_rod_impact_extreme_kappa_is_exact():
    assert RodImpact(kappa=1e300).kappa == sp.Integer(10) ** 300
    assert RodImpact(kappa=np.float64(1e-300)).kappa == sp.Rational(1, 10**300)
    assert RodImpact(kappa=math.inf).rigid


@pytest.mark.parametrize("n_terms", [200, 21, 10**9])
def test_formula_documents_check_their_budget_before_any_work(n_terms):
    with pytest.raises(ValueError, match=f"n_terms = {n_terms} exceeds the budget of 20"):
        formula("rod-bvp", n_terms=n_terms)
    with pytest.raises(ValueError, match="exceeds the budget"):
        latex_document(n_terms)
    with pytest.raises(ValueError, match="exceeds the budget"):
        latex_formulas(n_terms)


@pytest.mark.parametrize("n_terms", [2.5, "3", True, -1])
def test_series_term_counts_are_validated(n_terms):
    with pytest.raises((TypeError, ValueError), match="n_terms must be"):
        RodImpact().series("Y", n_terms)


@pytest.mark.parametrize("function", [rod_displacement, rod_force])
@pytest.mark.parametrize(
    ("args", "pattern"),
    [
        ((math.nan, 1.0, 0.0), "^t must be finite"),
        ((1.0, 0.0, 0.0), "^alpha must be > 0"),
        ((1.0, 1.0, -1.0), "^f must be >= 0"),
        ((CODE, 1.0, 0.0), "^t must be a real number"),
        ((1.0, True, 0.0), "^alpha must be a real number"),
    ],
)
def test_rod_functions_name_the_bad_argument(function, args, pattern):
    with pytest.raises((ValueError, TypeError), match=pattern):
        function(*args)


def test_rod_functions_name_mismatched_shapes():
    with pytest.raises(ValueError, match=r"^t \(shape \(2,\)\) and alpha \(shape \(3,\)\)"):
        rod_displacement(np.zeros(2), np.ones(3), 0.0)
    with pytest.raises(ValueError, match=r"^alpha \(shape \(2,\)\) and f \(shape \(3,\)\)"):
        rod_contact_time(np.ones(2), np.zeros(3), condition="force")


@pytest.mark.parametrize("alpha", [1e-300, 1e-12, 2e6, 1e16, 1e300])
def test_rod_mass_ratios_outside_the_verified_range_are_refused(alpha):
    # a heavy striker's Laguerre sums cancel (alpha = 1e16 gave y(4) = 4.44 > t), a very
    # light one's recurrences overflow (NaN) or its certified search runs out of cells
    for call in (
        lambda: rod_displacement(4.0, alpha, 0.0),
        lambda: rod_force(4.0, alpha, 0.0),
        lambda: rod_contact_time(alpha, 0.0, condition="position"),
    ):
        with pytest.raises(ValueError, match=r"^alpha must lie in \[1e-10, 1e\+06\]"):
            call()


@pytest.mark.parametrize("alpha", [1e-10, 1e6])
def test_rod_mass_ratios_at_the_ends_of_the_range_are_exact(alpha):
    # before the first reflection alpha y'' + y' = f, y(0) = 0, y'(0) = 1 (closed form)
    t = np.array([0.5, 1.0, 1.9])
    exact = [float(0.3 * s + 0.7 * alpha * -mp.expm1(-mp.mpf(s) / alpha)) for s in t]
    assert np.max(np.abs(rod_displacement(t, alpha, 0.3) - exact)) < 1e-12


# -- multibody ------------------------------------------------------------------------------


def test_reduce_contact_names_nan_in_F_as_nan():
    with pytest.raises(ValueError, match=r"^F must be finite, got NaN at F\[1, 0\]"):
        reduce_contact(np.eye(2), [0.0, math.nan], x, [x, v], [v, x], {x: 0, v: 1}, 1, 0)


def test_reduce_contact_names_penalty_arrays_of_different_lengths():
    with pytest.raises(ValueError, match=r"^k \(shape \(3,\)\) and d \(shape \(2,\)\)"):
        particle(k=[1.0, 2.0, 3.0], d=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"^k \(shape \(2,\)\) and d \(shape \(3,\)\)"):
        particle().with_penalty([1.0, 2.0], [0.1, 0.2, 0.3])


@pytest.mark.parametrize(
    ("k", "d", "pattern"),
    [(math.nan, 0.0, "^k must be finite"), (0.0, 0.0, "^k must be > 0"), (1.0, -1.0, "^d ")],
)
def test_reduce_contact_penalties_are_validated(k, d, pattern):
    with pytest.raises(ValueError, match=pattern):
        particle(k=k, d=d)


@pytest.mark.parametrize("k", [1e-300, 1e300, 1e-30])
def test_penalty_design_errors_name_the_input(k):
    r = particle()
    for call in (
        lambda: stick_damping(r, k),
        lambda: damping_for_restitution(r, k, 0.5),
    ):
        value, error = _attempt(call)
        if error is not None:
            assert f"k = {k!r}" in str(error)
        else:
            assert np.isfinite(value)


@pytest.mark.parametrize("contact_time", [1e-300, 1e300, 1e30])
def test_penalty_for_targets_refuses_extreme_contact_times_by_name(contact_time):
    with pytest.raises(ValueError, match=re.escape(f"contact_time = {contact_time!r}")):
        penalty_for_targets(particle(), restitution=0.5, contact_time=contact_time)


@pytest.mark.parametrize("bad", [math.nan, -1.0, 0.0, 1.0, CODE])
def test_penalty_design_targets_are_validated(bad):
    with pytest.raises((ValueError, TypeError), match="^restitution "):
        damping_for_restitution(particle(), 1.0, bad)


# -- the generated NumPy module --------------------------------------------------------------

GENERATED_PROBE = r"""
import json, sys
sys.modules["sympy"] = None
sys.modules["impactsym"] = None
sys.path.insert(0, sys.argv[1])
import impactsym_numpy as m
CODE = "__import__('os').system('touch PWNED')"
calls = {
    "nan D": lambda: m.boundary_force(float("nan"), 0.2),
    "string f": lambda: m.boundary_position(0.5, CODE),
    "negative tau": lambda: m.contact_function_force(-1.0, 0.5, 0.2),
    "bool f": lambda: m.ridge_time_force(0.5, True),
    "complex D": lambda: m.contact_function_position(1.0, 0.5j, 0.2),
    "shapes": lambda: m.boundary_force([0.1, 0.2], [0.1, 0.2, 0.3]),
    "huge D": lambda: m.boundary_force(1e100, 0.0),
    "inf t": lambda: m.rod_displacement(float("inf"), 1.0, 0.0),
    "zero alpha": lambda: m.rod_contact_force(1.0, 0.0, 0.0),
    "string alpha": lambda: m.rod_displacement(1.0, CODE, 0.0),
    "list of strings": lambda: m.rod_displacement(["1"], 1.0, 0.0),
}
out = {}
for label, call in calls.items():
    try:
        out[label] = ["no error", repr(call())]
    except Exception as exc:
        out[label] = [type(exc).__name__, str(exc)]
out["fine"] = ["value", m.boundary_force(0.5, 0.2)]
print(json.dumps(out))
"""


def test_generated_module_validates_its_inputs_in_a_clean_interpreter(tmp_path):
    (tmp_path / "impactsym_numpy.py").write_text(python_module())
    run = subprocess.run(
        [sys.executable, "-c", GENERATED_PROBE, str(tmp_path)],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    )
    got = json.loads(run.stdout)
    expected = {
        "nan D": ("ValueError", "D must be finite, got nan"),
        "string f": ("TypeError", "f must be a real number or array, got"),
        "negative tau": ("ValueError", "tau must be >= 0, got -1.0"),
        "bool f": ("TypeError", "f must be a real number or array of real numbers"),
        "complex D": ("TypeError", "D must be a real number or array of real numbers"),
        "shapes": ("ValueError", "D (shape (2,)) and f (shape (3,)) cannot be broadcast"),
        "huge D": ("ValueError", "D must be <= 1e+08"),
        "inf t": ("ValueError", "t must be finite, got inf"),
        "zero alpha": ("ValueError", "alpha must be > 0, got 0.0"),
        "string alpha": ("TypeError", "alpha must be a real number or array"),
        "list of strings": ("TypeError", "t must be a real number or array of real numbers"),
    }
    for label, (kind, start) in expected.items():
        assert got[label][0] == kind, (label, got[label])
        assert got[label][1].startswith(start), (label, got[label])
    assert 0 < got["fine"][1] < 1
    assert not (tmp_path / "PWNED").exists()


# -- the command line -------------------------------------------------------------------------


def test_cli_latex_with_code_as_a_name_is_an_unknown_formula(capsys):
    assert main(["latex", CODE]) == 2
    assert "no formula named" in capsys.readouterr().err


def test_cli_export_into_a_directory_fails_cleanly(tmp_path, capsys):
    target = tmp_path / "a_directory"
    target.mkdir()
    (target / "keep.txt").write_text("mine")
    assert main(["export", "python", str(target)]) == 2
    assert capsys.readouterr().err.startswith("impactsym: error:")
    assert (target / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in Path(tmp_path).iterdir()) == ["a_directory"]


def test_cli_export_writes_atomically(tmp_path):
    target = tmp_path / "m.py"
    assert main(["export", "python", str(target)]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["m.py"]
    assert "def boundary_force" in target.read_text()
