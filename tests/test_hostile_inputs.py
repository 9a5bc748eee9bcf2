"""Hostile and careless input to every public function: a clear error naming the argument,
or a correct limit value; never code run from a string, a silent NaN or a contradiction.

Every test runs in a fresh temporary working directory: the strings carrying code would
create the file ``PWNED`` there if SymPy's parser ever saw them.
"""

from __future__ import annotations

import itertools
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
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impactsym.cli import main
from impactsym.contact import (
    contact_surface,
    contact_time,
    physical_contact,
    regime_of,
    restitution,
    stick_boundary,
)
from impactsym.export import python_module
from impactsym.multibody import (
    damping_for_restitution,
    penalty_for_targets,
    reduce_contact,
    stick_damping,
)
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


def test_broadcast_names_every_argument():
    with pytest.raises(ValueError, match=r"^a \(shape \(2,\)\), b \(shape \(3,\)\) and c"):
        broadcast(a=np.zeros(2), b=np.zeros(3), c=np.zeros(4))


# -- rod derivation and the rigid rod functions ----------------------------------------------


def test_bounce_sequence_at_huge_damping_warns_nothing():
    # sqrt((D - 1)(D + 1)) overflowed for D > 1.3e154 (warnings are errors here)
    from impactsym import bounce_sequence

    assert bounce_sequence(1e300, 1.0, condition="force").n_contacts == 1


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
