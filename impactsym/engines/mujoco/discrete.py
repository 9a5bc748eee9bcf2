r"""MuJoCo's contact at the user's timestep: dispatch per integrator, and the phase statistics.

:func:`step_contact` gives the contact at a touch phase as the engine's states show it
(:class:`~impactsym.engines.mujoco.stepping.StepContact`) for ``integrator`` ``"euler"``
or ``"implicitfast"`` (the same map without joint damping:
:func:`~impactsym.engines.mujoco.euler.euler_contact`). :func:`phase_summary` averages
over the touch phase, uniform in ``[0, 1)``, and bounds the result over all phases.

The restitution and contact time are piecewise smooth in the phase, with jumps where the
end step changes (`docs/physics.md#touch-phase`). The summary evaluates the contact on a
grid of phases, locates every change of the end step (or of the stick verdict) between
grid points by bisection in the phase to ``1e-12``, and integrates each smooth piece by
Gauss-Legendre (exact for the flat impedance, whose restitution is a quadratic in the
phase on each piece); the range takes the piece ends (the one-sided limits at the jumps),
the nodes and the vertex of the quadratic through each piece.

All quantities are SI: seconds, metres, m/s, m/s^2.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.mujoco.euler import euler_contact
from impactsym.engines.mujoco.model import Coefficients
from impactsym.engines.mujoco.stepping import StepContact
from impactsym.records import ArrayRecord

__all__ = ["INTEGRATORS", "PhaseSummary", "phase_summary", "step_contact"]


def _rk4_missing(*args: Any) -> StepContact:
    raise NotImplementedError("integrator 'rk4' is not available in this build")


#: the discrete contact model of each MuJoCo integrator (same signature)
INTEGRATORS = {"euler": euler_contact, "implicitfast": euler_contact, "rk4": _rk4_missing}

_GRID = 8  # phase intervals searched for jumps of the end step
_BISECT = 42  # bisection steps per jump (2^-42 < 1e-12 of a phase)
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(5)


def check_integrator(integrator: object) -> str:
    """``integrator`` as a key of :data:`INTEGRATORS`, or raise naming it. Internal."""
    if not isinstance(integrator, str) or integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {sorted(INTEGRATORS)}, got {integrator!r}")
    return integrator


def step_contact(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
    *,
    integrator: str,
) -> StepContact:
    """The contact at touch phase ``phase`` under MuJoCo's ``integrator`` (arrays, SI).

    Arguments as in :func:`~impactsym.engines.mujoco.euler.euler_contact` (``coeffs``
    with refsafe applied).
    """
    model = INTEGRATORS[check_integrator(integrator)]
    return model(coeffs, solimp, rho, gravity, speed, timestep, phase)


@dataclass(frozen=True, eq=False)
class PhaseSummary(ArrayRecord):
    """The contact over the touch phase (uniform in ``[0, 1)``), arrays, SI.

    Attributes
    ----------
    restitution, contact_time
        Means over the phase (``contact_time`` is ``inf`` where some phases stick).
    restitution_min, restitution_max, contact_time_min, contact_time_max
        Bounds that hold at every phase.
    stick_fraction
        Fraction of the phases at which the body sticks.
    """

    restitution: np.ndarray
    contact_time: np.ndarray
    restitution_min: np.ndarray
    restitution_max: np.ndarray
    contact_time_min: np.ndarray
    contact_time_max: np.ndarray
    stick_fraction: np.ndarray


def phase_summary(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    *,
    integrator: str,
) -> PhaseSummary:
    """Mean over the touch phase and bounds over every phase (module docstring).

    Arguments as in :func:`step_contact`, without ``phase``.
    """
    model = INTEGRATORS[check_integrator(integrator)]
    arrays = np.broadcast_arrays(
        *(
            np.asarray(a, float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep)
        )
    )
    shape = arrays[0].shape
    b, k, rho, g, v, dt = (a.ravel() for a in arrays)
    size = b.size

    def run(i, p):
        """The contact of elements ``i`` at phases ``p`` (same shape)."""
        c = Coefficients(b[i], k[i])
        return model(c, solimp, rho[i], g[i], v[i], dt[i], p)

    grid = np.linspace(0.0, 1.0, _GRID + 1)
    grid[0] = 1e-300  # the limit phase -> 0+ (phase 0 itself is checked on its own)
    i_all = np.repeat(np.arange(size), _GRID + 1)
    p_all = np.tile(grid, size)
    at = run(i_all, p_all)
    key = np.where(at.sticks, -1, at.steps).reshape(size, _GRID + 1)
    # bisection for the jump inside each grid interval whose ends differ
    lo = np.tile(grid[:-1], (size, 1))
    hi = np.tile(grid[1:], (size, 1))
    lo[:, 0] = 1e-300
    jump = key[:, :-1] != key[:, 1:]
    ii, kk = np.nonzero(jump)
    a, c = lo[ii, kk].copy(), hi[ii, kk].copy()
    left_key = key[ii, kk]
    for _ in range(_BISECT):
        if ii.size == 0:
            break
        mid = 0.5 * (a + c)
        m = run(ii, mid)
        same = np.where(m.sticks, -1, m.steps) == left_key
        a, c = np.where(same, mid, a), np.where(same, c, mid)
    # pieces: [lo, a], [c, hi] for jumping intervals, [lo, hi] otherwise
    starts = [lo.ravel()]
    ends = [np.where(jump, np.nan, hi).ravel()]
    owner = [np.repeat(np.arange(size), _GRID)]
    ends[0][np.ravel_multi_index((ii, kk), jump.shape)] = a
    starts.append(c)
    ends.append(hi[ii, kk])
    owner.append(ii)
    p0, p1, own = np.concatenate(starts), np.concatenate(ends), np.concatenate(owner)
    half, centre = 0.5 * (p1 - p0), 0.5 * (p1 + p0)
    nodes = centre[:, None] + half[:, None] * _NODES[None, :]
    pts = np.concatenate([p0[:, None], nodes, p1[:, None]], axis=1)
    res = run(np.repeat(own, pts.shape[1]), pts.ravel())
    e = res.restitution.reshape(pts.shape)
    t = res.contact_time.reshape(pts.shape)
    stuck = res.sticks.reshape(pts.shape)
    w = half[:, None] * _WEIGHTS[None, :]
    e_mean = np.bincount(own, (w * e[:, 1:-1]).sum(axis=1), minlength=size)
    with np.errstate(invalid="ignore"):
        t_piece = np.where(stuck[:, 1:-1].any(axis=1), np.inf, (w * t[:, 1:-1]).sum(axis=1))
    t_mean = np.zeros(size)
    np.add.at(t_mean, own, t_piece)
    stick_frac = np.bincount(own, (w * stuck[:, 1:-1]).sum(axis=1), minlength=size)
    # the range: piece ends, nodes, and the vertex of the quadratic through each piece
    vertex = _vertex(pts[:, [0, 3, -1]], e[:, [0, 3, -1]], p0, p1)
    e_lo = np.fmin(e.min(axis=1), vertex)
    e_hi = np.fmax(e.max(axis=1), vertex)
    zero = run(np.arange(size), np.zeros(size))  # phase 0 exactly
    e_min = np.minimum(_reduce(np.minimum, own, e_lo, size, np.inf), zero.restitution)
    e_max = np.maximum(_reduce(np.maximum, own, e_hi, size, -np.inf), zero.restitution)
    t_min = np.minimum(_reduce(np.minimum, own, t.min(axis=1), size, np.inf), zero.contact_time)
    t_max = np.maximum(_reduce(np.maximum, own, t.max(axis=1), size, -np.inf), zero.contact_time)
    fields = (e_mean, t_mean, e_min, e_max, t_min, t_max, stick_frac)
    return PhaseSummary(*(np.reshape(f, shape) for f in fields))


def _reduce(op, owner, values, size, start):
    out = np.full(size, start)
    op.at(out, owner, values)
    return out


def _vertex(p, e, lo, hi):
    """Value at the vertex of the quadratic through three points, where inside the piece."""
    (x0, x1, x2), (y0, y1, y2) = p.T, e.T
    with np.errstate(all="ignore"):
        d01, d12 = (y1 - y0) / (x1 - x0), (y2 - y1) / (x2 - x1)
        c2 = (d12 - d01) / (x2 - x0)
        c1 = d01 - c2 * (x0 + x1)
        xv = -c1 / (2.0 * c2)
        yv = y0 + d01 * (xv - x0) + c2 * (xv - x0) * (xv - x1)
    inside = np.isfinite(yv) & (xv > lo) & (xv < hi)
    return np.where(inside, yv, np.nan)
