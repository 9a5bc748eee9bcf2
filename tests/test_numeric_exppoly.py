"""The exponential-polynomial machinery, :mod:`impactsym.numeric.exppoly`, against mpmath:
the cheap positivity certificate never certifies a function with a zero, the one-sided
Taylor exclusion finds every planted root, and its roots agree with mpmath's; a tangential
touch is no sign change, and a root on a subdivision node is found."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from impactsym.numeric.exppoly import exp_poly_positive, exp_poly_roots


def value(A, B, x):
    """F(x) = e^x A(x) + B(x) in 40-digit arithmetic from the float64 coefficients."""
    with mp.workdps(40):
        x = mp.mpf(x)
        a = sum((mp.mpf(c) * x**k for k, c in enumerate(A)), mp.mpf(0))
        b = sum((mp.mpf(c) * x**k for k, c in enumerate(B)), mp.mpf(0))
        return mp.exp(x) * a + b


def rod_like(rng, n_b):
    """Coefficients shaped like the rod's pieces: alternating, growing, or factorial-like."""
    k = np.arange(n_b)
    scale = rng.choice([1.0, 2.0, 5.0]) ** k / np.array([math.factorial(int(i)) for i in k])
    return (rng.normal(size=n_b) * scale * rng.choice([1.0, 100.0])).tolist()


def planted(rng, root):
    """A random F with a simple zero at ``root`` (the constant of B adjusted)."""
    A = rng.normal(size=rng.integers(0, 4))
    A[rng.random(A.size) < 0.3] = 0.0  # sparse A: a leading term alone must count
    A = A.tolist()
    B = rod_like(rng, int(rng.integers(1, 18)))
    B[0] -= float(value(A, B, root))
    return A, B


def test_positive_certificate_is_never_given_to_a_function_with_a_zero():
    rng = np.random.default_rng(7)
    refused = 0
    for _ in range(400):
        root = rng.uniform(0.01, 2.0)
        A, B = planted(rng, root)
        hi = rng.uniform(root, 2.5)
        if float(value(A, B, 0.0)) <= 0.0:
            continue
        refused += 1
        assert not exp_poly_positive(A, B, hi), (A, B, hi, root)
    assert refused > 100


def test_positive_certificate_holds_where_it_is_given_and_is_not_vacuous():
    """Where the certificate is given, F > 0 at 401 points in mpmath and exp_poly_roots
    finds nothing; and it is given for most functions that stay well above zero."""
    rng = np.random.default_rng(8)
    given = clear = 0
    for _ in range(300):
        A = rng.normal(size=rng.integers(0, 4)).tolist()
        B = rod_like(rng, int(rng.integers(0, 18)))
        hi = rng.uniform(0.0, 2.0)
        x = np.linspace(0.0, hi, 401)
        lowest = min(float(value(A, B, xi)) for xi in x[::20])
        if exp_poly_positive(A, B, hi):
            given += 1
            assert min(float(value(A, B, xi)) for xi in x) > 0.0, (A, B, hi)
            assert exp_poly_roots(np.array(A), np.array(B), 0.0, hi).size == 0
        if lowest > 0.0:
            clear += 1
        # a clearly positive one (B nearly the constant 1, A small) is always seen
        B = [1.0] + [1e-3 * rng.normal() / math.factorial(k) for k in range(rng.integers(17))]
        A = (1e-2 * rng.normal(size=rng.integers(0, 4))).tolist()
        assert exp_poly_positive(A, B, hi), (A, B, hi)
    assert given > 0.3 * clear


def test_contact_and_flight_shapes():
    """The rod's contact function f e^x + B and a flight gap with A = (c0, c1, -alpha f / 2)."""
    assert exp_poly_positive([0.5], [1.0, -0.5, 0.1], 2.0)
    assert not exp_poly_positive([0.5], [-0.6, 0.0, 0.0], 2.0)  # F(0) < 0
    assert not exp_poly_positive([0.0], [0.0], 1.0)  # F = 0 is not positive
    assert exp_poly_positive([1.0], [], 1.0)  # F = e^x
    # 1/2 - x^2 e^x (zero at 0.54): the omitted orders of a term of A that starts
    # beyond B's length still count
    assert not exp_poly_positive([0.0, 0.0, -1.0], [0.5], 1.0)
    assert exp_poly_positive([0.0, 0.0, -1.0], [0.5], 0.3)
    # a gap that closes at x = 1.5: (1.5 - x)(1 + x) e^x, as e^x A
    assert not exp_poly_positive([1.5, 0.5, -1.0], [], 2.0)
    assert exp_poly_positive([1.5, 0.5, -1.0], [], 0.5)  # (a sufficient test: not to 1.5)


@pytest.mark.parametrize("seed", range(6))
def test_roots_planted_anywhere_are_found_and_agree_with_mpmath(seed):
    rng = np.random.default_rng(100 + seed)
    for _ in range(30):
        root = rng.uniform(0.05, 1.95)
        A, B = planted(rng, root)
        found = exp_poly_roots(np.array(A), np.array(B), 0.0, 2.0)
        slope = abs(float(mp.diff(lambda x, A=A, B=B: value(A, B, x), root)))
        if slope < 1e-6:
            continue  # (nearly) a double root: float64 cannot place it
        assert np.abs(found - root).min() < 1e-9 / min(slope, 1.0), (A, B, root, found)
        for r in found:  # every root reported is a zero of F (to its rounding)
            with mp.workdps(40):
                exact = mp.findroot(lambda x, A=A, B=B: value(A, B, x), mp.mpf(r))
            assert abs(float(exact) - r) < 1e-12, (A, B, r)
        first = exp_poly_roots(np.array(A), np.array(B), 0.0, 2.0, first=True)
        assert first.tolist() == found[:1].tolist()


def test_the_written_out_cases_agree_with_the_general_certificate():
    """A = [a] and A quadratic take shortcuts; a trailing zero in A takes the general
    loop, which must decide every case the same way."""
    rng = np.random.default_rng(9)
    decided = 0
    for _ in range(3000):
        A = (rng.normal(size=rng.choice([1, 3])) * rng.choice([0.01, 1.0, 10.0])).tolist()
        if len(A) == 1:
            A = [abs(A[0])]
        B = rod_like(rng, int(rng.integers(1, 20)))
        B[0] = abs(B[0]) + rng.choice([0.0, 1.0, 10.0])
        hi = rng.uniform(0.0, 2.0)
        fast = exp_poly_positive(A, B, hi)
        assert fast == exp_poly_positive([*A, 0.0], B, hi), (A, B, hi)
        decided += fast
    assert 300 < decided < 2700


def opening(rng, slope):
    """A random F with F(0) = 0 exactly and F'(0) = slope (up to rounding), A quadratic or
    not, as a gap that opens at a separation."""
    A = (rng.normal(size=rng.choice([1, 2, 3, 4])) * rng.choice([0.1, 1.0])).tolist()
    B = rod_like(rng, int(rng.integers(3, 16)))
    B[0] = -A[0]
    B[1] = slope - (A[0] + (A[1] if len(A) > 1 else 0.0))
    return A, B


def test_rising_certificate_is_never_given_to_a_gap_that_closes_again():
    rng = np.random.default_rng(12)
    checked = 0
    for _ in range(400):
        A, B = opening(rng, rng.choice([0.0, 0.0, abs(rng.normal())]))
        root = rng.uniform(0.05, 2.0)
        B[2] -= float(value(A, B, root)) / root**2  # F(root) = 0, F(0), F'(0) unchanged
        if float(mp.diff(lambda x, A=A, B=B: value(A, B, x), root)) == 0.0:
            continue
        checked += 1
        hi = rng.uniform(root, 2.5)
        assert not exp_poly_positive(A, B, hi, rising_from_zero=True), (A, B, hi, root)
    assert checked > 300


def test_rising_certificate_holds_where_it_is_given():
    rng = np.random.default_rng(13)
    given = 0
    for _ in range(300):
        A, B = opening(rng, rng.choice([0.0, abs(rng.normal())]))
        hi = rng.uniform(0.0, 2.0)
        if exp_poly_positive(A, B, hi, rising_from_zero=True):
            given += 1
            x = np.linspace(0.0, hi, 201)[1:]
            assert min(float(value(A, B, xi)) for xi in x) > 0.0, (A, B, hi)
            found = exp_poly_roots(np.array(A), np.array(B), 0.0, hi, rising_from_zero=True)
            assert found.size == 0
    assert given > 30


@pytest.mark.parametrize("hi", [-1.0, math.nan, math.inf])
def test_exp_poly_positive_refuses_an_interval_it_cannot_bound(hi):
    # with hi < 0 the bound min(T_k, 0) hi^k is no bound: e^x - 0.5 + 2x, negative at
    # x = -1, was "proven" positive for hi = -1
    with pytest.raises(ValueError, match="hi must be finite and >= 0"):
        exp_poly_positive([1.0], [-0.5, 2.0], hi)


@pytest.mark.parametrize(("lo", "hi"), [(0.0, math.nan), (math.nan, 1.0), (0.0, math.inf)])
def test_exp_poly_roots_refuses_a_non_finite_interval(lo, hi):
    # a NaN end used to subdivide for ever
    with pytest.raises(ValueError, match="lo and hi must be finite"):
        exp_poly_roots(np.array([]), np.array([-3.0, 1.0]), lo, hi)


def test_exp_poly_roots_gives_up_on_an_interval_far_longer_than_its_scale():
    # [0, 1e300] for x - 3 used to subdivide for ever (the Taylor powers overflow)
    with np.errstate(all="ignore"), pytest.raises(RuntimeError, match="more than 100000 cells"):
        exp_poly_roots(np.array([]), np.array([-3.0, 1.0]), 0.0, 1e300)


def test_exp_poly_roots_finds_close_roots_and_exponential_ones():
    roots = [0.3, 0.3 + 1e-6, 0.9, 1.7]
    B = np.polynomial.polynomial.polyfromroots(roots)
    found = exp_poly_roots(np.zeros(0), B, 0.0, 2.0)
    assert np.abs(found - roots).max() < 1e-9
    # e^x - 1 - 2x: zero at 0 (excluded, the left end) and one more, by mpmath
    found = exp_poly_roots(np.array([1.0]), np.array([-1.0, -2.0]), 0.0, 3.0)
    root = mp.findroot(lambda x: mp.exp(x) - 1 - 2 * x, 1.3)
    assert found.size == 1
    assert found[0] == pytest.approx(float(root), abs=1e-14)
    # (x - 1)^2 e^x - 1e-3 has two roots near 1 +- 0.0316
    found = exp_poly_roots(np.array([1.0, -2.0, 1.0]), np.array([-1e-3]), 0.0, 2.0)
    assert found.size == 2
    assert exp_poly_roots(np.array([1.0]), np.array([0.5]), 0.0, 2.0).size == 0


@pytest.mark.parametrize(
    ("A", "B", "lo", "hi"),
    [
        # e^x - e x touches zero at 1 only (its minimum): 1 is a bisection node of [0, 2]
        ([1.0], [0.0, -math.e], 0.0, 2.0),
        ([1.0], [0.0, -math.e], 0.0, 1.7),
        # (x - 1/2)^2 touches at a node of [0, 1], (x - 1/3)^2 off the nodes
        ([], [0.25, -1.0, 1.0], 0.0, 1.0),
        ([], [1.0 / 9.0, -2.0 / 3.0, 1.0], 0.0, 1.0),
    ],
)
def test_exp_poly_roots_a_tangential_touch_is_no_sign_change(A, B, lo, hi):
    # F >= 0 throughout: check by dense sampling that nothing crosses
    x = np.linspace(lo, hi, 10001)
    F = np.exp(x) * np.polynomial.polynomial.polyval(
        x, A or [0.0]
    ) + np.polynomial.polynomial.polyval(x, B)
    assert F.min() > -1e-15
    assert exp_poly_roots(np.array(A), np.array(B), lo, hi).size == 0


def test_exp_poly_roots_a_crossing_on_a_node_is_still_a_root():
    """Simple and triple zeros exactly at the first bisection node 1/2 of [0, 1] change
    sign and are found exactly (first=True included)."""
    simple = np.array([-0.5, 1.0])
    triple = np.polynomial.polynomial.polyfromroots([0.5, 0.5, 0.5])
    for B in (simple, -simple, triple, -triple):
        assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0).tolist() == [0.5]
        assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0, first=True).tolist() == [0.5]
    # a tangency at a node followed by a crossing: only the crossing
    B = np.polynomial.polynomial.polyfromroots([0.5, 0.5, 0.8])
    assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0) == pytest.approx([0.8], abs=1e-15)


def test_exp_poly_roots_takes_lists_as_it_takes_arrays():
    """Lists of floats (the event loop's form, trailing zeros stripped in Python) give
    the same roots as arrays, also with trailing (negative) zeros, NumPy scalars in the
    list, or an empty A."""
    rng = np.random.default_rng(3)
    cases = [([], [0.2, -1.0, 1.0, 0.0, -0.0]), ([1.0, 0.0], [-3.0]), ([0.0], [0.5, -1.0])]
    for _ in range(40):
        root = float(rng.uniform(0.1, 1.9))
        cases.append(planted(rng, root))
    for A, B in cases:
        want = exp_poly_roots(np.array(A), np.array(B), 0.0, 2.0)
        got = exp_poly_roots(list(A), list(B), 0.0, 2.0)
        mixed = exp_poly_roots([np.float64(a) for a in A], [*B, 0.0], 0.0, 2.0)
        assert got.tolist() == want.tolist() == mixed.tolist()
