"""Hostile and careless input to every public function: a clear error naming the argument,
or a correct limit value; never code run from a string, a silent NaN or a contradiction.

Every test runs in a fresh temporary working directory: the strings carrying code would
create the file ``PWNED`` there if SymPy's parser ever saw them.
"""

from __future__ import annotations

import itertools
import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impactsym.contact import (
    contact_surface,
    contact_time,
    physical_contact,
    regime_of,
    restitution,
    stick_boundary,
)
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


# -- section 2: every argument named, every limit right -------------------------------------

SECTION2 = {
    "contact_time": lambda D, f: contact_time(D, f),
    "restitution": lambda D, f: restitution(D, f, condition="position"),
    "contact_surface": lambda D, f: contact_surface(D, f),
}


@pytest.mark.parametrize("function", sorted(SECTION2))
@pytest.mark.parametrize(
    ("D", "f", "error", "pattern"),
    [
        (math.nan, 0.5, ValueError, "^D must be finite, got nan"),
        (0.5, math.inf, ValueError, "^f must be finite, got inf"),
        (-1.0, 0.5, ValueError, "^D must be >= 0, got -1.0"),
        (0.5, -1e-300, ValueError, "^f must be >= 0"),
        (CODE, 0.5, TypeError, "^D must be a real number"),
        (0.5, True, TypeError, "^f must be a real number"),
        (0.5, 1j, TypeError, "^f must be a real number"),
        (None, 0.5, TypeError, "^D must be a real number"),
        ([0.1, 0.2, 0.3], [0.1, 0.2], ValueError, r"^D \(shape \(3,\)\) and f \(shape \(2,\)\)"),
        ([0.1, math.nan], 0.5, ValueError, r"D must be finite, got nan \(at index \(1,\)"),
    ],
)
def test_section2_functions_name_the_bad_argument(function, D, f, error, pattern):
    with pytest.raises(error, match=pattern):
        SECTION2[function](D, f)


def test_condition_must_be_named_and_keyword_only():
    with pytest.raises(ValueError, match="condition must be 'position' or 'force'"):
        contact_time(0.5, 0.5, condition=CODE)
    with pytest.raises(TypeError):
        contact_time(0.5, 0.5, "force")  # keyword-only


def _bisect(fun, lo, hi, steps=80):
    """Root of ``fun`` between ``lo`` and ``hi`` (opposite signs) by plain bisection."""
    sign_lo = mp.sign(fun(lo))
    assert sign_lo * mp.sign(fun(hi)) < 0
    for _ in range(steps):
        mid = (lo + hi) / 2
        if mp.sign(fun(mid)) == sign_lo:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def _release_time_mp(D, f=0):
    """Contact time of the force condition from the matrix exponential of the ODE
    (mpmath, no eigenvalues or closed forms): root of g = 2 D z' + z in tau > 0.
    g is of order D^-3 there, a difference of terms of order 1: hence the digits."""
    with mp.workdps(int(3 * math.log10(D)) + 40):
        D, f = mp.mpf(D), mp.mpf(f)
        A = mp.matrix([[0, 1, 0], [-1, -2 * D, 2 * D * f], [0, 0, 0]])
        x0 = mp.matrix([0, 1, 1])

        def state(tau):
            return mp.expm(A * tau) * x0

        def g(tau):
            z, zd, _ = state(tau)
            return 2 * D * zd + z

        guess = mp.log(16 * D**4) / (2 * D)  # leading order, only to bracket the root
        root = _bisect(g, guess / 2, guess * 2)
        return float(root), float(-state(root)[1])


@pytest.mark.parametrize("D", [1e9, 1e20, 1e40])
def test_far_overdamped_force_contact_releases_at_the_exact_time(D):
    tau_ref, e_ref = _release_time_mp(D)
    assert contact_time(D, 0.0) == pytest.approx(tau_ref, rel=1e-14)
    assert restitution(D, 0.0) == pytest.approx(e_ref, rel=1e-12)
    assert contact_time(D, 0.0, condition="position") == math.inf
    assert restitution(D, 0.0, condition="position") == 0.0


@pytest.mark.parametrize("D", [1e100, 1e200, 1e300, 1.7e308])
def test_far_overdamped_closed_form_holds_to_the_largest_float(D):
    # the closed form checked against the matrix exponential above, now in mpmath
    with mp.workdps(40):
        Dm = mp.mpf(D)
        sigma = mp.sqrt(Dm**2 - 1)
        mu = Dm + sigma
        tau = mp.log((2 * Dm * mu - 1) * mu**2) / (2 * sigma)
        e = (mp.exp(-tau / mu) / mu - mu * mp.exp(-mu * tau)) / (2 * sigma)
    assert contact_time(D, 0.0) == pytest.approx(float(tau), rel=1e-14)
    assert restitution(D, 0.0) == pytest.approx(float(e), rel=1e-12, abs=1e-320)


def test_far_overdamped_limit_joins_the_kernels_continuously():
    D = np.array([0.999e8, 1e8, 1.001e8])
    tau = contact_time(D, 0.0)
    np.testing.assert_allclose(tau, [_release_time_mp(d)[0] for d in D], rtol=1e-13)


def _boundary_sign_mp(D, f, dps=80):
    """Sign of min g (force condition) after impact, from the matrix exponential."""
    with mp.workdps(dps):
        D, f = mp.mpf(D), mp.mpf(f)
        A = mp.matrix([[0, 1, 0], [-1, -2 * D, 2 * D * f], [0, 0, 0]])
        x0 = mp.matrix([0, 1, 1])

        def gdot(tau):
            z, zd, _ = mp.expm(A * tau) * x0
            return 2 * D * (2 * D * f - z - 2 * D * zd) + zd

        def g(tau):
            z, zd, _ = mp.expm(A * tau) * x0
            return 2 * D * zd + z

        grid = [mp.mpf(10) ** (k / 4) / D for k in range(-8, 40)]
        lo, hi = next((a, b) for a, b in itertools.pairwise(grid) if gdot(a) < 0 < gdot(b))
        ridge = _bisect(gdot, lo, hi)
        return mp.sign(g(ridge))


@pytest.mark.parametrize("f", [1e-40, 1e-100, 1e-300])
def test_tiny_force_stick_boundary_follows_its_asymptote_and_is_exact(f):
    d_star = stick_boundary(f)
    assert d_star == pytest.approx(0.5 * f**-0.25, rel=1e-15)
    if f == 1e-40:  # the matrix exponential gets slow beyond
        assert _boundary_sign_mp(d_star * (1 - 1e-9), f) < 0  # releases
        assert _boundary_sign_mp(d_star * (1 + 1e-9), f) > 0  # sticks
    assert contact_time(d_star * 1.001, f) == math.inf


@SETTINGS
@given(
    log_f=st.floats(-320, 300),
    condition=st.sampled_from(["force", "position"]),
    side=st.sampled_from([1 - 1e-3, 1 + 1e-3, 0.5, 3.0]),
)
def test_stick_boundary_and_contact_time_never_contradict(log_f, condition, side):
    f = 10.0**log_f
    if f == 0.0:
        f = 5e-324
    d_star = stick_boundary(f, condition=condition)
    assert d_star > 0
    D = d_star * side
    tau, error = _attempt(lambda: contact_time(D, f, condition=condition))
    if error is not None:  # a point double precision cannot decide is refused by name
        assert str(error).startswith(f"D = {D!r}, f = {f!r}")
        return
    if side > 1:
        assert tau == math.inf
    else:
        assert 0 < tau < math.inf


@SETTINGS
@given(
    log_D=st.floats(-320, 307),
    log_f=st.floats(-320, 307),
    condition=st.sampled_from(["force", "position"]),
)
def test_extreme_magnitudes_give_a_value_in_range_or_a_named_refusal(log_D, log_f, condition):
    D, f = 10.0**log_D, 10.0**log_f
    tau, error = _attempt(lambda: contact_time(D, f, condition=condition))
    if error is not None:
        assert str(error).startswith(f"D = {D!r}, f = {f!r}")
        return
    e = restitution(D, f, condition=condition)
    assert tau > 0
    assert not math.isnan(tau)
    assert 0.0 <= e <= 1.0
    assert (e == 0.0) == (tau == math.inf) or e < 1e-300  # e underflows for D > 1e154


def test_the_special_points_work():
    assert contact_time(1e100, 0.0) < 1e-97  # f = 0 always releases under the force condition
    assert contact_time(1.0, 0.0) == pytest.approx(2.0, rel=1e-12)
    assert stick_boundary(0.0) == math.inf
    assert stick_boundary(0.0, condition="position") == 1.0
    assert contact_time(0.0, 1e300) == pytest.approx(math.pi, rel=1e-15)  # D = 0: 2Df = 0
    assert contact_time(1.0, 1e300) == math.inf
    assert restitution(0.0, 1e300) == 1.0


def test_stick_boundary_for_large_force_is_the_asymptote_and_the_kernel_agrees():
    f = 2e12
    d_star = stick_boundary(f)
    assert d_star == pytest.approx((16 * math.pi * f**2) ** (-1 / 3), rel=5e-9)
    assert contact_time(d_star * (1 - 1e-6), f) < math.inf
    assert contact_time(d_star * (1 + 1e-6), f) == math.inf
    with pytest.raises(ValueError, match=r"^D = .*, f = 1e\+50: the static penetration"):
        contact_time(stick_boundary(1e50) * 0.999, 1e50)


@pytest.mark.parametrize("value", [math.nan, -1.0, [0.5, 1.0], CODE])
def test_regime_of_refuses_what_is_not_a_damping_ratio(value):
    with pytest.raises((ValueError, TypeError), match="^D "):
        regime_of(value)


@pytest.mark.parametrize(
    ("inputs", "names"),
    [
        ({"m": 1.0, "k": 1.0, "d": 1e-300, "v0": 1e-300, "F": 1.0}, "F, d, v0"),
        ({"m": 1e-308, "k": 1e-308, "d": 1e308, "v0": 1.0}, "d, k, m"),
        ({"m": 1e308, "k": 1e-308, "d": 0.0, "v0": 1.0}, "m, k"),
    ],
)
def test_physical_contact_overflow_names_the_inputs(inputs, names):
    with pytest.raises(ValueError, match=f"the inputs {names} are too extreme"):
        physical_contact(**inputs)


@pytest.mark.parametrize(
    "inputs",
    [
        {"m": 1e-300, "k": 1.0, "d": 1.0, "v0": 1.0},
        {"m": 1.0, "k": 1e-300, "d": 1.0, "v0": 1.0},
        {"m": 1e300, "k": 1e-300, "d": 1.0, "v0": 1.0},
        {"m": 1.0, "k": 1e300, "d": 1e-300, "v0": 1.0},
        {"m": 1.0, "k": 1.0, "d": 1e-320, "v0": 1.0, "F": 0.5},
        {"m": 1e-300, "k": 1e-300, "d": 1e-300, "v0": 1e-300, "F": 1e-300},
    ],
)
def test_physical_contact_extreme_inputs_are_consistent(inputs):
    c = physical_contact(**inputs)
    assert c.sticks == math.isinf(c.normalized_contact_time)
    assert math.isinf(c.contact_time) == math.isinf(c.normalized_contact_time)
    if not c.sticks:
        assert c.contact_time > 0
        expected = c.normalized_contact_time / math.sqrt(inputs["k"]) * math.sqrt(inputs["m"])
        assert c.contact_time == pytest.approx(expected, rel=1e-14)
    assert 0.0 <= c.restitution <= 1.0


_LOG = st.floats(-300, 300)
_LOG_OR_ZERO = st.one_of(st.just(None), st.floats(-320, 300))


@SETTINGS
@given(
    log_m=_LOG,
    log_k=_LOG,
    log_v0=_LOG,
    log_d=_LOG_OR_ZERO,
    log_F=_LOG_OR_ZERO,
    condition=st.sampled_from(["force", "position"]),
)
def test_physical_contact_at_any_magnitude_is_consistent_or_names_its_inputs(
    log_m, log_k, log_v0, log_d, log_F, condition
):
    m, k, v0 = 10.0**log_m, 10.0**log_k, 10.0**log_v0
    d = 0.0 if log_d is None else 10.0**log_d
    F = 0.0 if log_F is None else 10.0**log_F
    c, error = _attempt(lambda: physical_contact(m, k, d, v0, F, condition=condition))
    if error is not None:
        assert "the inputs " in str(error)
        return
    assert c.sticks == math.isinf(c.contact_time) == math.isinf(c.normalized_contact_time)
    assert c.sticks or c.contact_time > 0
    assert 0.0 <= c.restitution <= 1.0


def test_physical_contact_vanishing_damping_is_the_undamped_limit():
    # d too small to matter: z'' + z = b with b = F / (sqrt(k m) v0) = 0.5
    c = physical_contact(m=1.0, k=1.0, d=1e-320, v0=1.0, F=0.5)
    z = lambda tau: 0.5 * (1 - math.cos(tau)) + math.sin(tau)  # noqa: E731
    assert abs(z(c.normalized_contact_time)) < 1e-14
    assert c.restitution == 1.0


def test_physical_contact_names_mismatched_shapes():
    with pytest.raises(ValueError, match=r"m \(shape \(2,\)\) and k \(shape \(3,\)\)"):
        physical_contact([1.0, 2.0], [1.0, 2.0, 3.0], 0.1, 1.0)


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


def test_bounce_sequence_at_huge_damping_warns_nothing():
    # sqrt((D - 1)(D + 1)) overflowed for D > 1.3e154 (warnings are errors here)
    from impactsym import bounce_sequence

    assert bounce_sequence(1e300, 1.0, condition="force").n_contacts == 1
