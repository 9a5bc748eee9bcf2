"""Figures of the spring-damper contact (paper section 2, Fig. 1a and 1b, and maps).

Every function takes an optional Matplotlib axes (3-D axes for the surface) and
returns it, so figures compose in notebooks and papers.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap

from impactsym.contact import contact_surface, contact_time, restitution, stick_boundary
from impactsym.validation import check_condition

LABELS = {"position": "position condition", "force": "force condition"}
COLORS = {"position": "tab:blue", "force": "tab:red"}


def boundary_curve(
    *, condition: str, f_max: float = 2.0, n_points: int = 400
) -> tuple[np.ndarray, ...]:
    """``(D*, f)`` along the stick boundary for ``0 < f <= f_max`` (log-spaced).

    >>> d_star, f = boundary_curve(condition="position", f_max=1.0, n_points=3)
    >>> f.tolist(), bool(d_star[0] > d_star[-1])
    ([0.0001, 0.01, 1.0], True)
    """
    f = np.geomspace(f_max * 1e-4, f_max, n_points)
    return stick_boundary(f, condition=condition), f


def plot_contact_surface(
    *,
    condition: str = "force",
    ax: Axes | None = None,
    D_max: float = 1.5,
    f_max: float = 1.0,
    n_points: int = 60,
) -> Axes:
    r"""Paper's Fig. 1a: the implicit surface :math:`g(\tau, D, f) = 0` over the D-f plane.

    Shows the lower sheet (contact time), the upper sheet (``g`` rising through zero
    after its first minimum) and the fold between them, where
    :math:`\partial g/\partial\tau = 0` and the surface turns over; beyond it the body
    sticks and the surface has no points.

    >>> ax = plot_contact_surface(condition="force", n_points=6)
    >>> ax.get_zlabel()
    '$\\tau$ with $g(\\tau, D, f) = 0$'
    """
    check_condition(condition)
    if ax is None:
        ax = plt.figure(figsize=(7, 5.5)).add_subplot(projection="3d")
    # grid in (s, f) with D = s * min(D*(f), D_max): the sheets end exactly on the fold
    n = n_points
    f_line = np.linspace(f_max / n, f_max, n)
    reach = np.minimum(stick_boundary(f_line, condition=condition), D_max)
    s = np.linspace(0.0, 1.0 - 1e-9, n)[:, None]
    D, f = s * reach, np.broadcast_to(f_line, (n, n))
    first, second, _ = contact_surface(D, f, condition=condition)
    ax.plot_surface(D, f, first, color="tab:blue", alpha=0.8, linewidth=0, label="contact time")
    ax.plot_surface(D, f, second, color="tab:orange", alpha=0.6, linewidth=0, label="second root")
    on_fold = reach < D_max
    _, _, ridge = contact_surface(reach[on_fold], f_line[on_fold], condition=condition)
    ax.plot(reach[on_fold], f_line[on_fold], ridge, color="k", lw=2.0, label="fold (ridge)")
    ax.set_xlabel("damping $D$")
    ax.set_ylabel("pressing force $f$")
    ax.set_zlabel(r"$\tau$ with $g(\tau, D, f) = 0$")
    ax.set_title(f"Contact-time surface, {LABELS[condition]}")
    ax.view_init(elev=22, azim=-125)
    ax.legend(loc="upper left")
    return ax


def plot_stick_boundary(
    *, ax: Axes | None = None, f_range: tuple[float, float] = (1e-3, 10.0), D_max: float = 2.5
) -> Axes:
    """Paper's Fig. 1b: stick/release boundaries of both conditions in the D-f plane.

    The pressing force is on a log axis: as ``f -> 0`` the position boundary tends to
    ``D* = 1`` and the force boundary grows without bound (like ``f**(-1/4) / 2``).

    >>> ax = plot_stick_boundary()
    >>> [line.get_label() for line in ax.get_lines()][:2]
    ['$D^*(f)$, position condition', '$D^*(f)$, force condition']
    """
    if ax is None:
        ax = plt.figure(figsize=(6, 4.5)).add_subplot()
    f = np.geomspace(*f_range, 400)
    for condition in ("position", "force"):
        ax.plot(
            stick_boundary(f, condition=condition),
            f,
            color=COLORS[condition],
            lw=2,
            label=f"$D^*(f)$, {LABELS[condition]}",
        )
    ax.axvline(1.0, color="0.6", lw=0.8, ls="--", label="critical damping $D = 1$")
    ax.set_yscale("log")
    ax.set_xlim(0, D_max)
    ax.set_ylim(*f_range)
    ax.text(0.05, 0.08, "release", transform=ax.transAxes, fontsize=12)
    ax.text(0.6, 0.6, "stick", transform=ax.transAxes, fontsize=12)
    ax.set_xlabel("damping $D$")
    ax.set_ylabel("pressing force $f = F/(d v_0)$")
    ax.set_title("Stick/release boundary")
    ax.legend(loc="upper right")
    return ax


def _map(
    quantity,
    label: str,
    title: str,
    condition: str,
    ax: Axes | None,
    D_max: float,
    f_max: float,
    n_points: int,
) -> Axes:
    """Color map of ``quantity(D, f, condition)`` over the D-f plane; grey where it sticks."""
    check_condition(condition)
    if ax is None:
        ax = plt.figure(figsize=(6, 4.5)).add_subplot()
    D, f = np.meshgrid(np.linspace(0, D_max, n_points), np.linspace(0, f_max, n_points))
    values = quantity(D, f, condition=condition)
    stuck = np.isinf(contact_time(D, f, condition=condition))
    # the cells are rasterized in vector output (PDF, SVG): a 400 x 400 map is 5.8 MB as
    # vector quads and well under 1 MB as an image; axes, labels and the boundary line
    # stay vector
    mesh = ax.pcolormesh(
        D,
        f,
        np.ma.masked_where(stuck, values),
        shading="auto",
        cmap="viridis",
        rasterized=True,
    )
    ax.pcolormesh(
        D,
        f,
        np.ma.masked_where(~stuck, np.ones_like(values)),
        shading="auto",
        cmap=ListedColormap(["0.85"]),
        rasterized=True,
    )
    d_star, f_line = boundary_curve(condition=condition, f_max=f_max)
    ax.plot(d_star, f_line, color="k", lw=1.5, label="stick boundary")
    ax.set_xlim(0, D_max)
    ax.set_ylim(0, f_max)
    ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel("damping $D$")
    ax.set_ylabel("pressing force $f$")
    ax.legend(loc="upper right", title="grey: sticks")
    ax.set_title(f"{title}, {LABELS[condition]}")
    return ax


def plot_contact_time_map(
    *,
    condition: str = "force",
    ax: Axes | None = None,
    D_max: float = 1.5,
    f_max: float = 1.0,
    n_points: int = 300,
) -> Axes:
    r"""Normalized contact time :math:`\tau_c(D, f)` over the D-f plane; grey: sticking.

    >>> plot_contact_time_map(condition="position", n_points=8).get_title()
    'Contact time, position condition'
    """
    return _map(
        contact_time,
        r"contact time $\tau_c$",
        "Contact time",
        condition,
        ax,
        D_max,
        f_max,
        n_points,
    )


def plot_restitution_map(
    *,
    condition: str = "force",
    ax: Axes | None = None,
    D_max: float = 1.5,
    f_max: float = 1.0,
    n_points: int = 300,
) -> Axes:
    """Coefficient of restitution :math:`e(D, f)` over the D-f plane; grey: sticking.

    >>> plot_restitution_map(condition="force", n_points=8).get_title()
    'Coefficient of restitution, force condition'
    """
    return _map(
        restitution,
        "restitution $e$",
        "Coefficient of restitution",
        condition,
        ax,
        D_max,
        f_max,
        n_points,
    )
