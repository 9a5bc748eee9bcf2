"""The conventions every impactsym figure follows: units on the axes, legends beside them.

**Units.** Every axis label -- x, y, z and colour bar -- ends its quantity with the unit
in square brackets: ``contact time $t_c$ [s]``, ``approach speed [m/s]``. A
dimensionless quantity carries ``[-]``; a normalized one says its scale in the label and
then ``[-]`` (``time $t\\,/\\,(L/c)$ [-]``, ``$\\tau = \\omega_0 t$ [-]``). Physical
units are SI unless a function takes the unit as an argument.
:data:`UNITS` lists the units the figures use; the test suite renders every figure and
checks each label against it.

**Legends** never cover data: :func:`legend_outside` puts a legend beside the axes
(right) or, where a colour bar already takes the right-hand side, below them. Figures
saved with a tight layout (:func:`impactsym.results.files.save_figure`,
``layout="constrained"`` or ``bbox_inches="tight"``) make room for it.

**Contour labels** are drawn in black on a light background (or white on a dark one),
never in a colour map's own colours.
"""

from __future__ import annotations

import re
from typing import Any

#: The units of the figures' axis labels, as written inside the square brackets.
UNITS = ("-", "s", "1/s", "m", "m/s", "m/s$^2$", "N", "N/m", "N s/m", "kg", "J")

#: A label carries a unit when it contains ``[unit]`` with one of :data:`UNITS`.
UNIT_PATTERN = re.compile(r"\[(" + "|".join(re.escape(unit) for unit in UNITS) + r")\]")

_PLACEMENTS = {
    "right": {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0},
    "below": {"loc": "upper center", "bbox_to_anchor": (0.5, -0.2), "borderaxespad": 0.0},
}


def has_unit(label: str) -> bool:
    """Whether an axis ``label`` carries a unit by the convention above.

    >>> has_unit("approach speed [m/s]"), has_unit("damping ratio $D$ [-]")
    (True, True)
    >>> has_unit("dampratio"), has_unit("$D^*(f)$")
    (False, False)
    """
    return UNIT_PATTERN.search(label) is not None


def legend_outside(*, ax: Any, where: str = "right", **options: Any) -> Any:
    """Draw the legend of ``ax`` outside its data area and return it.

    Parameters
    ----------
    ax
        Matplotlib axes (keyword-only, as everywhere in the package).
    where
        ``"right"`` (beside the axes, top-aligned) or ``"below"`` (under the x label;
        for axes whose right-hand side holds a colour bar).
    **options
        Passed to :meth:`matplotlib.axes.Axes.legend` (``handles``, ``fontsize``,
        ``title``, ...).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> ax = plt.figure().add_subplot()
    >>> _ = ax.plot([0, 1], [0, 1], label="line")
    >>> box = legend_outside(ax=ax).get_bbox_to_anchor().transformed(ax.transAxes.inverted())
    >>> round(float(box.x0), 6)
    1.02
    >>> plt.close(ax.figure)
    """
    if where not in _PLACEMENTS:
        raise ValueError(f"where must be one of {sorted(_PLACEMENTS)}, got {where!r}")
    return ax.legend(**_PLACEMENTS[where], **options)
