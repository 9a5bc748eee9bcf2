"""Figures of the bounce sequence until rest (spring-damper contact, paper section 2).

The functions draw :class:`~impactsym.contact.bounce.BounceSequence` and
:class:`~impactsym.contact.bounce.BounceMap` results computed by the caller; each takes
an optional Matplotlib axes and returns it (or the pair of axes), so figures compose in
notebooks and papers. Map cells are rasterized in vector output, so PDFs stay small.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap, LogNorm

from impactsym.plotting.contact import COLORS, LABELS
from impactsym.plotting.style import legend_outside
from impactsym.validation import check_condition, renamed

QUANTITIES = {
    "n_contacts": "number of contacts $N$ (sticking one included) [-]",
    "time_to_rest": r"time to rest $\omega_0 t_\mathrm{rest}$ [-]",
}


def plot_bounce_sequence(
    seq: Any,
    *,
    ax: Axes | None = None,
    t_max: float | None = None,
    n_points: int = 2000,
    tau_max: float | None = None,
) -> Axes:
    r"""Body penetration and element deflection over time, contacts shaded.

    Normalized on the first impact: :math:`z = x\omega_0/v_0` over :math:`\tau = \omega_0 t`.
    The plot runs to the normalized time ``t_max`` (default: a little beyond the start
    of the sticking contact, or beyond the last contact computed); ``tau_max`` is a
    former name of ``t_max``.

    >>> from impactsym.contact.bounce import bounce_sequence
    >>> ax = plot_bounce_sequence(bounce_sequence(0.1, 0.2, condition="force"))
    >>> ax.get_xlabel()
    'time $\\tau = \\omega_0 t$ [-]'
    """
    if ax is None:
        ax = plt.figure(figsize=(8.5, 3.5), layout="tight").add_subplot()
    horizon = _horizon([seq], renamed("t_max", t_max, "tau_max", tau_max, None))
    t = np.linspace(0.0, horizon, n_points)
    t = np.union1d(t, np.concatenate([seq.start, seq.end[np.isfinite(seq.end)]]))
    t = t[t <= horizon]
    z, element = seq.trajectory(t)
    color = COLORS[seq.condition]
    ax.plot(t, z, color=color, lw=1.4, label="body penetration $z$")
    if seq.condition == "force":
        ax.plot(t, element, color="k", lw=0.9, ls="--", label="element deflection $z_e$")
    for start, end in zip(seq.start, np.minimum(seq.end, horizon), strict=True):
        ax.axvspan(start, end, color=color, alpha=0.12, lw=0)
    ax.axhline(0.0, color="0.5", lw=0.6)
    state = f"rests at $\\tau$ = {seq.time_to_rest:.4g}" if seq.sticks else "not at rest (computed)"
    ax.set_title(
        f"{LABELS[seq.condition]}: $D$ = {seq.D:g}, $f$ = {seq.f:g}, "
        f"{seq.n_contacts} contact{'s' if seq.n_contacts != 1 else ''}, {state}",
        fontsize=10,
    )
    ax.set_xlabel(r"time $\tau = \omega_0 t$ [-]")
    ax.set_ylabel(r"$z = x\,\omega_0/v_0$ [-]")
    ax.set_xlim(0.0, horizon)
    legend_outside(ax=ax, fontsize=8)
    return ax


def _horizon(sequences: Sequence[Any], t_max: float | None) -> float:
    """``t_max``, or a little beyond the last contact start of ``sequences``."""
    if t_max is not None:
        return t_max
    last = max(s.start[-1] for s in sequences)
    return last + max(0.15 * last, 4.0 * np.pi)


def plot_bounce_sequences(
    sequences: Sequence[Any], *, axes: Sequence[Axes] | None = None
) -> Sequence[Axes]:
    """Sequences side by side (one axes each), on a common time axis.

    >>> from impactsym.contact.bounce import bounce_sequence
    >>> pair = [bounce_sequence(0.1, 0.2, condition=c) for c in ("position", "force")]
    >>> left, right = plot_bounce_sequences(pair)
    >>> left.get_title().split(":")[0], right.get_title().split(":")[0]
    ('position condition', 'force condition')
    """
    if axes is None:
        fig = plt.figure(figsize=(7.5 * len(sequences), 3.8), layout="tight")
        axes = fig.subplots(1, len(sequences), sharey=True, squeeze=False)[0]
    t_max = _horizon(sequences, None)
    for ax, seq in zip(axes, sequences, strict=True):
        plot_bounce_sequence(seq, ax=ax, t_max=t_max)
    return axes


def plot_bounce_map(
    result: Any,
    *,
    quantity: str = "n_contacts",
    boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Number of contacts or time to rest over a D-f grid (``result`` of
    :func:`~impactsym.contact.bounce.bounce_map` on 2-D meshgrid arrays).

    Grey: not at rest within the contacts computed (tiny ``D f``) or never pushed back
    (``f = 0``, ``D = 0``); black line, if ``boundary = (D*, f)`` is given: the stick
    boundary of the first contact (:func:`~impactsym.contact.stick_boundary`; beyond it
    the body sticks at once, one contact; white in the time-to-rest map). A geometric
    grid in ``f`` is shown on a log axis. The cells are rasterized in vector output.

    >>> from impactsym.contact import stick_boundary
    >>> from impactsym.contact.bounce import bounce_map
    >>> D, f = np.meshgrid(np.linspace(0.05, 1.5, 6), np.linspace(0.05, 1, 5))
    >>> line = np.geomspace(1e-4, 1.0, 50)
    >>> result = bounce_map(D, f, condition="force")
    >>> boundary = stick_boundary(line, condition="force"), line
    >>> plot_bounce_map(result, boundary=boundary).get_title()
    'Number of contacts until rest, force condition'
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {sorted(QUANTITIES)}, got {quantity!r}")
    if np.ndim(result.D) != 2:
        raise ValueError(f"result must be a bounce_map over 2-D grids, got shape {result.D.shape}")
    condition = result.condition
    if condition != "clipped":
        condition = check_condition(condition)
    if ax is None:
        ax = plt.figure(figsize=(6, 5), layout="tight").add_subplot()
    values = np.asarray(getattr(result, quantity), dtype=float)
    rests = result.sticks
    positive = values[rests & (values > 0)]
    norm = None
    if positive.size and positive.max() > positive.min():
        norm = LogNorm(vmin=positive.min(), vmax=positive.max())
    shown = np.ma.masked_where(~rests | (values <= 0), values)
    mesh = ax.pcolormesh(
        result.D, result.f, shown, shading="auto", cmap="viridis", norm=norm, rasterized=True
    )
    if quantity == "time_to_rest":  # zero where the first contact sticks: a colour of its own
        at_once = np.ma.masked_where(~(rests & (values == 0)), np.ones_like(values))
        ax.pcolormesh(
            result.D,
            result.f,
            at_once,
            shading="auto",
            cmap=ListedColormap(["w"]),
            rasterized=True,
        )
    grey = np.ma.masked_where(rests, np.ones_like(values))
    ax.pcolormesh(
        result.D, result.f, grey, shading="auto", cmap=ListedColormap(["0.8"]), rasterized=True
    )
    if boundary is not None:
        d_star, f_line = boundary
        ax.plot(d_star, f_line, color="k", lw=1.2, label="first contact sticks (right)")
    ax.set_xlim(result.D.min(), result.D.max())
    ax.set_ylim(result.f.min(), result.f.max())
    if result.f.min() > 0 and result.f.max() > 100 * result.f.min():
        ax.set_yscale("log")  # a geometric grid in f: show it as one
    ax.figure.colorbar(mesh, ax=ax, label=QUANTITIES[quantity])
    ax.set_xlabel("damping ratio $D$ [-]")
    ax.set_ylabel("pressing force $f$ [-]")
    legend_outside(
        ax=ax,
        where="below",
        handles=ax.get_lines(),
        fontsize=8,
        title="grey: not at rest",
        title_fontsize=8,
    )
    title = "Number of contacts until rest" if quantity == "n_contacts" else "Time to rest"
    ax.set_title(f"{title}, {LABELS.get(condition, 'clipped condition')}")
    return ax
