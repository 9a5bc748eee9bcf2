"""The certified first-sign-change search, :mod:`impactsym.numeric.isolation`, on functions
whose roots and minima are known in closed form: the first root is never missed, and
``certify=True`` proves ``g > 0`` exactly where that holds with margin, never where a
root, a touch or a non-positive start would contradict it."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.numeric.isolation import first_sign_change

# g = cos(k x) + c on [0, 7], |g''| <= k^2: first root arccos(-c)/k where |c| < 1,
# min g = c - 1 (> 0 exactly when c > 1)


def _cosines(k, c):
    def evaluate(x, owner):
        return np.cos(k[owner] * x) + c[owner], -k[owner] * np.sin(k[owner] * x), np.zeros_like(x)

    def bound(a, b, owner, *ends):
        return k[owner] ** 2

    return evaluate, bound


def _search(k, c, n_nodes=3, **options):
    evaluate, bound = _cosines(k, c)
    nodes = np.tile(np.linspace(0.0, 7.0, n_nodes), k.size)
    owner = np.repeat(np.arange(k.size), n_nodes)
    return first_sign_change(evaluate, bound, nodes, owner, k.size, **options)


def test_first_root_of_many_cosines_and_certificates_agree_with_closed_forms():
    rng = np.random.default_rng(3)
    k = rng.uniform(0.3, 4.0, 300)
    c = rng.uniform(-0.99, 2.5, 300)
    roots, positive = _search(k, c, certify=True)
    has_root = (np.abs(c) < 1) & (np.arccos(np.clip(-c, -1, 1)) / k <= 7.0)
    np.testing.assert_allclose(
        roots[has_root], np.arccos(-c[has_root]) / k[has_root], rtol=0, atol=1e-13
    )
    assert np.all(np.isnan(roots[~has_root]))
    # proved positive: exactly the cosines that stay above a margin on [0, 7]
    x = np.linspace(0.0, 7.0, 20001)
    low = np.min(np.cos(k[:, None] * x[None, :]), axis=1) + c
    assert np.all(low[positive] > 0)
    assert np.all(positive[low > 1e-6])
    assert not np.any(positive[has_root])
    # the certificate does not change the roots
    np.testing.assert_array_equal(_search(k, c), roots)


def test_a_touch_or_a_dip_within_the_tolerance_is_never_certified():
    # cos(x) + 1 touches 0 at pi (no sign change); cos(x) + 1 - 1e-13 dips 1e-13 below
    # it, a sign change that may be passed over (shallower than the tolerance)
    k = np.ones(2)
    c = np.array([1.0, 1.0 - 1e-13])
    roots, positive = _search(k, c, certify=True)
    assert np.isnan(roots[0])
    assert np.isnan(roots[1]) or abs(roots[1] - np.pi) < 1e-6
    assert not positive.any()
    # a dip deeper than the tolerance is a sign change
    roots = _search(k[:1], np.array([1.0 - 1e-9]))
    assert abs(roots[0] - np.arccos(-(1.0 - 1e-9))) < 1e-7


def test_a_non_positive_first_node_is_never_certified():
    k = np.ones(2)
    c = np.array([-1.0, 2.0])  # g(0) = 0 falling into a negative stretch; g > 0
    _, positive = _search(k, c, certify=True)
    assert positive.tolist() == [False, True]


@pytest.mark.parametrize("n_nodes", [2, 5, 40])
def test_the_result_does_not_depend_on_the_initial_nodes(n_nodes):
    k = np.array([3.0, 0.5, 2.0])
    c = np.array([0.2, 1.5, -0.9])
    roots, positive = _search(k, c, n_nodes=n_nodes, certify=True)
    np.testing.assert_allclose(roots[[0, 2]], np.arccos(-c[[0, 2]]) / k[[0, 2]], atol=1e-13)
    assert positive.tolist() == [False, True, False]
