r"""PyBullet's contact averaged over the touch phase: the mean and the range.

Where the branch pattern of :func:`~impactsym.engines.pybullet.stepping.step_pattern`
is constant in the phase ``p``, the end state is a fixed affine map of the free-flight
state ``-1`` (``x = v t + g t^2 / 2``, ``w = v + g t``, ``t = (p - 1) h``): the
restitution is a quadratic in ``p`` and the contact time ``(p + n) h`` linear. The
summary evaluates the pattern on a grid of phases, locates every change between grid
points by bisection to ``1e-12`` of a phase, and integrates each piece by three-point
Gauss-Legendre (exact for a quadratic); the range takes the piece ends (the one-sided
limits at the jumps) and the vertex of each piece's quadratic. Inside a grid interval
(32 per sub-step) the changes are found one after another (the rest of the interval is
searched again while its ends differ); a pattern that changes and changes back inside
one interval would go unseen (tested against dense phase sampling). With PyBullet's
defaults (no processing threshold, no velocity restitution) the summary is
:func:`~impactsym.engines.pybullet.phase_means.root_summary` instead: the changes at the
roots of the branch quantities, in closed form, checked by the pattern either side
(``1e-12`` of a phase off the root: the one-sided limits), a search only where a root
misses a change, and each piece's quadratic integrated exactly from the coefficients
its tracked run carries (no runs at Gauss nodes); the same means to ~1e-13, ranges to
~1e-12, many times faster (2-3 times faster than the same pieces integrated at runs of
the map at Gauss nodes). All arrays, SI.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import PhaseSummary
from impactsym.engines.phase_pieces import integrate_pieces, reduce_at, vertex
from impactsym.engines.pybullet.phase_means import CHUNK, root_summary
from impactsym.engines.pybullet.stepping import DEFAULT_RESTITUTION_THRESHOLD, step_pattern

__all__ = ["phase_summary"]

_GRID = 32  # phase intervals searched for changes of the pattern
_BISECT = 42  # bisection steps per change (2^-42 < 1e-12 of a phase)
#: changes of the pattern found inside one grid interval; the rest is one piece (met
#: where the pattern changes thousands of times over the phase: in the random contacts
#: checked, only contacts that stick at some phases, whose mean contact time is infinite)
_ROUNDS = 6
_NODES = 3  # Gauss-Legendre nodes per piece


def phase_summary(
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any,
    timestep: Any,
    *,
    substeps: int,
    slop: float,
    processing_threshold: float,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
    pattern: Callable[..., tuple[Any, np.ndarray]] | None = None,
) -> PhaseSummary:
    """Mean over the touch phase (uniform in ``[0, 1)``) and bounds over every phase.

    Arguments as in :func:`~impactsym.engines.pybullet.stepping.step_contact`, without
    ``phase`` (validated arrays, broadcast together). ``pattern`` replaces
    :func:`~impactsym.engines.pybullet.stepping.step_pattern` (same arguments and
    result; the rigid contact of :mod:`~impactsym.engines.pybullet.rigid` passes its own).
    Computed in passes of :data:`~impactsym.engines.pybullet.phase_means.CHUNK` elements.
    """
    shape = np.broadcast_shapes(
        *(np.shape(a) for a in (stiffness, damping, mass, speed, gravity, timestep))
    )
    if 0 in shape:  # an empty call: empty fields of its shape
        return PhaseSummary(*(np.empty(shape) for _ in dataclasses.fields(PhaseSummary)))
    closed = pattern is None and np.isinf(processing_threshold) and not velocity_restitution
    if closed:  # the compliant map with PyBullet's defaults: break points in closed form
        return root_summary(
            stiffness, damping, mass, speed, gravity, timestep, substeps=substeps, slop=slop,
            processing_threshold=processing_threshold, restitution_threshold=restitution_threshold,
        )  # fmt: skip
    step = step_pattern if pattern is None else pattern
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep))
    )
    shape = arrays[0].shape
    k, c, m, v, g, dt = (a.ravel() for a in arrays)
    size = k.size
    if size > CHUNK:  # in passes of CHUNK elements: the same numbers, element by element
        options = {
            "substeps": substeps, "slop": slop, "processing_threshold": processing_threshold,
            "velocity_restitution": velocity_restitution,
            "restitution_threshold": restitution_threshold, "pattern": pattern,
        }  # fmt: skip
        parts = [phase_summary(*(a[i : i + CHUNK] for a in (k, c, m, v, g, dt)), **options)
                 for i in range(0, size, CHUNK)]  # fmt: skip
        return PhaseSummary(*(
            np.concatenate([getattr(part, f.name) for part in parts]).reshape(shape)
            for f in dataclasses.fields(PhaseSummary)
        ))  # fmt: skip

    def run(i, p):
        return step(
            k[i],
            c[i],
            m[i],
            v[i],
            g[i],
            dt[i],
            p,
            substeps=substeps,
            slop=slop,
            processing_threshold=processing_threshold,
            velocity_restitution=velocity_restitution,
            restitution_threshold=restitution_threshold,
        )

    p0, p1, own = _bisected_pieces(run, size, substeps)
    pieces = integrate_pieces(lambda i, q: run(i, q)[0], p0, p1, own, size, nodes=_NODES)
    pts, e, t = pieces.pts, pieces.restitution, pieces.contact_time
    e_mean, t_mean, stick_frac = (
        pieces.restitution_mean, pieces.contact_time_mean, pieces.stick_fraction
    )  # fmt: skip
    top = vertex(pts[:, [0, 2, 4]], e[:, [0, 2, 4]], p0, p1)
    e_lo = np.fmin(e.min(axis=1), top)
    e_hi = np.fmax(e.max(axis=1), top)
    fields = (
        e_mean,
        t_mean,
        reduce_at(np.minimum, own, e_lo, size, np.inf),
        reduce_at(np.maximum, own, e_hi, size, -np.inf),
        reduce_at(np.minimum, own, t.min(axis=1), size, np.inf),
        reduce_at(np.maximum, own, t.max(axis=1), size, -np.inf),
        stick_frac,
    )
    return PhaseSummary(*(np.reshape(f, shape) for f in fields))


def _bisected_pieces(run, size, substeps):
    """The pieces of constant pattern by a grid and bisection (any ``pattern``): the
    pattern on ``_GRID`` intervals per sub-step, each change located to ``2^-42``."""
    n_grid = _GRID * min(substeps, 16)  # sub-steps put pattern changes 1/substeps apart
    grid = np.linspace(0.0, 1.0, n_grid + 1)
    grid[-1] = np.nextafter(1.0, 0.0)
    every = np.repeat(np.arange(size), n_grid + 1)
    _, key_grid = run(every, np.tile(grid, size))
    key_grid = key_grid.reshape(size, n_grid + 1)
    lo, hi = np.tile(grid[:-1], size), np.tile(grid[1:], size)
    k_lo, k_hi = key_grid[:, :-1].ravel(), key_grid[:, 1:].ravel()
    own = np.repeat(np.arange(size), n_grid)
    starts, ends, owner = [], [], []
    for _ in range(_ROUNDS):  # split off one constant piece per round where ends differ
        flat = k_lo == k_hi
        starts.append(lo[flat])
        ends.append(hi[flat])
        owner.append(own[flat])
        lo, hi, k_lo, k_hi, own = (a[~flat] for a in (lo, hi, k_lo, k_hi, own))
        if own.size == 0:
            break
        a, b = lo.copy(), hi.copy()
        for _ in range(_BISECT):
            mid = 0.5 * (a + b)
            same = run(own, mid)[1] == k_lo
            a, b = np.where(same, mid, a), np.where(same, b, mid)
        starts.append(lo)
        ends.append(a)
        owner.append(own)
        lo, k_lo = b, run(own, b)[1]  # the rest [b, hi] may hold further changes
    else:
        starts.append(lo)  # left after _ROUNDS: integrated as one piece
        ends.append(hi)
        owner.append(own)
    return np.concatenate(starts), np.concatenate(ends), np.concatenate(owner)
