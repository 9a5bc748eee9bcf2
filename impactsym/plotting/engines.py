"""Figures of the engine bridge: textbook vs exact restitution, MuJoCo's stick map.

Every function takes an optional Matplotlib axes and returns it; engine measurements
are added by the caller (``ax.plot``) so that the figures need no engine.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap

from impactsym.engines import lammps, mujoco

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


def textbook_restitution(targets: np.ndarray) -> dict[str, np.ndarray]:
    """Restitution the engines give when the textbook damping is used for ``targets``.

    Keys: ``"MuJoCo flat solimp"``, ``"MuJoCo default solimp"`` (timeconst 0.02,
    1 m/s, no gravity) and ``"LAMMPS coeff_restitution + limit_damping"``.

    >>> out = textbook_restitution(np.array([0.5]))
    >>> round(float(out["LAMMPS coeff_restitution + limit_damping"][0]), 4)
    0.5503
    """
    targets = np.asarray(targets, dtype=float)
    dampratio = np.asarray(lammps.textbook_damping_ratio(targets))
    out = {}
    for name, solimp in (("flat", FLAT), ("default", mujoco.DEFAULT_SOLIMP)):
        p = mujoco.predict(solref=(mujoco.DEFAULT_TIMECONST, dampratio), solimp=solimp, speed=1.0)
        out[f"MuJoCo {name} solimp"] = np.asarray(p.restitution)
    out["LAMMPS coeff_restitution + limit_damping"] = np.asarray(
        lammps.coeff_restitution_achieved(targets)
    )
    return out


def plot_textbook_error(*, ax: Axes | None = None, n_points: int = 60) -> Axes:
    """Achieved against wanted restitution with the textbook damping (curves).

    The diagonal is what :func:`impactsym.engines.mujoco.solref_for` and
    :func:`impactsym.engines.lammps.hooke_for` achieve.

    >>> plot_textbook_error(n_points=5).get_xlabel()
    'wanted restitution e'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 4.5))
    targets = np.linspace(0.02, 0.98, n_points)
    for (name, achieved), style in zip(
        textbook_restitution(targets).items(), ("-", "--", ":"), strict=True
    ):
        ax.plot(targets, achieved, style, label=f"textbook: {name}")
    ax.plot([0, 1], [0, 1], "k-", lw=0.8, label="impactsym design (all engines)")
    ax.set_xlabel("wanted restitution e")
    ax.set_ylabel("achieved restitution")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8)
    return ax


def stick_map(speed: np.ndarray, dampratio: np.ndarray, gravity: float = 9.81, solimp=FLAT):
    """MuJoCo's verdict on a (speed, dampratio) grid: 0 sticks, 1 force, 2 penetration.

    Returns ``(verdict, restitution)`` arrays of shape ``(len(dampratio), len(speed))``.

    >>> v, e = stick_map(np.array([0.05, 1.0]), np.array([0.2, 1.0]))
    >>> v.tolist()
    [[2, 1], [0, 0]]
    """
    S, R = np.meshgrid(speed, dampratio)
    p = mujoco.predict(
        solref=(mujoco.DEFAULT_TIMECONST, R), solimp=solimp, speed=S, gravity=gravity
    )
    verdict = np.where(p.sticks, 0, np.where(p.released_by_position, 2, 1))
    return verdict, np.asarray(p.restitution)


def plot_stick_map(
    *, ax: Axes | None = None, gravity: float = 9.81, n_points: int = 120, solimp=FLAT
) -> Axes:
    """Where MuJoCo's body sticks under gravity (timeconst 0.02): speed against dampratio.

    >>> plot_stick_map(n_points=8).get_ylabel()
    'dampratio'
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    speed = np.geomspace(0.01, 3.0, n_points)
    dampratio = np.geomspace(0.05, 2.0, n_points)
    verdict, e = stick_map(speed, dampratio, gravity, solimp)
    cmap = ListedColormap(["0.75", "#c6dbef", "#fdd0a2"])
    ax.pcolormesh(speed, dampratio, verdict, cmap=cmap, vmin=-0.5, vmax=2.5, shading="auto")
    lines = ax.contour(speed, dampratio, np.where(verdict > 0, e, np.nan), levels=[0.1, 0.3, 0.5])
    ax.clabel(lines, fmt="e=%.1f", fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("approach speed (m/s)")
    ax.set_ylabel("dampratio")
    ax.set_title(
        f"MuJoCo, g = {gravity:g} m/s$^2$: grey sticks, blue force ends contact, "
        "orange contact lost",
        fontsize=8,
    )
    return ax
