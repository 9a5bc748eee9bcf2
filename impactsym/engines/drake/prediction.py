r"""What Drake's point contact does to one impact: :func:`predict`.

Drake's point contact pushes with :math:`f_n = k x (1 + d x')_+` (``docs/physics.md``,
"Drake point contact"): ``k`` the combined ``point_contact_stiffness`` (N/m, two
geometries in series, :func:`~impactsym.engines.drake.pair.combine`), ``d`` the combined
``hunt_crossley_dissipation`` (s/m).

* ``time_step = 0`` (a continuous plant): the Hunt–Crossley law with exponent 1 and the
  pressing force ``m g`` of :func:`impactsym.contact.nonlinear.impact` (the order-8
  integration), or without gravity up to ``d v = 3`` its phase-plane quadrature
  (:mod:`impactsym.engines.drake.continuous`: Lambert W, a closed-form deepest point and
  a spectrally accurate contact time, the same numbers to ``1e-13``, much faster).
  Drake ends the contact where the overlap is gone; the force stays compressive to
  there (the rebound stays below ``1/d``), so the position condition is the engine's.
* ``time_step > 0``: the exact discrete update of :mod:`impactsym.engines.drake.update`
  at the touch phase ``phase`` (:mod:`impactsym.engines.drake.stepping`), or with
  ``phase=None`` the mean over the phase and the bounds over every phase
  (:mod:`impactsym.engines.drake.phases`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.nonlinear import impact
from impactsym.engines.drake.continuous import S_MAX, hunt_crossley_free
from impactsym.engines.drake.phases import PhaseSummary, phase_summary
from impactsym.engines.drake.stepping import step_contact
from impactsym.engines.drake.update import APPROXIMATIONS, DEFAULT_RELAXATION_TIME
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, finish, real_array

__all__ = [
    "DEFAULT_APPROXIMATION",
    "Prediction",
    "check_approximation",
    "predict",
    "read_prediction",
    "summary_prediction",
]

#: Drake 1.51's ``MultibodyPlantConfig.discrete_contact_approximation`` default.
DEFAULT_APPROXIMATION = "lagged"


@dataclass(frozen=True, eq=False)
class Prediction(ArrayRecord):
    """One impact on Drake's point contact (floats for scalar input, else arrays; SI).

    Attributes
    ----------
    time_step, approximation
        The plant's step (0: continuous) and discrete approximation (``None`` when
        continuous).
    phase
        The touch phase, or ``None``: then the numbers are means over the phase.
    restitution, contact_time
        Separation speed over approach speed, and touch to the end of contact
        (``inf`` and ``0`` where the body sticks); phase means where ``phase`` is None.
    sticks
        Where the body never leaves (at some phase, for the phase mean).
    max_penetration
        Largest overlap (over every phase for the phase mean); for a contact that creeps
        up to rest under gravity, its limit ``m g / k``.
    restitution_range, contact_time_range
        ``(low, high)`` over every touch phase (the value twice where it is exact).
    stick_fraction
        Fraction of the touch phases at which the body sticks.
    """

    time_step: float
    approximation: str | None
    phase: Any
    restitution: Any
    contact_time: Any
    sticks: Any
    max_penetration: Any
    restitution_range: tuple[Any, Any]
    contact_time_range: tuple[Any, Any]
    stick_fraction: Any


def check_approximation(approximation: object, time_step: float) -> str | None:
    """The discrete approximation in use: ``None`` for a continuous plant, Drake's
    default ``"lagged"`` for ``None``, else one of :data:`APPROXIMATIONS` (or raise)."""
    if approximation is not None and approximation not in APPROXIMATIONS:
        raise ValueError(
            f"approximation must be one of {', '.join(map(repr, APPROXIMATIONS))} or None "
            f"(Drake's default {DEFAULT_APPROXIMATION!r}), got {approximation!r}"
        )
    if time_step == 0.0:
        return None
    return DEFAULT_APPROXIMATION if approximation is None else approximation


def check_time_step(time_step: object) -> float:
    """``time_step`` as a float ``>= 0`` (one plant, one step), or raise naming it."""
    if isinstance(time_step, (bool, str, bytes)) or np.ndim(time_step) != 0:
        raise TypeError(f"time_step must be one real number >= 0, got {time_step!r}")
    value = float(time_step)
    if not np.isfinite(value) or value < 0.0:
        raise ValueError(f"time_step must be finite and >= 0 (0: continuous), got {time_step!r}")
    return value


def predict(
    *,
    stiffness: Any,
    dissipation: Any,
    mass: Any,
    speed: Any,
    gravity: Any = 0.0,
    time_step: float = 0.0,
    approximation: str | None = None,
    phase: Any = None,
    relaxation_time: Any = None,
) -> Prediction:
    r"""Restitution, contact time, stick verdict and penetration of Drake's point contact.

    A body of mass ``mass`` hits at ``speed`` under the pressing acceleration ``gravity``
    a contact with :math:`f_n = k x (1 + d x')_+` (module docstring).

    Parameters
    ----------
    stiffness, dissipation : float or array_like
        Combined ``point_contact_stiffness`` ``k > 0`` (N/m) and
        ``hunt_crossley_dissipation`` ``d >= 0`` (s/m) of the pair
        (:func:`~impactsym.engines.drake.pair.combine` from two geometries).
    mass, speed, gravity : float or array_like
        ``m > 0`` (kg), approach speed at touch ``v > 0`` (m/s), pressing acceleration
        ``g >= 0`` (m/s^2). All arrays broadcast.
    time_step : float
        The plant's ``time_step`` (s); 0 for a continuous plant.
    approximation : {"lagged", "similar", "tamsi", "sap"} or None
        ``discrete_contact_approximation``; ``None`` is Drake's default ``"lagged"``.
        The first three give the same update for one frictionless contact; ``"sap"``
        ignores ``dissipation`` and damps with ``relaxation_time``.
    phase : float or array_like or None
        Touch phase in ``[0, 1)`` (:mod:`impactsym.engines.drake.stepping`); ``None``: the
        mean over the phase, with the range over every phase.
    relaxation_time : float or array_like or None
        Combined ``relaxation_time`` of the pair (s, ``"sap"`` only: the sum of the two
        geometries'); ``None`` is Drake's default, 0.1 s on each geometry: 0.2 s.

    Returns
    -------
    Prediction

    Examples
    --------
    Continuous: the exact Hunt–Crossley restitution at ``d v = 1``,

    >>> round(predict(stiffness=1e4, dissipation=1.0, mass=1.0, speed=1.0).restitution, 5)
    0.59362

    and at Drake's default ``time_step = 1e-3`` (``"lagged"``), the phase mean and range:

    >>> p = predict(stiffness=1e4, dissipation=0.5, mass=1.0, speed=1.0, time_step=1e-3)
    >>> round(p.restitution, 4), tuple(round(float(e), 4) for e in p.restitution_range)
    (0.6582, (0.6549, 0.6624))
    """
    h = check_time_step(time_step)
    approx = check_approximation(approximation, h)
    tau_in = DEFAULT_RELAXATION_TIME if relaxation_time is None else relaxation_time
    values = {
        name: real_array(name, value, lower=0.0, strict=strict)
        for name, value, strict in (
            ("stiffness", stiffness, True),
            ("dissipation", dissipation, False),
            ("mass", mass, True),
            ("speed", speed, True),
            ("gravity", gravity, False),
            ("relaxation_time", tau_in, False),
        )
    }
    if phase is not None:
        values["phase"] = real_array("phase", phase, lower=0.0, strict=False)
        if (values["phase"][0] >= 1.0).any():
            raise ValueError(f"phase must lie in [0, 1), got {phase!r}")
    scalar = all(flag for _, flag in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    flat = {name: np.broadcast_to(a, shape).ravel() for name, (a, _) in values.items()}
    k, d, m, v, g, tau = (flat[n] for n in ("stiffness", "dissipation", "mass", "speed",
                                            "gravity", "relaxation_time"))  # fmt: skip
    if approx is None:
        e, t_c, pen = _continuous(k, d, m, v, g)
        stuck = np.isinf(t_c)
        fields = (e, t_c, stuck, pen, e, e, t_c, t_c, stuck)
    elif phase is not None:
        r = step_contact(k, d, tau, m, g, v, h, flat["phase"], approximation=approx)
        fields = (r.restitution, r.contact_time, r.sticks, r.max_penetration, r.restitution,
                  r.restitution, r.contact_time, r.contact_time, r.sticks)  # fmt: skip
    else:
        fields = _summary_fields(phase_summary(k, d, tau, m, g, v, h, approximation=approx))
    return _prediction(fields, h, approx, flat.get("phase"), shape, scalar)


def summary_prediction(
    summaries: np.ndarray, k: np.ndarray, d: np.ndarray, m: np.ndarray, v: np.ndarray,
    g: np.ndarray, h: float, approx: str, shape: tuple[int, ...], scalar: bool,
) -> Prediction:  # fmt: skip
    """The phase-mean prediction at a step of the designs ``(k, d)`` (flat, with
    ``m, v, g``; ``"tamsi"``/``"similar"``/``"lagged"``): ``summaries`` (the fields of
    :class:`~impactsym.engines.drake.phases.PhaseSummary` stacked, ``(8, size)``) where
    their restitution is finite, :func:`~impactsym.engines.drake.phases.phase_summary`
    elsewhere; in ``shape`` (floats where ``scalar``)."""
    fields = summaries.copy()
    rest = np.flatnonzero(~np.isfinite(fields[0]))
    if rest.size:
        r = phase_summary(*(a[rest] for a in (k, d)), 0.0, *(a[rest] for a in (m, g, v)), h,
                          approximation=approx)  # fmt: skip
        fields[:, rest] = r.stacked()
    return _prediction(_summary_fields(PhaseSummary(*fields)), h, approx, None, shape, scalar)


def _summary_fields(r):
    """The prediction's fields (in :func:`_prediction`'s order) of a phase summary."""
    return (r.restitution, r.contact_time, r.stick_fraction > 0, r.max_penetration,
            r.restitution_min, r.restitution_max, r.contact_time_min, r.contact_time_max,
            r.stick_fraction)  # fmt: skip


def _prediction(fields, h, approx, phase, shape, scalar):
    """The :class:`Prediction` of ``fields`` (restitution, contact time, sticks, overlap,
    the restitution's and the contact time's bounds, stick fraction) and ``phase`` (or
    ``None``), flat arrays put in ``shape`` (floats and bools where ``scalar``)."""

    def out(a):
        return finish(np.asarray(a, dtype=float).reshape(shape), scalar)

    def flag(a):
        a = np.asarray(a, bool).reshape(shape)
        return bool(a) if scalar else a

    e, t_c, stuck, pen, e_lo, e_hi, t_lo, t_hi, frac = fields
    return Prediction(
        time_step=h,
        approximation=approx,
        phase=None if phase is None else out(phase),
        restitution=out(e),
        contact_time=out(t_c),
        sticks=flag(stuck),
        max_penetration=out(pen),
        restitution_range=(out(e_lo), out(e_hi)),
        contact_time_range=(out(t_lo), out(t_hi)),
        stick_fraction=out(frac),
    )


def read_prediction(
    shape: tuple[int, ...], read: np.ndarray, values: Any, k: np.ndarray, d: np.ndarray,
    m: np.ndarray, v: np.ndarray, g: np.ndarray,
) -> Prediction:  # fmt: skip
    """The continuous prediction of the designs ``(k, d)`` (flat, with ``m, v, g``):
    ``values`` (restitution, contact time, deepest overlap of the ``read`` rows) read off
    a table where ``read``, :func:`predict` elsewhere; in ``shape``."""
    e, t_c, pen = (np.empty(read.size) for _ in range(3))
    e[read], t_c[read], pen[read] = values
    rest = np.flatnonzero(~read)
    if rest.size:
        e[rest], t_c[rest], pen[rest] = _continuous(*(a[rest] for a in (k, d, m, v, g)))
    stuck = np.isinf(t_c)
    e, t_c, pen = (a.reshape(shape) for a in (e, t_c, pen))
    return Prediction(time_step=0.0, approximation=None, phase=None, restitution=e,
                      contact_time=t_c, sticks=stuck.reshape(shape), max_penetration=pen,
                      restitution_range=(e, e), contact_time_range=(t_c, t_c),
                      stick_fraction=stuck.astype(float).reshape(shape))  # fmt: skip


def _continuous(k, d, m, v, g):
    """Restitution, contact time and deepest overlap of the continuous law (flat arrays):
    the phase-plane quadrature of :mod:`impactsym.engines.drake.continuous` without
    gravity up to ``d v = 3``, the order-8 integration of ``impact`` elsewhere."""
    e, t_c, pen = np.empty_like(k), np.empty_like(k), np.empty_like(k)
    free = (g == 0.0) & (d * v <= S_MAX)
    if free.any():
        scale = np.sqrt(m[free] / k[free])  # T
        e[free], tau, z_max = hunt_crossley_free(d[free] * v[free])
        t_c[free], pen[free] = tau * scale, z_max * v[free] * scale
    rest = ~free
    if rest.any():
        r = impact("hunt-crossley", stiffness=k[rest], damping=d[rest], mass=m[rest],
                   speed=v[rest], force=m[rest] * g[rest], exponent=1.0,
                   condition="position")  # fmt: skip
        e[rest], t_c[rest], pen[rest] = r.restitution, r.contact_time, r.max_penetration
    return e, t_c, pen
