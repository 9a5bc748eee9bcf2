"""Figures of the spring-damper contact (paper section 2, Fig. 1a and 1b, and maps).

The functions draw arrays computed by the caller (:mod:`impactsym.contact`, or the
grids of :mod:`impactsym.results.contact`); each takes an optional Matplotlib axes (3-D
axes for the surface) and returns it, so figures compose in notebooks and papers. Map
cells are rasterized in vector output (PDF, SVG): a 400 x 400 map is 5.8 MB as vector
quads and well under 1 MB as an image, while axes, labels and lines stay vector.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap

from impactsym.plotting.style import legend_outside
from impactsym.validation import check_condition

LABELS = {"position": "position condition", "force": "force condition"}
COLORS = {"position": "tab:blue", "force": "tab:red"}


def plot_contact_surface(
    D: np.ndarray,
    f: np.ndarray,
    first: np.ndarray,
    second: np.ndarray,
    fold: tuple[np.ndarray, np.ndarray, np.ndarray],
    *,
    condition: str,
    ax: Axes | None = None,
) -> Axes:
    r"""Paper's Fig. 1a: the implicit surface :math:`g(\tau, D, f) = 0` over the D-f plane.

    Draws the lower sheet ``first`` (contact time), the upper sheet ``second`` (``g``
    rising through zero after its first minimum) over the grid ``D, f``, and the fold
    ``(D, f, tau)`` between them, where :math:`\partial g/\partial\tau = 0` and the
    surface turns over; beyond it the body sticks and the surface has no points
    (:func:`impactsym.contact.contact_surface`; the grid of
    :func:`impactsym.results.contact.surface_grid` ends exactly on the fold).

    >>> from impactsym.results.contact import surface_grid
    >>> ax = plot_contact_surface(*surface_grid(condition="force", n_points=6), condition="force")
    >>> ax.get_zlabel()
    '$\\tau$ with $g(\\tau, D, f) = 0$ [-]'
    """
    check_condition(condition)
    if ax is None:
        ax = plt.figure(figsize=(7, 5.5)).add_subplot(projection="3d")
    # the sheets are meshes: rasterized in vector output, axes and labels stay vector
    sheets = {"linewidth": 0, "rasterized": True}
    ax.plot_surface(D, f, first, color="tab:blue", alpha=0.8, label="contact time", **sheets)
    ax.plot_surface(D, f, second, color="tab:orange", alpha=0.6, label="second root", **sheets)
    ax.plot(*fold, color="k", lw=2.0, label="fold (ridge)")
    ax.set_xlabel("damping ratio $D$ [-]")
    ax.set_ylabel("pressing force $f$ [-]")
    ax.set_zlabel(r"$\tau$ with $g(\tau, D, f) = 0$ [-]")
    ax.set_title(f"Contact-time surface, {LABELS[condition]}")
    ax.view_init(elev=22, azim=-125)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, 1.0), fontsize="small")
    return ax


def plot_stick_boundary(
    f: np.ndarray,
    boundaries: Mapping[str, np.ndarray],
    *,
    ax: Axes | None = None,
    D_max: float = 2.5,
) -> Axes:
    """Paper's Fig. 1b: stick/release boundaries ``{condition: D*(f)}`` in the D-f plane.

    The pressing force is on a log axis: as ``f -> 0`` the position boundary tends to
    ``D* = 1`` and the force boundary grows without bound (like ``f**(-1/4) / 2``).

    >>> from impactsym.contact import stick_boundary
    >>> f = np.geomspace(1e-3, 10.0, 50)
    >>> ax = plot_stick_boundary(f, {c: stick_boundary(f, condition=c) for c in LABELS})
    >>> [line.get_label() for line in ax.get_lines()][:2]
    ['$D^*(f)$, position condition', '$D^*(f)$, force condition']
    """
    if ax is None:
        ax = plt.figure(figsize=(8, 4.5), layout="tight").add_subplot()
    for condition, d_star in boundaries.items():
        ax.plot(
            d_star,
            f,
            color=COLORS[check_condition(condition)],
            lw=2,
            label=f"$D^*(f)$, {LABELS[condition]}",
        )
    ax.axvline(1.0, color="0.6", lw=0.8, ls="--", label="critical damping $D = 1$")
    ax.set_yscale("log")
    ax.set_xlim(0, D_max)
    ax.set_ylim(float(np.min(f)), float(np.max(f)))
    ax.text(0.05, 0.08, "release", transform=ax.transAxes, fontsize=12)
    ax.text(0.6, 0.6, "stick", transform=ax.transAxes, fontsize=12)
    ax.set_xlabel("damping ratio $D$ [-]")
    ax.set_ylabel("pressing force $f = F/(d v_0)$ [-]")
    ax.set_title("Stick/release boundary")
    legend_outside(ax=ax, fontsize="small")
    return ax


def _map(
    D: np.ndarray,
    f: np.ndarray,
    values: np.ndarray,
    sticks: np.ndarray,
    boundary: tuple[np.ndarray, np.ndarray] | None,
    label: str,
    title: str,
    condition: str,
    ax: Axes | None,
) -> Axes:
    """Color map of ``values`` over the D-f grid; grey where it ``sticks``, rasterized."""
    check_condition(condition)
    if ax is None:
        ax = plt.figure(figsize=(6, 5), layout="tight").add_subplot()
    mesh = ax.pcolormesh(
        D,
        f,
        np.ma.masked_where(sticks, values),
        shading="auto",
        cmap="viridis",
        rasterized=True,
    )
    ax.pcolormesh(
        D,
        f,
        np.ma.masked_where(~sticks, np.ones_like(values)),
        shading="auto",
        cmap=ListedColormap(["0.85"]),
        rasterized=True,
    )
    if boundary is not None:
        ax.plot(*boundary, color="k", lw=1.5, label="stick boundary")
    ax.set_xlim(float(np.min(D)), float(np.max(D)))
    ax.set_ylim(float(np.min(f)), float(np.max(f)))
    ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel("damping ratio $D$ [-]")
    ax.set_ylabel("pressing force $f$ [-]")
    legend_outside(ax=ax, where="below", handles=ax.get_lines(), title="grey: sticks", ncols=2)
    ax.set_title(f"{title}, {LABELS[condition]}")
    return ax


def plot_contact_time_map(
    D: np.ndarray,
    f: np.ndarray,
    tau_c: np.ndarray,
    *,
    condition: str,
    boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ax: Axes | None = None,
) -> Axes:
    r"""Normalized contact time :math:`\tau_c(D, f)` over a D-f grid; grey: sticking
    (``tau_c = inf``); black line: ``boundary = (D*, f)`` if given.

    >>> from impactsym.results.contact import map_grid
    >>> D, f, tau_c, _ = map_grid(condition="position", n_points=8)
    >>> plot_contact_time_map(D, f, tau_c, condition="position").get_title()
    'Contact time, position condition'
    """
    tau_c = np.asarray(tau_c, dtype=float)
    return _map(
        D,
        f,
        tau_c,
        np.isinf(tau_c),
        boundary,
        r"contact time $\tau_c = \omega_0 t_c$ [-]",
        "Contact time",
        condition,
        ax,
    )


def plot_restitution_map(
    D: np.ndarray,
    f: np.ndarray,
    e: np.ndarray,
    *,
    sticks: np.ndarray,
    condition: str,
    boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Coefficient of restitution :math:`e(D, f)` over a D-f grid; grey where it
    ``sticks``; black line: ``boundary = (D*, f)`` if given.

    >>> from impactsym.results.contact import map_grid
    >>> D, f, tau_c, e = map_grid(condition="force", n_points=8)
    >>> plot_restitution_map(D, f, e, sticks=np.isinf(tau_c), condition="force").get_title()
    'Coefficient of restitution, force condition'
    """
    return _map(
        D,
        f,
        np.asarray(e, dtype=float),
        np.asarray(sticks, dtype=bool),
        boundary,
        "restitution $e$ [-]",
        "Coefficient of restitution",
        condition,
        ax,
    )
