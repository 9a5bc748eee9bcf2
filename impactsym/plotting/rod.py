"""Figures of the rod impact (paper section 1): time histories and contact-time maps.

The functions draw results computed by the caller
(:class:`~impactsym.rod.history.TimeHistory`,
:class:`~impactsym.rod.contact_times.ContactTimeMap`); each takes an optional
Matplotlib axes (or a sequence of them) and returns it, so figures compose in notebooks
and papers. Map cells are rasterized in vector output.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import LogNorm
from matplotlib.patheffects import withStroke

from impactsym.plotting.style import legend_outside
from impactsym.validation import check_condition

#: quantity -> (attribute of TimeHistory, its contact-time attribute, axis label)
QUANTITIES = {
    "y": (
        "displacement",
        "contact_time_position",
        r"striker displacement $y\,/\,(v_0 L/c)$ [-]",
    ),
    "N": ("contact_force", "contact_time_force", r"contact force $N\,/\,(E A v_0/c)$ [-]"),
}


def plot_time_history(
    histories: Sequence[Any], quantity: str = "N", *, ax: Axes | None = None
) -> Axes:
    r"""Time history of :math:`y(t)` or :math:`N(t)` for a few :math:`(\alpha, f)`.

    One line per :class:`~impactsym.rod.history.TimeHistory` (the persistent-contact
    solution, :func:`impactsym.rod.history.time_history`); dotted vertical lines mark
    the reflection times :math:`t = 2, 4, \dots` (a reflected wave returns to the
    struck end), and a dot marks the first zero crossing (the contact time of the
    position condition for ``y``, of the force condition for ``N``).

    Parameters
    ----------
    histories
        One line each; the time axis ends at the largest ``t_max``.
    quantity
        ``"y"`` or ``"N"``.
    ax
        Axes to draw into (a new figure if omitted).

    Examples
    --------
    >>> from impactsym.rod.history import time_history
    >>> ax = plot_time_history([time_history(1.0, 0.0, t_max=4.0, n_points=50)], "N")
    >>> [float(x) for x in ax.get_xlim()]
    [0.0, 4.0]
    >>> plt.close(ax.figure)
    """
    values, zero, ax = _time_axes(quantity, ax, max(h.t_max for h in histories))
    for h in histories:
        (line,) = ax.plot(
            h.t, getattr(h, values), lw=1.3, label=rf"$\alpha={h.alpha:g},\ f={h.f:g}$"
        )
        tc = getattr(h, zero)
        if np.isfinite(tc):
            ax.plot([tc], [0.0], "o", color=line.get_color(), ms=5)
    kappa = histories[0].kappa
    stiffness = "rigid contact" if np.isinf(kappa) else rf"$\kappa = {kappa:g}$"
    ax.set_title(f"Rod impact, persistent contact, {stiffness}; dots: first zero")
    legend_outside(ax=ax, fontsize="small")
    return ax


def _time_axes(quantity: str, ax: Axes | None, t_max: float):
    """Attribute names of ``quantity`` and its zero, and the axes framed for a time
    history (labels, zero line, dotted reflection times)."""
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be 'y' or 'N', got {quantity!r}")
    values, zero, ylabel = QUANTITIES[quantity]
    if ax is None:
        ax = plt.figure(figsize=(8.5, 4), layout="tight").add_subplot()
    for k in range(2, int(t_max) + 1, 2):
        ax.axvline(k, color="0.6", lw=0.8, ls=":", zorder=0)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, t_max)
    ax.set_xlabel(r"time $t\,/\,(L/c)$ [-] (dotted: reflections return)")
    ax.set_ylabel(ylabel)
    return values, zero, ax


def _pcolor_edges(values: np.ndarray, log: bool) -> np.ndarray:
    v = np.log(values) if log else values
    mid = (v[1:] + v[:-1]) / 2 if v.size > 1 else v
    first = 2 * v[0] - mid[0] if v.size > 1 else v[0] - 0.5
    last = 2 * v[-1] - mid[-1] if v.size > 1 else v[0] + 0.5
    edges = np.r_[first, mid, last]
    return np.exp(edges) if log else edges


def _ordinal(k: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(k, f"{k}th")


def _atlas_frame(study: Any, ax: Axes | None):
    if ax is None:
        ax = plt.figure(figsize=(6, 4.5), layout="tight").add_subplot()
    ae, fe = _pcolor_edges(study.alpha, True), _pcolor_edges(study.f, False)
    return ax, ae, fe


def _shade_sticking(ax: Axes, study: Any, sticks: np.ndarray, color: str) -> None:
    """Grey shading (rasterized) and a smooth outline where the striker sticks."""
    if not sticks.any():
        return
    ae, fe = _pcolor_edges(study.alpha, True), _pcolor_edges(study.f, False)
    ax.pcolormesh(
        ae, fe, np.where(sticks, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2, rasterized=True
    )
    if min(sticks.shape) > 1:
        ax.contour(
            study.alpha, study.f, sticks.astype(float), levels=[0.5], colors=color, linewidths=1.0
        )


def _mark_intervals(ax: Axes, study: Any, condition: str) -> None:
    """Boundaries between the regions whose first contact ends on the 1st, 2nd, ...
    reflection interval (white lines), each region labelled once."""
    interval = study.interval(condition=condition)
    if min(interval.shape) < 2 or np.all(np.isnan(interval)):
        return
    top = int(np.nanmax(interval))
    filled = np.where(np.isnan(interval), top + 1, interval)
    levels = np.arange(1.5, top + 1.0)
    if levels.size:
        ax.contour(study.alpha, study.f, filled, levels=levels, colors="w", linewidths=0.8)
    A, F = np.meshgrid(np.log(study.alpha), study.f)
    for k in range(1, min(top, 6) + 1):
        region = interval == k
        if region.sum() < max(4, region.size // 400):
            continue
        # the region's point nearest to its centroid (in log alpha, f)
        la, ff = A[region], F[region]
        i = np.argmin((la - la.mean()) ** 2 + (ff - ff.mean()) ** 2)
        ax.text(
            np.exp(la[i]),
            ff[i],
            _ordinal(k),
            color="w",
            fontsize=8,
            ha="center",
            va="center",
            fontweight="bold",
            path_effects=[withStroke(linewidth=2, foreground="k")],  # readable on any colour
        )


def plot_contact_time_atlas(study: Any, *, condition: str, ax: Axes | None = None) -> Axes:
    r"""Contact time of one condition over the :math:`\alpha`-:math:`f` plane (an atlas).

    Colour: :math:`t_c` (rasterized mesh, so that PDFs stay small); black lines:
    smooth contours of :math:`t_c`; white lines and labels: the regions where the
    first contact ends on the 1st, 2nd, 3rd, ... reflection interval
    (:meth:`~impactsym.rod.contact_times.ContactTimeMap.interval`); grey: the striker
    sticks (no sign change up to ``study.t_max``).

    >>> from impactsym.rod import contact_time_map
    >>> ax = plot_contact_time_atlas(contact_time_map([0.5, 5.0], [0.0, 0.5]), condition="position")
    >>> ax.get_xscale()
    'log'
    >>> plt.close(ax.figure)
    """
    times = {"force": study.force, "position": study.position}[check_condition(condition)]
    ax, ae, fe = _atlas_frame(study, ax)
    finite = np.where(np.isfinite(times), times, np.nan)
    mesh = ax.pcolormesh(
        ae,
        fe,
        finite,
        cmap="viridis",
        norm=LogNorm(vmin=2.0, vmax=max(4.0, np.nanmax(finite, initial=4.0))),
        rasterized=True,
    )
    ax.figure.colorbar(mesh, ax=ax, label=r"contact time $t_c\,/\,(L/c)$ [-]")
    if min(times.shape) > 1 and np.isfinite(times).sum() > 3:
        levels = [3, 5, 8, 12, 20, 40]
        ax.contour(study.alpha, study.f, finite, levels=levels, colors="k", linewidths=0.5)
    _mark_intervals(ax, study, condition)
    _shade_sticking(ax, study, np.isinf(times), "k")
    ax.set_xscale("log")
    ax.set_xlabel(r"mass ratio $\alpha = M / m_{rod}$ [-]")
    ax.set_ylabel(r"pressing force $f$ [-]")
    ax.set_title(
        f"{condition} condition{_stiffness(study)} (grey: sticks up to t = {study.t_max:g})"
    )
    return ax


def plot_contact_time_ratio(study: Any, *, ax: Axes | None = None) -> Axes:
    r"""Ratio of the contact times, position over force condition.

    Near 1 (white) the two conditions agree (colours saturate at 1/4 and 4; black
    contours at 1/2, 1, 2); shaded where the striker sticks under one condition
    (light grey) or both (dark grey).

    >>> from impactsym.rod import contact_time_map
    >>> ax = plot_contact_time_ratio(contact_time_map([0.1, 5.0], [0.0, 2.0]))
    >>> ax.get_title()
    'contact-time ratio, position / force condition'
    >>> plt.close(ax.figure)
    """
    ax, ae, fe = _atlas_frame(study, ax)
    ratio = study.ratio
    mesh = ax.pcolormesh(
        ae, fe, ratio, cmap="RdBu_r", norm=LogNorm(vmin=0.25, vmax=4.0), rasterized=True
    )
    ax.figure.colorbar(mesh, ax=ax, label=r"$t_c^{\,position} / t_c^{\,force}$ [-]")
    if min(ratio.shape) > 1 and np.isfinite(ratio).sum() > 3:
        ax.contour(study.alpha, study.f, ratio, levels=[0.5, 1.0, 2.0], colors="k", linewidths=0.6)
    force_sticks, position_sticks = np.isinf(study.force), np.isinf(study.position)
    either = force_sticks | position_sticks
    if either.any():
        shade = np.where(force_sticks & position_sticks, 2.0, np.where(either, 1.0, np.nan))
        ax.pcolormesh(ae, fe, shade, cmap="Greys", vmin=0, vmax=3, rasterized=True)
    ax.set_xscale("log")
    ax.set_xlabel(r"mass ratio $\alpha = M / m_{rod}$ [-]")
    ax.set_ylabel(r"pressing force $f$ [-]")
    ax.set_title("contact-time ratio, position / force condition" + _stiffness(study))
    return ax


def _stiffness(study: Any) -> str:
    """``", kappa = ..."`` for a finite contact stiffness, else nothing (rigid)."""
    return "" if np.isinf(study.kappa) else rf", $\kappa = {study.kappa:g}$"


def plot_contact_time_atlases(study: Any, *, axes: Sequence[Axes] | None = None):
    """The three atlases side by side: force, position, ratio. Returns the axes.

    >>> from impactsym.rod import contact_time_map
    >>> axes = plot_contact_time_atlases(contact_time_map([0.5, 5.0], [0.0, 0.5]))
    >>> len(axes)
    3
    >>> plt.close(axes[0].figure)
    """
    if axes is None:
        axes = plt.figure(figsize=(16, 4.6), layout="tight").subplots(1, 3)
    plot_contact_time_atlas(study, condition="force", ax=axes[0])
    plot_contact_time_atlas(study, condition="position", ax=axes[1])
    plot_contact_time_ratio(study, ax=axes[2])
    return axes


def plot_stiffness_comparison(
    histories: Sequence[Any], quantity: str = "N", *, ax: Axes | None = None
) -> Axes:
    r"""``y`` or ``N`` of one :math:`(\alpha, f)` for several contact stiffnesses
    :math:`\kappa` (one :class:`~impactsym.rod.history.TimeHistory` each; ``inf``: rigid).

    >>> from impactsym.rod.history import time_history
    >>> runs = [time_history(1.0, 0.2, kappa=k, t_max=3.0, n_points=100) for k in (50.0, np.inf)]
    >>> ax = plot_stiffness_comparison(runs)
    >>> [line.get_label() for line in ax.lines if not line.get_label().startswith("_")]
    ['$\\kappa = 50$', 'rigid']
    >>> plt.close(ax.figure)
    """
    values, _, ax = _time_axes(quantity, ax, max(h.t_max for h in histories))
    for h in histories:
        label = "rigid" if np.isinf(h.kappa) else rf"$\kappa = {h.kappa:g}$"
        ax.plot(h.t, getattr(h, values), lw=1.2, label=label)
    first = histories[0]
    ax.set_title(rf"Contact stiffness, $\alpha = {first.alpha:g}$, $f = {first.f:g}$")
    legend_outside(ax=ax, fontsize="small")
    return ax
