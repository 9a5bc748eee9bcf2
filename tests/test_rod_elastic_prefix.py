"""The cells at a reflection interval's start proved positive before the search (issue 22).

:func:`impactsym.rod.elastic.search._positive_prefix` skips the first cells of an
interval whose polynomial ``A + f B`` its Bernstein coefficients prove positive (the
search's halving cannot prove ``N > 0`` where ``N`` nearly touches zero at a reflection
time, its second derivative ``~ kappa^2`` there). Checked against what did not come from
that derivation: the polynomials evaluated exactly (rational arithmetic) on dense points,
a planted dip just below zero, and the contact times of the search without the prefix.
"""

from __future__ import annotations

from fractions import Fraction
from types import SimpleNamespace

import numpy as np
import pytest

from impactsym.rod.elastic import search
from impactsym.rod.elastic.manifold import ManifoldTable
from impactsym.rod.elastic.search import (
    DEPTH,
    TABLE_TOLERANCE,
    _bernstein_weights,
    _positive_prefix,
    elastic_contact_times,
)


def _exact(coefficients, f, xi):
    """``sum (A_k + f B_k) xi^k`` in rational arithmetic (``coefficients = (A, B)``)."""
    A, B = coefficients
    c = [Fraction(a) + Fraction(f) * Fraction(b) for a, b in zip(A, B, strict=True)]
    x, total, power = Fraction(xi), Fraction(0), Fraction(1)
    for ck in c:
        total += ck * power
        power *= x
    return total


def _table(polys, err=0.0):
    """A stand-in table: cells with ``A`` rows ``polys``, ``B = 0``, error ``err``."""
    A = np.array(polys, dtype=float)
    B = np.zeros_like(A)
    errors = np.full(A.shape[0], err)

    def certified(index, f, tolerance):
        return errors[index] + f * 0.0 <= tolerance

    return SimpleNamespace(A=A, B=B, certified=certified)


def _shifted_square(depth, degree=24):
    """``4 (xi - 1/2)^2 + depth`` as coefficients of degree ``degree``."""
    poly = np.zeros(degree + 1)
    poly[:3] = [1.0 + depth, -4.0, 4.0]
    return poly


@pytest.mark.parametrize("degree", [24, 25])
def test_bernstein_weights_give_the_polynomial_back(degree):
    """``sum_j b_j C(n, j) xi^j (1 - xi)^(n - j)`` with ``b = W c`` is ``sum c_k xi^k``
    (rational arithmetic at a few points; the weights only rounded once)."""
    rng = np.random.default_rng(3)
    c = rng.normal(size=degree + 1)
    b = _bernstein_weights(degree) @ c
    from math import comb

    for xi in (Fraction(0), Fraction(1, 3), Fraction(7, 10), Fraction(1)):
        bern = sum(
            Fraction(bj) * comb(degree, j) * xi**j * (1 - xi) ** (degree - j)
            for j, bj in enumerate(b)
        )
        direct = _exact((c, np.zeros_like(c)), 0.0, xi)
        assert abs(float(bern - direct)) <= 1e-13 * float(np.abs(c).sum())


def test_the_prefix_stops_before_a_dip_below_zero():
    """Positive cells, then one whose square dips to ``-1e-10`` in its middle (positive at
    both ends, where the search's nodes are): the prefix stops there; lifted to ``+0.1``
    it passes (at ``+1e-3`` it would not: the least Bernstein coefficient of degree 24
    lies 0.043 below the square's least value). A cell not certified (or followed by
    one) is not skipped."""
    rising = np.zeros(25)
    rising[:2] = [1.0, 0.5]
    cells = np.arange(6)
    forces = np.array([0.0, 1.0])
    dip = _table([rising, rising, _shifted_square(-1e-10), rising, rising, rising])
    assert _positive_prefix(dip, cells, forces).tolist() == [2, 2]
    lifted = _table([rising, rising, _shifted_square(0.1), rising, rising, rising])
    assert _positive_prefix(lifted, cells, forces).tolist() == [5, 5]  # the last: no next
    loose = _table([rising] * 6, err=2.0 * TABLE_TOLERANCE)
    assert _positive_prefix(loose, cells, forces).tolist() == [0, 0]


@pytest.mark.parametrize(("swing", "proved"), [(1.0, 1), (1e3, 0)])
def test_a_value_within_the_rounding_of_the_coefficients_is_not_proved(swing, proved):
    """``1e-12 + s xi (1 - xi)``: its Bernstein coefficients are exact bounds (the least,
    ``1e-12``, at both ends), but float computes them only within ``~ 32 u s``: at
    ``s = 1`` the cell is proved, at ``s = 1e3`` (rounding ``7e-12``) it is not."""
    bump = np.zeros(25)
    bump[:3] = [1e-12, swing, -swing]
    flat = np.zeros(25)
    flat[0] = 1e-12
    table = _table([bump, flat])
    assert _positive_prefix(table, np.arange(2), np.array([0.0])).tolist() == [proved]


@pytest.mark.parametrize(("a", "k", "which"), [(0.1, 1e3, "N"), (3.0, 1e4, "N"), (1.0, 100.0, "y")])
def test_the_cells_proved_are_positive_in_exact_arithmetic(a, k, which):
    """On a slow-manifold table, every cell the prefix skips (intervals 1 to 4, forces in
    [0, 2]) has ``A + f B > 0`` at 101 points, evaluated exactly from the stored floats,
    and the start of the next cell above ``-DEPTH``."""
    table = ManifoldTable(a, k, 5)
    view = table.view(which)
    forces = np.linspace(0.0, 2.0, 9)
    xi = [Fraction(j, 100) for j in range(101)]
    skipped = 0
    for m in range(1, 5):
        cells = np.flatnonzero((view.lo >= 2.0 * m) & (view.lo < 2.0 * m + 2.0))
        prefix = _positive_prefix(view, cells, forces)
        for f, count in zip(forces, prefix, strict=True):
            coefficients = [(view.A[i], view.B[i]) for i in cells[: count + 1]]
            for c in coefficients[:count]:
                assert min(_exact(c, f, x) for x in xi) > 0
            if count:
                assert _exact(coefficients[count], f, 0) > -DEPTH
            skipped += count
    assert skipped > 0  # the test looked at something


def test_the_search_without_the_prefix_finds_the_same_contact_times(monkeypatch):
    """The stiff map's contact times of ``N`` with the prefix skipped and with every cell
    searched by halving (``_PREFIX_CELLS = 0``) agree to rounding."""
    which = "N"
    A, F = np.meshgrid(np.geomspace(0.1, 10.0, 4), np.linspace(0.0, 2.0, 9))
    alpha, f = A.ravel(), F.ravel()
    for k in (1e2, 1e4):
        kappa = np.full(alpha.size, k)
        fast = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0)
        monkeypatch.setattr(search, "_PREFIX_CELLS", 0)
        slow = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0)
        monkeypatch.undo()
        np.testing.assert_array_equal(np.isinf(fast), np.isinf(slow))
        finite = np.isfinite(fast)
        assert np.max(np.abs(fast[finite] - slow[finite]), initial=0.0) <= 1e-13
