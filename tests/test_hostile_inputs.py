"""Hostile and careless input to every public function: a clear error naming the argument,
or a correct limit value; never code run from a string, a silent NaN or a contradiction.

Every test runs in a fresh temporary working directory: the strings carrying code would
create the file ``PWNED`` there if SymPy's parser ever saw them.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, settings

from impactsym.export import formula, latex_document
from impactsym.rod import RodImpact, latex_formulas
from impactsym.rod import contact_force as rod_force
from impactsym.rod import contact_time as rod_contact_time
from impactsym.rod import displacement as rod_displacement

CODE = "__import__('os').system('touch PWNED')"

SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)

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
