"""Figures of the multibody penalty-contact analysis (paper section 3).

The functions draw what :mod:`impactsym.multibody` computed (agreement sweeps,
convergence studies, stick boundaries and iso-restitution curves of a design); each
takes an optional Matplotlib ``ax`` and returns it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from impactsym.plotting.style import legend_outside
from impactsym.validation import check_condition

_MARKERS = {
    "impulse": ("o", "C0", "impulse projection $M^{-1} n_0$"),
    "normal": ("x", "C3", "paper projection $n_0/(n_0^T n_0)$"),
}


def _style(marker: str, color: str) -> dict[str, Any]:
    """Open circles or crosses in ``color`` (crosses have no edge to colour)."""
    if marker == "o":
        return {"marker": marker, "facecolors": "none", "edgecolors": color}
    return {"marker": marker, "color": color}


def _plain_log_ticks(axis: Any) -> None:
    """Label a log axis with plain numbers at 1, 2, 5 x 10^n only."""
    from matplotlib.ticker import LogLocator, NullFormatter, StrMethodFormatter

    axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(StrMethodFormatter("{x:g}"))
    axis.set_minor_formatter(NullFormatter())


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure(figsize=(6.5, 4.5), layout="tight").add_subplot()


def plot_agreement(agreement: Any, *, condition: str, ax: Any = None) -> Any:
    """Relative contact-time error of the reduced model against the full simulation.

    One point per sweep case that releases in both models, over the reduced damping
    ratio ``D``, for both projections; the legend gives the share of correct
    stick/release verdicts, and cases with a wrong verdict are drawn on the top line.
    """
    check_condition(condition)
    ax = _axes(ax)
    full = agreement.t_full[condition]
    top = 1.0
    for projection, (marker, color, label) in _MARKERS.items():
        red = agreement.t_reduced[(projection, condition)]
        D = agreement.D[projection]
        wrong = np.isfinite(full) != np.isfinite(red)
        both = np.isfinite(full) & np.isfinite(red)
        err = np.abs(red[both] / full[both] - 1)
        ax.scatter(
            D[both],
            np.maximum(err, 1e-7),
            s=20,
            linewidths=1,
            **_style(marker, color),
            label=f"{label}: verdict {100 * np.mean(~wrong):.0f} %, "
            f"median {100 * np.median(err):.2g} %",
        )
        if wrong.any():
            ax.scatter(D[wrong], np.full(wrong.sum(), top), s=50, **_style(marker, color))
    ax.axhline(top, color="0.7", lw=0.8, ls="--")
    ax.text(
        0.02,
        top,
        "wrong verdict",
        transform=ax.get_yaxis_transform(),
        va="bottom",
        fontsize="small",
        color="0.4",
    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.xaxis)
    ax.set_ylim(1e-6, 3 * top)
    ax.set_xlabel("$D$ of the reduced oscillator [-]")
    ax.set_ylabel(r"$|t_c^{\mathrm{reduced}} / t_c^{\mathrm{full}} - 1|$ [-]")
    ax.set_title(f"{agreement.example}: {condition} condition")
    legend_outside(ax=ax, where="below", fontsize="x-small")
    return ax


def plot_verdict_map(
    agreement: Any,
    *,
    condition: str,
    projection: str = "impulse",
    boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ax: Any = None,
) -> Any:
    """Sweep points in the ``(f, D)`` plane of the reduced model, marked by the verdict
    of the full simulation, over the section-2 stick boundary ``boundary = (D*, f)``
    (:func:`impactsym.contact.stick_boundary` of ``condition``) if given."""
    check_condition(condition)
    ax = _axes(ax)
    D, f = agreement.D[projection], agreement.f[projection]
    stick_full = ~np.isfinite(agreement.t_full[condition])
    stick_red = ~np.isfinite(agreement.t_reduced[(projection, condition)])
    ax.scatter(
        f[~stick_full],
        D[~stick_full],
        s=18,
        facecolors="none",
        edgecolors="C0",
        label="full model releases",
    )
    ax.scatter(f[stick_full], D[stick_full], s=18, color="C1", label="full model sticks")
    wrong = stick_full != stick_red
    if wrong.any():
        ax.scatter(
            f[wrong],
            D[wrong],
            s=60,
            marker="x",
            color="C3",
            label=f"reduced verdict wrong ({wrong.sum()})",
        )
    if boundary is not None:
        d_star, f_line = boundary
        ax.plot(f_line, d_star, color="k", lw=1.2, label=r"section 2: $D^*(f)$")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(0.8 * D.min(), 1.25 * D.max())
    ax.set_xlabel("$f$ of the reduced oscillator [-]")
    ax.set_ylabel("$D$ of the reduced oscillator [-]")
    ax.set_title(f"{agreement.example}: {condition} condition, {projection} projection")
    legend_outside(ax=ax, fontsize="small")
    return ax


def plot_convergence(
    omegas: Sequence[float],
    errors: Mapping[str, Sequence[float]],
    *,
    ax: Any = None,
    title: str = "",
) -> Any:
    """Relative contact-time error of the reduced model against ``omega0``, per projection."""
    ax = _axes(ax)
    w = np.asarray(omegas, dtype=float)
    for projection, err in errors.items():
        marker, color, label = _MARKERS.get(projection, ("s", "C2", projection))
        ax.loglog(w, np.abs(np.asarray(err, dtype=float)), marker=marker, color=color, label=label)
    ref = np.abs(np.asarray(next(iter(errors.values())), dtype=float))[0]
    for order, style in ((1, ":"), (2, "--")):
        ax.loglog(
            w,
            ref * (w[0] / w) ** order,
            color="0.6",
            ls=style,
            lw=0.8,
            label=rf"$\propto \omega_0^{{-{order}}}$",
        )
    ax.set_xlabel(r"$\sqrt{k / \tilde m}$ [1/s]")
    ax.set_ylabel("relative contact-time error [-]")
    ax.set_title(title)
    legend_outside(ax=ax, where="below", fontsize="small", ncols=2)
    return ax


def plot_design_region(
    k: Any,
    boundaries: Mapping[str, Any],
    *,
    ax: Any = None,
    restitution_curves: Mapping[float, Any] | None = None,
    restitution_condition: str,
    design: tuple[float, float] | None = None,
    units: tuple[str, str] = ("N/m", "N s/m"),
) -> Any:
    """Admissible penalty parameters of a reduced contact over the stiffnesses ``k``.

    Draws the stick boundaries ``{condition: d*(k)}``
    (:func:`impactsym.multibody.design.stick_damping`; release below, stick above), the
    iso-restitution curves ``{e: d(k)}`` under ``restitution_condition``
    (:func:`impactsym.multibody.design.damping_for_restitution`) and a design point.
    The axes are labelled in ``units`` of ``(k, d)``: SI by default, the units of a model
    written in metres, kilograms and seconds.
    """
    check_condition(restitution_condition)
    if len(units) != 2 or not all(isinstance(unit, str) for unit in units):
        raise TypeError(f"units must be two strings (k, d), got {units!r}")
    ax = _axes(ax)
    k = np.asarray(k, dtype=float)
    for style, (condition, d_star) in zip(("-", "--"), boundaries.items(), strict=False):
        check_condition(condition)
        d_star = np.asarray(d_star, dtype=float)
        ax.plot(k, d_star, color="k", ls=style, label=f"stick boundary ({condition})")
    for i, (e, d_e) in enumerate((restitution_curves or {}).items()):
        ax.plot(k, d_e, color=f"C{i}", lw=0.9, label=f"$e = {e:g}$ ({restitution_condition})")
    if design is not None:
        ax.plot(*design, marker="*", ms=12, color="C3", ls="none", label="design")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"penalty stiffness $k$ [{units[0]}]")
    ax.set_ylabel(f"penalty damping $d$ [{units[1]}]")
    ax.text(0.03, 0.95, "stick above", transform=ax.transAxes, ha="left", va="top")
    ax.text(0.03, 0.05, "release below", transform=ax.transAxes, ha="left", va="bottom")
    legend_outside(ax=ax, fontsize="small")
    return ax
