"""Figure of what the usual damping design formulas deliver (nonlinear contact laws).

:func:`plot_formula_errors` draws the table of
:func:`impactsym.contact.lawformulas.formula_table` computed by the caller: the
restitution each formula delivers against the one it was asked for.
"""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from impactsym.plotting.style import legend_outside

_STYLES = ("-o", "-s", "-^", "-v", "-D", "--", ":")


def plot_formula_errors(
    target: np.ndarray,
    delivered: np.ndarray,
    labels: Sequence[str],
    *,
    ax: Axes | None = None,
) -> Axes:
    """Delivered against asked-for restitution, one curve per design formula.

    ``delivered[i]`` is what formula ``labels[i]`` delivers for ``target``; the diagonal
    is the exact design (:func:`impactsym.contact.damping_for`).

    >>> t = np.array([0.2, 0.5, 0.8])
    >>> plot_formula_errors(t, np.array([t + 0.1, t]), ["a", "b"]).get_xlabel()
    'target restitution $e$ [-]'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(8.0, 4.8), layout="tight")
    ax.plot([0, 1], [0, 1], "-", color="0.6", lw=2.5, label="exact design (damping_for)")
    for row, label, style in zip(delivered, labels, _STYLES * len(labels), strict=False):
        ax.plot(target, row, style, ms=3.5, lw=1.2, label=label)
    ax.set_xlabel("target restitution $e$ [-]")
    ax.set_ylabel("delivered restitution [-]")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    legend_outside(ax=ax, fontsize=8)
    return ax
