"""Figures of the rod impact continued past separation (:func:`impactsym.rod.impact_sequence`).

The functions draw sequences computed by the caller; each takes an optional Matplotlib
axes and returns it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from impactsym.plotting.style import legend_outside


def plot_sequence(seq: Any, *, ax: Axes | None = None, n_points: int = 4001) -> Axes:
    r"""Energy split over time with the contact intervals shaded.

    Striker kinetic energy :math:`\alpha y'^2/2`, rod energy (elastic + kinetic), the
    work :math:`f y` of the pressing force, all in units of :math:`m_{rod} v_0^2`;
    grey bands: contact.

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> ax = plot_sequence(impact_sequence(1.0, 0.0, t_max=8.0), n_points=50)
    >>> len(ax.lines)
    3
    """
    if ax is None:
        ax = plt.figure(figsize=(9.5, 3.5), layout="tight").add_subplot()
    t = np.linspace(0.0, seq.t_max, n_points)[:-1]
    energy = seq.energy
    ax.plot(t, energy.striker(t), label=r"striker $\alpha y'^2/2$")
    ax.plot(t, energy.rod(t), label="rod (elastic + kinetic)")
    ax.plot(t, energy.work(t), label=r"work of $f$: $f y$", ls="--")
    if hasattr(energy, "spring"):  # a finite contact stiffness
        ax.plot(t, energy.spring(t), label=r"contact spring $N^2/(2\kappa)$")
    for start, end in seq.contacts:
        ax.axvspan(start, end, color="0.85", zorder=0)
    ax.set_xlabel(r"time $t\,/\,(L/c)$ [-]")
    ax.set_ylabel(r"energy $/\,(m_{rod} v_0^2)$ [-]")
    stiffness = "" if np.isinf(seq.kappa) else rf", $\kappa = {seq.kappa:g}$"
    ax.set_title(
        rf"$\alpha = {seq.alpha:g}$, $f = {seq.f:g}${stiffness}: "
        f"{len(seq.contacts)} contact(s) (grey)"
    )
    legend_outside(ax=ax, fontsize="small")
    return ax


def plot_fixed_end_stress(sequences: Sequence[Any], *, ax: Axes | None = None) -> Axes:
    r"""Largest compressive stress at the fixed end over :math:`\alpha`.

    One point per sequence (all of one ``f`` and horizon), against the light-striker
    value :math:`2(1 + e^{-2/\alpha})` (the reflected front meets the next one) and the
    rod as a massless spring, :math:`\sqrt{\alpha}` (unit :math:`E v_0 / c`, the impact
    stress).

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> ax = plot_fixed_end_stress([impact_sequence(a, 0.0, t_max=6.0) for a in (0.5, 2.0)])
    >>> len(ax.lines)
    3
    """
    if ax is None:
        ax = plt.figure(figsize=(7.5, 4), layout="tight").add_subplot()
    alpha = np.array([seq.alpha for seq in sequences], dtype=float)
    stress = [seq.max_fixed_end_stress for seq in sequences]
    f, t_max = sequences[0].f, sequences[0].t_max
    ax.plot(alpha, stress, "o-", ms=3, label=rf"exact, $f = {f:g}$, $t \leq {t_max:g}$")
    ax.plot(alpha, 2 * (1 + np.exp(-2 / alpha)), ":", label=r"$2(1 + e^{-2/\alpha})$")
    ax.plot(alpha, np.sqrt(alpha), "--", label=r"massless spring $\sqrt{\alpha}$")
    ax.set_xscale("log")
    ax.set_xlabel(r"mass ratio $\alpha = M / m_{rod}$ [-]")
    ax.set_ylabel(r"max $\sigma(1, t)\,/\,(E v_0 / c)$ [-]")
    legend_outside(ax=ax, fontsize="small")
    return ax


def plot_restitution(sequences: Sequence[Any], *, ax: Axes | None = None) -> Axes:
    r"""Coefficient of restitution of Saint-Venant's problem (:math:`f = 0`) over
    :math:`\alpha`, one point per sequence, against the classical values: :math:`e = 1`
    of the rigid-body (massless-spring) theory and the single-contact light-striker value
    :math:`2 \exp(-1 - e^{-2/\alpha}/2)` (valid while one contact ends before
    :math:`t = 4`).

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> ax = plot_restitution([impact_sequence(a, 0.0, t_max=20.0) for a in (0.5, 2.0)])
    >>> len(ax.lines)
    3
    """
    if ax is None:
        ax = plt.figure(figsize=(7.5, 4), layout="tight").add_subplot()
    alpha = np.array([seq.alpha for seq in sequences], dtype=float)
    e = [seq.restitution for seq in sequences]
    ax.plot(alpha, e, "o-", ms=3, label="exact (all contacts)")
    light = 2 * np.exp(-1 - np.exp(-2 / alpha) / 2)
    ax.plot(alpha, np.where(alpha < 1.7, light, np.nan), ":", label="one contact, light striker")
    ax.plot(alpha, np.ones_like(alpha), "--", label="rigid body / massless spring")
    ax.set_xscale("log")
    ax.set_xlabel(r"mass ratio $\alpha = M / m_{rod}$ [-]")
    ax.set_ylabel("coefficient of restitution [-]")
    legend_outside(ax=ax, fontsize="small")
    return ax
