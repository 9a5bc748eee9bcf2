"""The pointwise contact-time search on the pole sums alone, no table: a reference for the tables.

Every force is searched on its own from a uniform grid of initial nodes (step at most 0.1,
``alpha / 4`` and half the contact spring's time scale, plus the reflection times), with
the values, slopes and second-derivative bounds of the pole sums
(:func:`impactsym.rod.elastic.search.pole_search`): nothing of the cell tables
(:mod:`impactsym.rod.elastic.cells`, :mod:`impactsym.rod.elastic.taylor`), their
screening of forces or their interval-by-interval search. Also
:func:`table_within_its_bounds`: a table's values against the pole sums at 60 digits.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.isolation import first_sign_change
from impactsym.rod.elastic.poles import pole_model
from impactsym.rod.elastic.search import pole_search
from impactsym.rod.elastic.taylor import fastest_rate


def pointwise_pole_contact_times(which, alpha, f, *, kappa, t_max):
    """First sign change of ``y`` or ``N`` (``which``) in ``(0, t_max]`` for the forces
    ``f`` (1-D) at one ``(alpha, kappa)``; ``inf`` if none."""
    f = np.asarray(f, dtype=float)
    n_terms = int(t_max // 2) + 1
    evaluate, bound = pole_search(which, alpha, f, kappa=kappa, n_terms=n_terms)
    step = min(0.1, 0.25 * alpha, 0.5 / np.sqrt(fastest_rate(alpha, kappa=kappa)))
    base = np.union1d(
        np.linspace(0.0, t_max, int(np.ceil(t_max / step)) + 1), np.arange(2.0, t_max, 2.0)
    )
    owner = np.repeat(np.arange(f.size), base.size)
    nodes = np.tile(base, f.size)
    roots = first_sign_change(evaluate, bound, nodes, owner, f.size, max_cells=2**22)
    return np.where(np.isnan(roots), np.inf, roots)


def table_within_its_bounds(table, alpha, kappa, n_terms, t, f):
    """Assert that ``N`` and ``y`` of ``table`` at ``(t, f)`` lie within their proven
    bounds of the pole sums evaluated in mpmath at 60 digits (the inverted Laplace series,
    nothing of the delay equations); the bounds, ``N``'s then ``y``'s."""
    bounds = []
    for which in ("N", "y"):
        reference = pole_model(which, alpha, kappa=kappa, n_terms=n_terms, dps=60)
        view = table.view(which)
        value, _ = view.evaluate(t, f)
        exact = np.array([reference.evaluate_mp(x, y) for x, y in zip(t, f, strict=True)])
        i = view.cell(t)
        bound = view.err_a[i] + f * view.err_b[i]
        assert np.all(np.abs(value - exact) <= bound), which
        bounds.append(bound)
    return np.concatenate(bounds)
