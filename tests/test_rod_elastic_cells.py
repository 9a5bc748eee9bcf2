"""The mpmath cell table (:mod:`impactsym.rod.elastic.cells`) and finite-kappa contact times.

Against independent references:

* the delay ODE of :mod:`references.rod_elastic_delay` (d'Alembert + method of steps,
  SciPy DOP853 at ``rtol = 1e-13``, nothing from the Laplace series): contact times at
  a fixed random grid and near critical contact damping, the ``inf`` guarantee;
* the proven error bound of every cell against the pole sums evaluated with mpmath at
  90 digits (a different evaluation of the exact pole data, not the float assembly);
* the pointwise search on the pole sums alone (:mod:`references.rod_pole_search`) on an
  ``f`` sweep, where the Taylor table (the default) and the mpmath cell table
  (``method="cells"``) must agree with it.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.rod.elastic.cells import cell_table
from impactsym.rod.elastic.poles import pole_model


@pytest.mark.parametrize(
    ("which", "a", "k"),
    [
        ("N", 1.3, 20.0),
        ("y", 1.3, 20.0),
        ("N", 1.0, 4.0),  # critical: a double root
        ("y", 1.0, 3.999),  # near critical: merged in mpmath
        ("N", 2.0, 1000.0),  # a fast pole
        ("y", 0.05, 1.0),  # underdamped contact
    ],
)
def test_cell_error_bound_holds_against_90_digit_pole_sums(which, a, k):
    table = cell_table(which, a, kappa=k, n_terms=11)
    reference = pole_model(which, a, kappa=k, n_terms=11, dps=90)
    rng = np.random.default_rng(3)
    # random points, and every cell's ends and centre in the first two intervals
    early = table.hi <= 4.0
    t = np.concatenate([rng.uniform(0.0, 21.99, 25), table.lo[early], table.c[early]])
    f = rng.uniform(0.0, 3.0, t.size)
    value, _ = table.evaluate(t, f)
    exact = np.array([reference.evaluate_mp(x, y) for x, y in zip(t, f, strict=True)])
    i = table.cell(t)
    bound = table.err_a[i] + f * table.err_b[i]
    assert np.all(np.abs(value - exact) <= bound)
    # and the bound is useful: most cells are at 1e-11 or better
    assert np.mean(table.err_a + table.err_b <= 1e-11) > 0.5
