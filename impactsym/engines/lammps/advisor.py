r"""The timestep advisor: the largest timestep at which LAMMPS keeps the restitution.

:func:`timestep_for` compares the restitution of LAMMPS's velocity-Verlet at every touch
phase (:mod:`~impactsym.engines.lammps.phases`, exact ranges) with the continuous value
(:func:`~impactsym.engines.lammps.hooke.predict` with ``timestep=None``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.lammps.common import natural
from impactsym.engines.lammps.hooke import predict
from impactsym.engines.lammps.phases import phase_statistics
from impactsym.engines.lammps.verlet import positive_limit, stability_limit
from impactsym.validation import finish, real_array

__all__ = ["timestep_for"]

#: geometric grid of omega0 * timestep scanned upwards (points per decade, lowest value)
_PER_DECADE = 24
_TAU_LOW = 1e-4
_BISECTIONS = 40


def _error(D, load, tau, e_c, limit):
    """Largest relative deviation of the restitution over phases (``inf`` beyond the model)."""
    ok = tau < np.minimum(stability_limit(D), positive_limit(D))
    err = np.full(D.shape, np.inf)
    if ok.any():
        st = phase_statistics(D[ok], load[ok], tau[ok], limit)
        dev = np.maximum(
            np.abs(st["restitution_max"] / e_c[ok] - 1.0),
            np.abs(st["restitution_min"] / e_c[ok] - 1.0),
        )
        err[ok] = np.where(st["sticks_somewhere"], np.inf, dev)
    return err


def timestep_for(
    *,
    kn: Any,
    damping: Any,
    mass: float,
    speed: Any,
    gravity: Any = 0.0,
    limit_damping: bool,
    tolerance: float = 0.01,
) -> float | np.ndarray:
    r"""Largest timestep at which the restitution at every touch phase is within ``tolerance``.

    The deviation ``max over phases |e(phase) / e_continuous - 1|`` is exact for each
    timestep (the phase ranges of :func:`~impactsym.engines.lammps.phases.phase_statistics`).
    "Largest" is searched as the **first crossing from below**: ``omega0 * timestep`` is
    scanned upwards on a geometric grid (24 points per decade from ``1e-4`` to the
    stability limit ``2 / (D + sqrt(1 + D^2))``, or the over-correction limit where that is
    lower) and the first grid interval in which the deviation exceeds ``tolerance`` is
    bisected (40 halvings). Every grid timestep below the result is within the
    tolerance; a larger timestep beyond the crossing at which the deviation happens to
    dip again is not returned (the deviation is not monotone: the end state jumps).

    Parameters
    ----------
    kn, damping, mass, speed, gravity, limit_damping
        As :func:`~impactsym.engines.lammps.hooke.predict`.
    tolerance
        Relative deviation allowed, in ``(0, 1)``.

    Returns
    -------
    float or numpy.ndarray
        Seconds.

    >>> from impactsym.engines.lammps import hooke_for
    >>> c = hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)
    >>> h = timestep_for(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0, limit_damping=True)
    >>> round(1e-3 / h)  # steps per contact time for 1 % at every phase
    90
    """
    tol, _ = real_array("tolerance", tolerance, lower=0.0, strict=True)
    if np.ndim(tolerance) != 0 or not tol < 1:
        raise ValueError(f"tolerance must be one number in (0, 1), got {tolerance!r}")
    c = predict(
        kn=kn, damping=damping, mass=mass, speed=speed, gravity=gravity, limit_damping=limit_damping
    )
    scalar = np.ndim(c.restitution) == 0
    e_c = np.atleast_1d(np.asarray(c.restitution, dtype=float)).ravel()
    if np.any(e_c <= 0):
        raise ValueError(
            "the continuous contact sticks (restitution 0): no relative tolerance in the "
            "restitution applies; lower gravity or the damping"
        )
    k = np.broadcast_to(np.asarray(kn, float), np.shape(c.restitution)).ravel()
    eta = np.broadcast_to(np.asarray(damping, float), k.shape).ravel()
    v = np.broadcast_to(np.asarray(speed, float), k.shape).ravel()
    g = np.broadcast_to(np.asarray(gravity, float), k.shape).ravel()
    omega, _, D = natural(k, eta, float(mass))
    load = g / (omega * v)
    top = np.minimum(stability_limit(D), positive_limit(D))
    count = int(np.ceil(_PER_DECADE * np.log10(top.max() / _TAU_LOW))) + 1
    grid = _TAU_LOW * 10.0 ** (np.arange(count) / _PER_DECADE)
    G = np.broadcast_to(grid, (k.size, count))
    err = _error(
        np.repeat(D, count),
        np.repeat(load, count),
        G.ravel(),
        np.repeat(e_c, count),
        limit_damping,
    ).reshape(G.shape)
    over = err > tol
    first = np.argmax(over, axis=1)
    if np.any(over[:, 0]):
        raise ValueError(
            f"the restitution deviates by more than tolerance = {tolerance!r} already at "
            f"omega0 * timestep = {_TAU_LOW:g}"
        )
    none = ~np.any(over, axis=1)
    lo = np.where(none, grid[-1], grid[np.maximum(first - 1, 0)])
    hi = np.where(none, grid[-1], grid[first])
    for _ in range(_BISECTIONS):
        mid = np.sqrt(lo * hi)
        bad = _error(D, load, mid, e_c, limit_damping) > tol
        lo, hi = np.where(bad, lo, mid), np.where(bad, mid, hi)
    return finish((lo / omega).reshape(np.shape(c.restitution)), scalar)
