"""Figures of the nonlinear contact laws: stick/release boundaries, restitution, maps.

The analogue of the paper's Fig. 1b and of the section-2 maps for every law of
:mod:`impactsym.contact.laws`, drawn from arrays computed by the caller
(:func:`impactsym.contact.law_stick_boundary`, :func:`impactsym.contact.law_contact_map`;
several laws side by side for ``impactsym reproduce``, :mod:`impactsym.results.laws`).
A one-panel function takes an optional Matplotlib axes and returns it; a function of one
panel per law makes its figure and returns the array of axes. Map cells are rasterized
in vector output, as in :mod:`impactsym.plotting.contact`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap

from impactsym.plotting.contact import COLORS, LABELS
from impactsym.plotting.style import legend_outside
from impactsym.validation import check_condition

#: Axis label of each law's damping number (docs/physics.md, "Nonlinear contact laws").
DAMPING_LABELS = {
    "linear": "damping ratio $D$ [-]",
    "hertz-linear": "damping number $D = cT/(2m)$ [-]",
    "hunt-crossley": r"damping number $s = \lambda v_0$ [-]",
    "tsuji": r"damping number $\alpha$ [-]",
    "viscoelastic": r"damping number $\beta = 3A/(2T)$ [-]",
}
#: Axis label of each law's pressing number.
PRESSING_LABELS = {
    "linear": "pressing force $f = F/(c v_0)$ [-]",
    **dict.fromkeys(
        ("hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"),
        "pressing number $f = F T/(m v_0)$ [-]",
    ),
}
QUANTITIES = {
    "contact_time": ("contact time $t_c/T$ [-]", "Contact time"),
    "restitution": ("restitution $e$ [-]", "Coefficient of restitution"),
}


def _law(law: object) -> str:
    if law not in DAMPING_LABELS:
        raise ValueError(f"law must be one of {sorted(DAMPING_LABELS)}, got {law!r}")
    return str(law)


def plot_law_stick_boundary(
    damping_number: np.ndarray,
    boundaries: Mapping[str, np.ndarray],
    *,
    law: str,
    ax: Axes | None = None,
) -> Axes:
    """Stick/release boundaries ``{condition: f*(damping_number)}`` of one law.

    The paper's Fig. 1b for ``law``: the body releases below each line and sticks above
    it; the pressing number is on a log axis (a boundary value of 0, sticking without
    pressing force, lies below it and is not drawn).

    >>> from impactsym.contact import law_stick_boundary
    >>> D = np.linspace(0.05, 0.9, 12)
    >>> ax = plot_law_stick_boundary(
    ...     D, {c: law_stick_boundary("linear", D, condition=c) for c in LABELS}, law="linear")
    >>> ax.get_xlabel()
    'damping ratio $D$ [-]'
    """
    law = _law(law)
    if ax is None:
        ax = plt.figure(figsize=(8, 4.5), layout="tight").add_subplot()
    _boundary_lines(ax, damping_number, boundaries, law=law)
    ax.set_title(f"Stick/release boundary, {law} law")
    legend_outside(ax=ax, fontsize="small")
    return ax


def _boundary_lines(
    ax: Axes, damping_number: np.ndarray, boundaries: Mapping[str, np.ndarray], *, law: str
) -> None:
    """The lines ``f*(damping_number)`` of each condition on ``ax``, log ``f``, labels."""
    for condition, f_star in boundaries.items():
        f_star = np.asarray(f_star, dtype=float)
        shown = np.where((f_star > 0) & np.isfinite(f_star), f_star, np.nan)
        ax.plot(
            damping_number,
            shown,
            color=COLORS[check_condition(condition)],
            lw=2,
            label=f"$f^*$, {LABELS[condition]}",
        )
    ax.set_yscale("log")
    ax.text(0.05, 0.08, "release", transform=ax.transAxes, fontsize=12)
    ax.text(0.6, 0.85, "stick", transform=ax.transAxes, fontsize=12)
    ax.set_xlabel(DAMPING_LABELS[law])
    ax.set_ylabel(PRESSING_LABELS[law])


def plot_law_stick_boundaries(
    damping_numbers: Mapping[str, np.ndarray],
    boundaries: Mapping[str, Mapping[str, np.ndarray]],
) -> np.ndarray:
    """The stick/release boundaries of several laws side by side, one panel per law.

    ``damping_numbers[law]`` are the damping numbers of ``law`` and
    ``boundaries[law][condition]`` its :math:`f^*` there (as for
    :func:`plot_law_stick_boundary`); the laws are drawn in the order of
    ``damping_numbers``, the legend beside the last panel. Returns the axes.

    >>> d = np.array([0.1, 0.5])
    >>> axes = plot_law_stick_boundaries(
    ...     {"tsuji": d, "viscoelastic": d},
    ...     {"tsuji": {"force": [0.8, 0.3]}, "viscoelastic": {"force": [1.2, 0.5]}})
    >>> [ax.get_title() for ax in axes]
    ['tsuji', 'viscoelastic']
    """
    laws = [_law(law) for law in damping_numbers]
    if not laws or set(boundaries) != set(laws):
        raise ValueError(
            f"boundaries must hold the laws of damping_numbers {laws}, got {sorted(boundaries)}"
        )
    fig = plt.figure(figsize=(3.6 * len(laws) + 2.4, 4.2), layout="tight")
    axes = np.array(fig.subplots(1, len(laws), squeeze=False)[0])
    for ax, law in zip(axes, laws, strict=True):
        _boundary_lines(ax, np.asarray(damping_numbers[law]), boundaries[law], law=law)
        ax.set_title(law)
    legend_outside(ax=axes[-1], fontsize="small")
    return axes


def plot_law_restitution(
    damping_numbers: Mapping[str, np.ndarray],
    restitution: Mapping[str, Mapping[str, np.ndarray]],
) -> np.ndarray:
    """Restitution against the damping number without pressing force, one panel per law.

    ``damping_numbers[law]`` are the damping numbers of ``law`` and
    ``restitution[law][condition]`` the restitution there (0 where the body sticks); one
    line per condition, the legend beside the last panel. Returns the axes.

    >>> d = np.array([0.0, 0.5, 1.0])
    >>> axes = plot_law_restitution({"linear": d}, {"linear": {"position": [1.0, 0.16, 0.0]}})
    >>> axes[0].get_ylabel()
    'restitution $e$ [-]'
    """
    laws = [_law(law) for law in damping_numbers]
    if not laws or set(restitution) != set(laws):
        raise ValueError(
            f"restitution must hold the laws of damping_numbers {laws}, got {sorted(restitution)}"
        )
    fig = plt.figure(figsize=(3.6 * len(laws) + 2.4, 4.2), layout="tight")
    axes = np.array(fig.subplots(1, len(laws), squeeze=False)[0])
    for ax, law in zip(axes, laws, strict=True):
        for condition, e in restitution[law].items():
            ax.plot(
                damping_numbers[law],
                e,
                color=COLORS[check_condition(condition)],
                lw=2,
                ls="-" if condition == "position" else "--",
                label=LABELS[condition],
            )
        ax.set_ylim(0.0, 1.02)
        ax.grid(alpha=0.3)
        ax.set_xlabel(DAMPING_LABELS[law])
        ax.set_ylabel(QUANTITIES["restitution"][0])
        ax.set_title(law)
    legend_outside(ax=axes[-1], fontsize="small")
    return axes


def plot_law_map(
    result: Any,
    *,
    quantity: str = "contact_time",
    boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Contact time or restitution of a :class:`~impactsym.contact.lawgrid.LawContactMap`
    over its (damping number, ``f``) grid; grey where the body sticks; black line:
    ``boundary = (damping numbers, f*)`` if given. ``f`` is on a log axis when all its
    values are positive.

    >>> from impactsym.contact import law_contact_map
    >>> d, f = np.meshgrid(np.linspace(0.1, 1.0, 4), np.geomspace(0.01, 10.0, 4))
    >>> plot_law_map(law_contact_map("linear", d, f, condition="force")).get_title()
    'Contact time, linear law, force condition'
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {sorted(QUANTITIES)}, got {quantity!r}")
    law, condition = _law(result.law), check_condition(result.condition)
    label, title = QUANTITIES[quantity]
    delta, f = np.asarray(result.damping_number), np.asarray(result.f)
    values, sticks = np.asarray(getattr(result, quantity)), np.asarray(result.sticks)
    if ax is None:
        ax = plt.figure(figsize=(6, 5), layout="tight").add_subplot()
    mesh = ax.pcolormesh(
        delta, f, np.ma.masked_where(sticks, values), shading="auto", cmap="viridis",
        rasterized=True,
    )  # fmt: skip
    ax.pcolormesh(
        delta, f, np.ma.masked_where(~sticks, np.ones_like(values)), shading="auto",
        cmap=ListedColormap(["0.85"]), rasterized=True,
    )  # fmt: skip
    if boundary is not None:
        ax.plot(*boundary, color="k", lw=1.5, label="stick boundary $f^*$")
    if np.all(f > 0):
        ax.set_yscale("log")
    ax.set_xlim(float(np.min(delta)), float(np.max(delta)))
    ax.set_ylim(float(np.min(f)), float(np.max(f)))
    ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(DAMPING_LABELS[law])
    ax.set_ylabel(PRESSING_LABELS[law])
    legend_outside(ax=ax, where="below", handles=ax.get_lines(), title="grey: sticks", ncols=2)
    ax.set_title(f"{title}, {law} law, {LABELS[condition]}")
    return ax
