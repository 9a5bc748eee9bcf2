"""The vectorized bracketed root finders, :mod:`impactsym.numeric.roots`, against SciPy's
scalar ``brentq`` and closed forms: accuracy, hard roots, shapes, and loud failures."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from impactsym.numeric.roots import bracketed_illinois, bracketed_newton, bracketed_newton_scalar


def kepler_problems(n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Eccentricities e in [0, 0.99] and mean anomalies M in [0, pi] of E - e sin E = M,
    whose root lies in [M, M + e]."""
    rng = np.random.default_rng(5)
    return rng.uniform(0.0, 0.99, n), rng.uniform(0.0, np.pi, n)


def kepler_by_brentq(e: np.ndarray, M: np.ndarray) -> np.ndarray:
    return np.array(
        [
            brentq(lambda E, ei=ei, Mi=Mi: E - ei * np.sin(E) - Mi, Mi, Mi + ei, xtol=1e-15)
            if ei > 0
            else Mi
            for ei, Mi in zip(e, M, strict=True)
        ]
    )


def test_newton_solves_keplers_equation_like_brentq():
    e, M = kepler_problems()
    root = bracketed_newton(
        lambda E, e, M: E - e * np.sin(E) - M, lambda E, e, M: 1 - e * np.cos(E), M, M + e, [e, M]
    )
    np.testing.assert_allclose(root, kepler_by_brentq(e, M), rtol=0, atol=4e-15)


def test_illinois_solves_keplers_equation_like_brentq():
    e, M = kepler_problems()
    root = bracketed_illinois(lambda E, i: E - e[i] * np.sin(E) - M[i], M, M + e)
    # within its documented tolerance: the final bracket is narrower than rtol |E|
    reference = kepler_by_brentq(e, M)
    assert np.all(np.abs(root - reference) <= 1e-13 * np.abs(reference) + 4e-15)


def test_newton_converges_at_a_triple_root_by_bisection():
    # g' vanishes at the root: Newton alone would crawl; the bracket keeps it going
    root = bracketed_newton(
        lambda x, c: (x - c) ** 3, lambda x, c: 3 * (x - c) ** 2, 0.0, 1.0, [np.full(3, 0.3)]
    )
    assert np.all(np.abs(root - 0.3) < 1e-5)


def test_illinois_converges_at_a_jump_and_over_many_decades():
    # a step function has no root, only a sign change: the bracket shrinks onto the jump
    jump = bracketed_illinois(lambda x, i: np.where(x < 0.3, -1.0, 1.0), 0.0, 1.0)
    assert abs(jump[0] - 0.3) < 1e-13
    # in log x the relative accuracy holds from 1e-10 to 1e10
    targets = np.geomspace(1e-20, 1e20, 41)
    root = bracketed_illinois(
        lambda x, i: x**2 - targets[i], np.full(41, 1e-12), np.full(41, 1e12), log=True
    )
    np.testing.assert_allclose(root, np.sqrt(targets), rtol=1e-12)


def test_newton_keeps_shapes_and_exact_bracket_ends():
    lo = np.zeros((2, 3))
    c = np.array([0.0, 1.0, 4.0])  # c = 0: the root is the bracket end itself
    root = bracketed_newton(lambda x, c: x**2 - c, lambda x, c: 2 * x, lo, 3.0, [c])
    assert root.shape == (2, 3)
    np.testing.assert_allclose(root, np.broadcast_to(np.sqrt(c), (2, 3)), rtol=1e-15)
    empty = bracketed_newton(lambda x: x, lambda x: 1.0 + 0 * x, np.zeros(0), np.ones(0))
    assert empty.shape == (0,)


def test_failures_are_loud():
    with pytest.raises(ValueError, match="sign change"):
        bracketed_newton(lambda x: x**2 + 1, lambda x: 2 * x, np.array([-1.0]), np.array([1.0]))
    with pytest.raises(ValueError, match="sign change"):
        bracketed_newton(lambda x: 1 / x, lambda x: -1 / x**2, np.array([0.0]), np.array([1.0]))
    with pytest.raises(RuntimeError, match="did not converge"):
        bracketed_newton(lambda x: x - 0.3, lambda x: 1e-9 + 0 * x, 0.0, 1.0, max_iter=3)
    with pytest.raises(RuntimeError, match="did not converge"):
        bracketed_illinois(lambda x, i: np.where(x < 0.3, -1.0, 1.0), 0.0, 1.0, max_iter=3)


def test_illinois_refuses_a_bracket_without_sign_change():
    # regression: it used to return the bracket end (here 4.0) as if it were a root
    with pytest.raises(ValueError, match="sign change"):
        bracketed_illinois(lambda x, i: x**2 + 1.0, np.ones(2), np.full(2, 4.0))
    with pytest.raises(ValueError, match="element 1"):  # wrong orientation, one element
        bracketed_illinois(
            lambda x, i: np.array([1.0, -1.0])[i] * (x - 2.0), np.ones(2), np.full(2, 3.0)
        )
    with pytest.raises(ValueError, match="sign change"):  # NaN at an end
        bracketed_illinois(
            lambda x, i: np.where(x < 1, np.nan, x - 2), np.zeros(1), np.full(1, 3.0)
        )
    # a root exactly on an end is still fine, at either end
    ends = bracketed_illinois(lambda x, i: x - np.array([1.0, 4.0])[i], np.ones(2), np.full(2, 4.0))
    np.testing.assert_array_equal(ends, [1.0, 4.0])


def test_known_end_values_and_a_joint_derivative_give_the_same_roots_as_brentq():
    # the options callers use to save evaluations (dg=None: g returns (g, dg); the values
    # at the bracket ends passed in) must not change the roots, nor hide a bad bracket
    e, M = kepler_problems()
    ref = kepler_by_brentq(e, M)

    def g_dg(E, e, M):
        return E - e * np.sin(E) - M, 1 - e * np.cos(E)

    ends = [g_dg(M, e, M)[0], g_dg(M + e, e, M)[0]]
    root = bracketed_newton(g_dg, None, M, M + e, [e, M], g_lo=ends[0], g_hi=ends[1])
    np.testing.assert_allclose(root, ref, rtol=0, atol=4e-15)

    def kepler(E, i):
        return E - e[i] * np.sin(E) - M[i]

    root = bracketed_illinois(kepler, M, M + e, f_lo=ends[0], f_hi=ends[1], rtol=1e-15)
    np.testing.assert_allclose(root, ref, rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="sign change"):
        bracketed_newton(g_dg, None, M, M + e, [e, M], g_lo=ends[1] + 1.0, g_hi=ends[1])
    with pytest.raises(ValueError, match="sign change"):
        bracketed_illinois(kepler, M, M + e, f_lo=ends[1] + 1.0, f_hi=ends[1])


def test_scalar_newton_matches_the_vectorized_one_and_brentq():
    """bracketed_newton_scalar runs the same iteration one root at a time."""
    e, M = kepler_problems(200)
    vector = bracketed_newton(
        lambda E, e, M: E - e * np.sin(E) - M, lambda E, e, M: 1 - e * np.cos(E), M, M + e, [e, M]
    )
    scalar = np.array(
        [
            bracketed_newton_scalar(
                lambda E, ei=ei, Mi=Mi: (E - ei * np.sin(E) - Mi, 1 - ei * np.cos(E)), Mi, Mi + ei
            )
            for ei, Mi in zip(e, M, strict=True)
        ]
    )
    np.testing.assert_allclose(scalar, kepler_by_brentq(e, M), rtol=0, atol=4e-15)
    np.testing.assert_allclose(scalar, vector, rtol=0, atol=4e-15)


def test_scalar_newton_bisects_at_a_triple_root_and_keeps_exact_ends():
    root = bracketed_newton_scalar(lambda x: ((x - 0.3) ** 3, 3 * (x - 0.3) ** 2), 0.0, 1.0)
    assert abs(root - 0.3) < 1e-5
    assert bracketed_newton_scalar(lambda x: (x * x - 4.0, 2 * x), 2.0, 3.0) == 2.0
    assert bracketed_newton_scalar(lambda x: (x - 3.0, 1.0), 0.0, 3.0) == 3.0
    # a flat derivative (g' = 0 at the midpoint) bisects instead of dividing by zero
    root = bracketed_newton_scalar(lambda x: (x**3 - 0.001, 3 * x * x), -1.0, 1.0)
    assert root == pytest.approx(0.1, abs=1e-15)


def test_scalar_newton_failures_are_loud():
    with pytest.raises(ValueError, match="sign change"):
        bracketed_newton_scalar(lambda x: (x * x + 1.0, 2 * x), -1.0, 1.0)
    with pytest.raises(ValueError, match="sign change"):
        bracketed_newton_scalar(lambda x: (float("nan"), 1.0), 0.0, 1.0)


def test_newton_system_solves_many_two_by_two_systems_against_scipy():
    from scipy.optimize import fsolve

    from impactsym.numeric.roots import newton_system

    # x^2 + y^2 = a, x - y^3 = b: each column is its own system
    a = np.array([2.0, 5.0, 1.0, 10.0])
    b = np.array([0.0, 1.0, -0.5, 2.0])

    def residual(u):
        return np.stack([u[0] ** 2 + u[1] ** 2 - a, u[0] - u[1] ** 3 - b])

    u0 = np.ones((2, a.size))
    u, r = newton_system(residual, u0, max_iter=40)
    assert np.all(np.abs(r) < 1e-9)
    for i in range(a.size):

        def one(w, i=i):
            return [w[0] ** 2 + w[1] ** 2 - a[i], w[0] - w[1] ** 3 - b[i]]

        ref = fsolve(one, [1.0, 1.0], xtol=1e-14)
        np.testing.assert_allclose(u[:, i], ref, rtol=1e-8)
    # the step bound: one iteration moves no component by more than max_step
    once, _ = newton_system(residual, u0, max_iter=1, max_step=0.25)
    assert np.all(np.abs(once - u0) <= 0.25)


def test_newton_system_shrink_iterates_only_unconverged_systems():
    from impactsym.numeric.roots import newton_system

    # u^3 = a per column; the first column starts at its root
    a = np.array([8.0, 2.0, 27.0, 0.5])
    u0 = np.array([[2.0, 1.0, 2.0, 1.0]])
    calls = []

    def residual(u, idx):
        calls.append(idx.copy())
        return u**3 - a[idx]

    u, r = newton_system(residual, u0, shrink=True, max_iter=40, tol=1e-13)
    np.testing.assert_allclose(u[0], np.cbrt(a), rtol=1e-13)
    assert np.all(np.abs(r) < 1e-13)
    assert calls[0].tolist() == [0, 1, 2, 3]  # the start, all columns
    assert all(0 not in idx for idx in calls[1:])  # converged at the start: no step
    assert u[0, 0] == 2.0
    # each column stops at its own convergence: the same roots as the unshrunk
    # iteration on that column alone, and fewer evaluations than all columns together
    for i in range(1, 4):
        column = u0[:, i : i + 1]
        alone, _ = newton_system(lambda w, i=i: w**3 - a[i], column, max_iter=40, tol=1e-13)
        assert abs(alone[0, 0] - u[0, i]) <= 1e-13 * u[0, i]
    assert sum(idx.size for idx in calls) < 4 * len(calls)


def test_newton_from_given_starts_finds_the_same_roots_in_fewer_evaluations():
    """``start``: first iterates inside the brackets (outside or nan: the midpoint); the
    roots are brentq's either way, and starts next to them save evaluations."""
    e, M = kepler_problems()
    calls = []

    def g(E, e, M):
        calls.append(E.size)
        return E - e * np.sin(E) - M, 1 - e * np.cos(E)

    reference = kepler_by_brentq(e, M)
    near = reference + 1e-6
    far = np.where(np.arange(e.size) % 2 == 0, M - 1.0, np.nan)  # outside, and nan
    counts = []
    for start in (None, near, far):
        calls.clear()
        root = bracketed_newton(g, None, M, M + e, [e, M], start=start)
        np.testing.assert_allclose(root, reference, rtol=0, atol=4e-15)
        counts.append(sum(calls))
    assert counts[1] <= counts[0] - e.size  # from next to the roots: a step fewer each
    assert counts[2] == counts[0]  # starts outside the brackets: the midpoints
