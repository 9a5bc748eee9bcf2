"""Figures of the engine bridge: textbook vs exact restitution, MuJoCo's stick map, the
restitution the engines achieve at their timestep and the timestep advisor.

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
from matplotlib.ticker import NullFormatter

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


def _draw_designs(ax, x, curves, measured, x_key):
    """One colour per design: its predicted line and band, then its measured points."""
    measured = measured or {}
    for index, name in enumerate(dict.fromkeys([*curves, *measured])):
        color = f"C{index}"
        if name in curves:
            _band_lines(ax, x, curves[name], name, color)
        if name in measured:
            _measured_points(ax, measured[name][x_key], measured[name], name, color)


def _band_lines(ax: Axes, x, curve: Mapping[str, np.ndarray], label: str, color) -> None:
    """A predicted phase-mean curve and its phase band (``"mean"``, ``"min"``, ``"max"``)."""
    ax.fill_between(x, curve["min"], curve["max"], color=color, alpha=0.2, lw=0)
    ax.plot(x, curve["mean"], "-", color=color, label=f"{label}: predicted mean, phase band")


def _measured_points(ax: Axes, x, points: Mapping[str, np.ndarray], label: str, color) -> None:
    """Engine output: phase mean with bars from the smallest to the largest value."""
    mean = np.asarray(points["mean"])
    yerr = np.array([mean - np.asarray(points["min"]), np.asarray(points["max"]) - mean])
    ax.errorbar(
        x,
        mean,
        yerr=yerr,
        fmt="o",
        ms=4,
        mfc="none",
        color=color,
        capsize=2,
        lw=0.8,
        label=f"{label}: measured mean, range",
    )


def plot_timestep_restitution(
    timesteps: np.ndarray,
    curves: Mapping[str, Mapping[str, np.ndarray]],
    measured: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    *,
    target: float,
    default_timestep: float = 0.002,
    legend: str = "right",
    ax: Axes | None = None,
) -> Axes:
    """Achieved restitution against the engine's timestep, one colour per design.

    ``curves[name]`` holds the predicted ``"mean"``, ``"min"`` and ``"max"`` over touch
    phases at ``timesteps`` (a line and a band); ``measured[name]`` (optional) the
    engine's ``"timestep"``, ``"mean"``, ``"min"``, ``"max"`` (points with bars), as
    :func:`impactsym.engines.survey.mujoco_measured` returns them. The target and the
    engine's default timestep are marked; ``legend`` is ``"right"`` or ``"below"``
    (:func:`impactsym.plotting.style.legend_outside`).

    >>> dt = np.geomspace(1e-4, 4e-3, 5)
    >>> band = {"mean": 0.5 + 0 * dt, "min": 0.49 + 0 * dt, "max": 0.51 + 0 * dt}
    >>> plot_timestep_restitution(dt, {"design": band}, target=0.5).get_xscale()
    'log'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.5), layout="tight")
    _draw_designs(ax, timesteps, curves, measured, "timestep")
    ax.axhline(target, color="k", lw=0.8, label=f"target e = {target:g}")
    ax.axvline(
        default_timestep, color="0.4", ls=":", label=f"default timestep {default_timestep:g} s"
    )
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide over two decades
    ax.set_xlabel("timestep [s]")
    ax.set_ylabel("achieved restitution $e$ [-]")
    legend_outside(ax=ax, where=legend, fontsize=8)
    return ax


def plot_timestep_advice(
    targets: np.ndarray,
    timesteps: Mapping[str, np.ndarray],
    *,
    default_timestep: float | None = 0.002,
    ylabel: str = "largest timestep for 1 % [s]",
    legend: str = "right",
    ax: Axes | None = None,
) -> Axes:
    """The timestep advisor's curves: the largest timestep against the target restitution.

    ``timesteps[name]`` are the advisor's values for ``targets`` (e.g.
    :func:`impactsym.engines.mujoco.timestep_for` of the designs, or
    :func:`impactsym.engines.survey.lammps_advice`); a log axis. ``default_timestep``
    (if not ``None``) is marked; ``legend`` as in :func:`plot_timestep_restitution`.

    >>> e = np.linspace(0.1, 0.9, 5)
    >>> plot_timestep_advice(e, {"a": 1e-3 * e}).get_yscale()
    'log'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.5), layout="tight")
    for (name, values), style in zip(timesteps.items(), ("-", "--", ":", "-."), strict=False):
        ax.plot(targets, values, style, label=name)
    if default_timestep is not None:
        ax.axhline(
            default_timestep, color="0.4", ls=":", label=f"default timestep {default_timestep:g} s"
        )
    ax.set_yscale("log")
    ax.set_xlabel("target restitution $e$ [-]")
    ax.set_ylabel(ylabel)
    legend_outside(ax=ax, where=legend, fontsize=8)
    return ax


def plot_at_timestep(
    targets: np.ndarray,
    curves: Mapping[str, Mapping[str, np.ndarray]],
    measured: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    *,
    title: str = "",
    legend: str = "right",
    ax: Axes | None = None,
) -> Axes:
    """Achieved over target restitution at one timestep, one colour per design.

    ``curves[name]``: predicted ``"mean"``, ``"min"``, ``"max"`` over touch phases of the
    ratio achieved/target at ``targets`` (line and band); ``measured[name]``: the
    engine's ``"targets"``, ``"mean"``, ``"min"``, ``"max"`` of that ratio (points with
    bars). A line at 1 marks the target; ``legend`` as in
    :func:`plot_timestep_restitution`.

    >>> e = np.linspace(0.1, 0.9, 5)
    >>> band = {"mean": 1 + 0 * e, "min": 0.99 + 0 * e, "max": 1.01 + 0 * e}
    >>> plot_at_timestep(e, {"design": band}).get_xlabel()
    'target restitution $e$ [-]'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.5), layout="tight")
    _draw_designs(ax, targets, curves, measured, "targets")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xlabel("target restitution $e$ [-]")
    ax.set_ylabel("achieved / target restitution [-]")
    if title:
        ax.set_title(title, fontsize=9)
    legend_outside(ax=ax, where=legend, fontsize=8)
    return ax
