r"""The timestep advisor: the largest timestep at which MuJoCo keeps the restitution.

:func:`timestep_for` compares the restitution at every touch phase (the range of
:func:`~impactsym.engines.mujoco.prediction.predict` at a timestep, exact over phases)
with the continuous value (``timestep=None``). It replaces the one-parameter rule
``omega0 dt <= 0.03``: the error grows with the damping rate as well (a design for
``e = 0.2`` passed that rule at ``dt = 4.2e-4`` and was off by -3.3 %).
All quantities are SI: seconds, m/s, m/s^2, kilograms.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import check_integrator
from impactsym.engines.mujoco.discrete_design import stable
from impactsym.engines.mujoco.model import (
    DEFAULT_SOLIMP,
    check_mass,
    check_solimp,
    coefficients,
    d_max,
    effective_impedance,
    weight_ratio,
)
from impactsym.engines.mujoco.prediction import predict
from impactsym.records import ArrayRecord
from impactsym.validation import finish, real_array

__all__ = ["TimestepAdvice", "timestep_for"]

#: the scan: points per decade of timestep / contact time, its lowest value, and how far
#: down it extends when the deviation is too large already there
_PER_DECADE = 8
_LOW = 1e-2
_LOWEST = 1e-6
_BISECTIONS = 24


@dataclass(frozen=True, eq=False)
class TimestepAdvice(ArrayRecord):
    """The advisor's answer (floats, or arrays over the ``solref`` elements; SI).

    Attributes
    ----------
    timestep
        The largest timestep of the scan (see :func:`timestep_for`), seconds.
    error
        The worst relative deviation of the restitution over touch phases there.
    restitution
        The continuous restitution (``timestep -> 0``) it is measured against.
    restitution_range
        ``(min, max)`` of the restitution over touch phases at ``timestep``.
    """

    timestep: Any
    error: Any
    restitution: Any
    restitution_range: tuple[Any, Any]

    def __float__(self) -> float:
        return float(self.timestep)


class _Scaled:
    """The contact of element ``i`` at its own timestep ``h``, as one ``predict`` call.

    ``predict`` takes one timestep; time scaling maps element ``i`` at timestep ``h`` to
    the common timestep ``H`` exactly (positions kept, ``sigma = h / H``): ``solref``
    ``(tc / sigma, dr)`` or ``(-sigma^2 k, -sigma b)``, speed ``sigma v``, gravity
    ``sigma^2 g``; the restitution is unchanged (refsafe too: ``tc >= 2 h`` iff
    ``tc / sigma >= 2 H``).
    """

    def __init__(self, ref, simp, v, g, m, w, rho, integrator):
        self.ref, self.simp, self.v, self.g = ref, simp, v, g
        self.m, self.w, self.rho, self.integrator = m, w, rho, integrator
        self.H = 1.0

    def solref(self, sigma, i):
        a, b = self.ref[0][i], self.ref[1][i]
        pos = a > 0
        return (
            np.where(pos, a / sigma, a * sigma * sigma),
            np.where(pos, b, b * sigma),
        )

    def stable(self, h, i):
        """Whether the in-contact step map is stable at timesteps ``h`` (module doc)."""
        sigma = h / self.H
        dm = d_max(self.simp)
        dp = effective_impedance(dm, self.rho[i])
        c = coefficients(self.solref(sigma, i), self.simp, self.H)
        H = self.H
        return stable(
            kappa=dp * dm * c.stiffness * H * H, beta=dp * c.damping * H, integrator=self.integrator
        )

    def phases(self, h, i):
        """``predict`` over phases (mean and range) of elements ``i`` at timesteps ``h``."""
        sigma = h / self.H
        return predict(
            solref=self.solref(sigma, i),
            solimp=self.simp,
            speed=sigma * self.v[i],
            gravity=sigma * sigma * self.g[i],
            mass=self.m,
            inverse_weight=None if self.w is None else self.w[i],
            timestep=self.H,
            integrator=self.integrator,
            phase=None,
        )


def timestep_for(
    *,
    solref: Any,
    solimp: Any = DEFAULT_SOLIMP,
    speed: Any,
    gravity: Any = 0.0,
    tolerance: float = 0.01,
    integrator: str = "euler",
    mass: float | None = None,
    inverse_weight: Any = None,
) -> TimestepAdvice:
    r"""Largest timestep at which the restitution at every touch phase is within ``tolerance``.

    The deviation ``err(dt) = max over phases |e(dt, phase) / e_continuous - 1|`` is
    exact for each timestep (the phase range of
    :func:`~impactsym.engines.mujoco.prediction.predict`). It is not monotone in ``dt``
    (the end step jumps, the rebound is read at a state), so "largest" is defined as
    the **first crossing from below**: ``dt / t_c`` (``t_c`` the continuous contact
    time) is scanned upwards on a geometric grid (8 points per decade from ``1e-2``,
    extended down to ``1e-6`` if needed, up to the stability limit of the step map or
    ``t_c``), and the first grid interval in which ``err > tolerance`` is bisected (24
    halvings in log). Every scanned timestep up to the result meets the tolerance
    (``err`` at the result is returned); a larger timestep at which the deviation
    happens to dip again is not returned. A timestep at which the body sticks at some
    phase counts as exceeding any tolerance.

    Parameters
    ----------
    solref, solimp, speed, gravity, mass, inverse_weight
        As :func:`~impactsym.engines.mujoco.prediction.predict` (arrays broadcast).
    tolerance
        Relative deviation allowed, one number in ``(0, 1)``.
    integrator
        ``"euler"``, ``"implicitfast"`` or ``"rk4"``.

    Returns
    -------
    TimestepAdvice
        ``.timestep`` (seconds), ``.error`` there, the continuous ``.restitution`` and
        the phase range there: the worst error tells how close to the tolerance the
        result is, the continuous value what it is measured against (an object, not a
        float, for these; ``float(advice)`` gives the timestep of a scalar one).

    Raises
    ------
    ValueError
        For bad input (named); where the continuous contact sticks (no relative
        tolerance applies); where even ``dt = 1e-6 t_c`` deviates by more.
    """
    tol, _ = real_array("tolerance", tolerance, lower=0.0, strict=True)
    if np.ndim(tolerance) != 0 or not tol < 1:
        raise ValueError(f"tolerance must be one number in (0, 1), got {tolerance!r}")
    integrator = check_integrator(integrator)
    simp = check_solimp(solimp)
    m = check_mass(mass)
    common = {"solimp": simp, "mass": m, "inverse_weight": inverse_weight}
    c = predict(solref=solref, speed=speed, gravity=gravity, **common)
    scalar = np.ndim(c.restitution) == 0
    shape = np.shape(c.restitution)
    e_c = np.atleast_1d(np.asarray(c.restitution, float)).ravel()
    if np.any(np.asarray(c.sticks)) or np.any(e_c <= 0):
        raise ValueError(
            "the continuous contact sticks (restitution 0) for this solref, speed and "
            "gravity: no relative tolerance in the restitution applies"
        )
    n = e_c.size

    def flat(a):
        return np.broadcast_to(np.asarray(a, float), shape).ravel()

    w = None if inverse_weight is None else flat(inverse_weight)
    rho = flat(weight_ratio(m, inverse_weight))
    sc = _Scaled((flat(solref[0]), flat(solref[1])), simp, flat(speed), flat(gravity), m, w,
                 rho, integrator)  # fmt: skip
    t_c = flat(c.contact_time)
    sc.H = float(np.median(t_c)) * _LOW

    def deviation(h, i):
        """Worst deviation over phases, and the range, at timesteps ``h`` of elements ``i``."""
        err = np.full(h.shape, np.inf)
        rng = np.full((2, *h.shape), np.nan)
        j = np.flatnonzero(sc.stable(h, i))
        if j.size:
            k = i[j]
            p = sc.phases(h[j], k)
            lo, hi = (np.asarray(a, float).ravel() for a in p.restitution_range)
            dev = np.maximum(np.abs(lo / e_c[k] - 1.0), np.abs(hi / e_c[k] - 1.0))
            err[j] = np.where(np.asarray(p.sticks).ravel(), np.inf, dev)
            rng[:, j] = lo, hi
        return err, rng

    every = np.arange(n)
    # the lowest scanned dt / t_c: 1e-2, or a decade lower while the deviation exceeds it
    low = np.full(n, _LOW)
    while True:
        bad = deviation(low * t_c, every)[0] > tol
        if not bad.any():
            break
        if np.any(low[bad] <= _LOWEST * 1.0001):
            i = int(np.flatnonzero(bad & (low <= _LOWEST * 1.0001))[0])
            raise ValueError(
                f"the restitution deviates by more than tolerance = {tolerance!r} from "
                f"its continuous value {e_c[i]:.6g} already at timestep = "
                f"{_LOWEST:g} * contact time (element {i})"
            )
        low = np.where(bad, low / 10.0, low)
    count = int(np.ceil(_PER_DECADE * np.log10(1.0 / low.min()))) + 1
    ratio = 10.0 ** (np.arange(count) / _PER_DECADE)  # grid = low * ratio, up to dt = t_c
    grid = (low * t_c)[:, None] * ratio[None, :]
    inside = ratio[None, :] <= 1.0 / low[:, None] * (1.0 + 1e-12)
    idx = np.repeat(every, count)
    err = deviation(grid.ravel(), idx)[0].reshape(n, count)
    over = (err > tol) | ~inside
    first = np.argmax(over, axis=1)
    none = ~over.any(axis=1)
    lo = grid[every, np.where(none, count - 1, np.maximum(first - 1, 0))]
    hi = np.where(none, lo, grid[every, first])
    for _ in range(_BISECTIONS):
        mid = np.sqrt(lo * hi)
        bad = deviation(mid, every)[0] > tol
        lo, hi = np.where(bad, lo, mid), np.where(bad, mid, hi)
    e_lo, rng = deviation(lo, every)
    out = (lo, e_lo, e_c, rng[0], rng[1])
    out = tuple(finish(a.reshape(shape), scalar) for a in out)
    return TimestepAdvice(out[0], out[1], out[2], (out[3], out[4]))
