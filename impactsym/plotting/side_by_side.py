"""The engines side by side: restitution delivered against the wanted one, per engine,
with the native recipe (predicted curve and band, measured points) and impactsym's design
(measured points on the diagonal its prediction is by construction).

Draws what :mod:`impactsym.engines.side_by_side` computes; no engine is needed.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from impactsym.plotting.style import legend_outside

#: One colour per engine.
COLORS = {"MuJoCo": "C0", "LAMMPS": "C2", "Drake": "C3", "PyBullet": "C1"}


def plot_side_by_side(
    targets: np.ndarray,
    native: Mapping[str, Mapping[str, np.ndarray]],
    measured: Mapping[tuple[str, str], Mapping[str, np.ndarray]] | None = None,
    *,
    title: str = "",
    ymax: float = 1.15,
    ax: Axes | None = None,
) -> Axes:
    """Delivered over wanted restitution, one colour per engine.

    ``native[label]``: the predicted phase ``"mean"``, ``"min"``, ``"max"`` of a
    native recipe at ``targets`` (or at its own ``"targets"``); ``label`` is the engine
    (dashed line and band) or the engine and a recipe name, e.g.
    ``"PyBullet restitution"`` (dotted line and band), coloured by its first word.
    ``measured[(engine, recipe)]`` with ``recipe`` ``"native"`` (open circles),
    ``"native-restitution"`` (open triangles) or ``"impactsym"`` (filled squares): the
    engine's ``"targets"`` and phase ``"mean"``. The diagonal is impactsym's designs as
    predicted. Values above ``ymax`` (a diverging step map) are left off the axes.

    >>> e = np.linspace(0.2, 0.9, 5)
    >>> plot_side_by_side(e, {"MuJoCo": {"mean": e, "min": e, "max": e}}).get_ylabel()
    'delivered restitution [-]'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.5), layout="tight")
    ax.plot([0, 1], [0, 1], "k-", lw=0.8, label="impactsym designs (predicted)")
    for label, curve in native.items():
        color = COLORS.get(label.split()[0], "k")
        x = curve.get("targets", targets)
        plain = " " not in label
        ax.fill_between(x, curve["min"], curve["max"], color=color, alpha=0.15 if plain else 0.08,
                        lw=0)  # fmt: skip
        name = f"{label} native" if plain else label
        ax.plot(x, curve["mean"], "--" if plain else ":", color=color,
                label=f"{name} (predicted)")  # fmt: skip
    names = {"native": "native", "native-restitution": "restitution", "impactsym": "impactsym"}
    marks = {"native": "o", "native-restitution": "^"}
    for (engine, recipe), points in (measured or {}).items():
        color = COLORS.get(engine, "k")
        native_recipe = recipe in marks
        ax.plot(
            points["targets"],
            points["mean"],
            marks.get(recipe, "s"),
            ls="none",
            color=color,
            mfc="none" if native_recipe else color,
            ms=6 if native_recipe else 4,
            label=f"{engine} {names.get(recipe, recipe)} (measured)",
        )
    ax.set_xlim(0, 1)
    ax.set_ylim(0, ymax)
    ax.set_xlabel("wanted restitution $e$ [-]")
    ax.set_ylabel("delivered restitution [-]")
    if title:
        ax.set_title(title, fontsize=9)
    legend_outside(ax=ax, fontsize=7)
    return ax
