"""Figures of the engine bridge: textbook vs exact restitution, MuJoCo's stick map.

The functions draw what :mod:`impactsym.engines.survey` computes; each takes an optional
Matplotlib axes and returns it. Engine measurements are added by the caller
(``ax.plot``), so the figures need no engine.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap

from impactsym.plotting.style import legend_outside


def plot_textbook_error(
    targets: np.ndarray, achieved: Mapping[str, np.ndarray], *, ax: Axes | None = None
) -> Axes:
    """Achieved against wanted restitution with the textbook damping (curves).

    ``achieved`` is :func:`impactsym.engines.survey.textbook_restitution` of ``targets``.
    The diagonal is what :func:`impactsym.engines.mujoco.solref_for` and
    :func:`impactsym.engines.lammps.hooke_for` achieve.

    >>> from impactsym.engines.survey import textbook_restitution
    >>> targets = np.linspace(0.02, 0.98, 5)
    >>> plot_textbook_error(targets, textbook_restitution(targets)).get_xlabel()
    'wanted restitution $e$ [-]'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.5), layout="tight")
    for (name, values), style in zip(achieved.items(), ("-", "--", ":"), strict=False):
        ax.plot(targets, values, style, label=f"textbook: {name}")
    ax.plot([0, 1], [0, 1], "k-", lw=0.8, label="impactsym design (all engines)")
    ax.set_xlabel("wanted restitution $e$ [-]")
    ax.set_ylabel("achieved restitution [-]")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    legend_outside(ax=ax, fontsize=8)
    return ax


def plot_stick_map(
    speed: np.ndarray,
    dampratio: np.ndarray,
    verdict: np.ndarray,
    restitution: np.ndarray,
    *,
    gravity: float = 9.81,
    ax: Axes | None = None,
) -> Axes:
    """Where MuJoCo's body sticks under gravity (timeconst 0.02): speed against dampratio.

    ``verdict, restitution`` is :func:`impactsym.engines.survey.stick_map` of ``speed``
    and ``dampratio`` (under ``gravity``, used for the title); the mesh is rasterized in
    vector output.

    >>> from impactsym.engines.survey import stick_map
    >>> speed, dampratio = np.geomspace(0.01, 3.0, 8), np.geomspace(0.05, 2.0, 8)
    >>> plot_stick_map(speed, dampratio, *stick_map(speed, dampratio)).get_ylabel()
    'dampratio [-]'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5), layout="tight")
    cmap = ListedColormap(["0.75", "#c6dbef", "#fdd0a2"])
    ax.pcolormesh(
        speed, dampratio, verdict, cmap=cmap, vmin=-0.5, vmax=2.5, shading="auto", rasterized=True
    )
    released = np.where(verdict > 0, restitution, np.nan)
    # black contours and labels: readable on every background colour of the mesh
    lines = ax.contour(speed, dampratio, released, levels=[0.1, 0.3, 0.5], colors="k")
    ax.clabel(lines, fmt="e=%.1f", fontsize=8, colors="k")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("approach speed [m/s]")
    ax.set_ylabel("dampratio [-]")
    ax.set_title(
        f"MuJoCo, g = {gravity:g} m/s$^2$: grey sticks, blue force ends contact, "
        "orange contact lost",
        fontsize=8,
    )
    return ax
