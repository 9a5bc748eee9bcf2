r"""The linear Hunt–Crossley impact without pressing force, from its phase plane.

Drake's continuous point contact without gravity is, in the units of
:mod:`impactsym.contact.laws` (:math:`T = \sqrt{m/k}`, :math:`L = v_0 T`),
:math:`z'' = -z (1 + s z')`, :math:`z(0) = 0`, :math:`z'(0) = 1`, :math:`s = d v_0`.
With :math:`w = z'` the orbit separates (``docs/physics.md``, "Drake point contact"):

.. math::

    \tfrac12 z^2 = G(w) = \int_w^1 \frac{\omega\,d\omega}{1 + s\omega},

so the deepest point is :math:`z_{max}^2 = 2G(0) = 2/s - 2\ln(1+s)/s^2` and the contact
ends at :math:`w = -e` with :math:`G(-e) = 0` (the Lambert-W restitution of
:func:`impactsym.contact.lawclosed.hunt_crossley_restitution`). The contact time is
:math:`\tau_c = \int_{-e}^{1} dw / (z(w)(1 + s w))`; with :math:`w = c + r\cos\theta`
(:math:`c = (1-e)/2`, :math:`r = (1+e)/2`) and :math:`G = \tfrac12 H(w)(1-w)(w+e)`,

.. math:: \tau_c = \int_0^\pi \frac{d\theta}{\sqrt{H(w)}\,(1 + s w)},

a smooth even periodic integrand, summed by the midpoint rule (spectrally accurate: its
nearest singularity, ``1 + s w = 0``, closes in on ``w = -e`` as ``s`` grows, so the
rule takes 32 nodes up to ``s = 1`` and 64 up to :data:`S_MAX` = 3 for ``1e-14``; beyond,
``e < 0.29``, the caller integrates the equation of motion instead). ``H``
is evaluated without cancellation from the mean of :math:`\omega/(1+s\omega)` over
:math:`[w, 1]` (upper half) or :math:`[-e, w]` (lower half), with a series for
:math:`\log(1+q)/q` at small :math:`q`. This replaces the order-8 integration for these
impacts. The contact time depends on ``s`` alone and is analytic on ``[0, S_MAX]`` (its
nearest singularity is at ``s = -1``), so :func:`hunt_crossley_free` evaluates a
piecewise Chebyshev interpolant of the quadrature (3 pieces of degree 24, built once
from :func:`contact_time_quadrature`; they agree to ``1e-14`` relative, the quadrature's
own rounding), ten times faster than the quadrature on large arrays.
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawclosed import hunt_crossley_parameter, hunt_crossley_restitution

__all__ = [
    "S_MAX",
    "contact_time_quadrature",
    "free_scales",
    "hunt_crossley_free",
    "start_stiffness",
]

#: Largest damping number ``s = d v0`` the quadrature serves (module docstring).
S_MAX = 3.0
_PIECES = 3  # Chebyshev pieces of [0, S_MAX] (the interpolant of the contact time)
_DEGREE = 24  # degree per piece: the quadrature's own rounding (~1e-14) is reached


def _one_minus_log_ratio(q: np.ndarray) -> np.ndarray:
    """``(1 - log1p(q)/q) / q`` for ``q >= 0``: a series below ``1e-3``."""
    small = q < 1e-3
    with np.errstate(divide="ignore", invalid="ignore"):
        out = (1.0 - np.log1p(q) / q) / q
    if small.any():  # the series only where it is used
        qs = q[small]
        out[small] = 0.5 - qs / 3 + qs**2 / 4 - qs**3 / 5 + qs**4 / 6 - qs**5 / 7
    return out


def _mean(a: np.ndarray, delta: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Mean of ``omega/(1 + s omega)`` over ``[a, a + delta]``:
    ``(a + (1 - log1p(q)/q)/s) / (1 + s a)`` with ``q = s delta/(1 + s a)``."""
    base = 1.0 + s * a
    q = s * delta / base
    return (a + delta / base * _one_minus_log_ratio(q)) / base


def hunt_crossley_free(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Restitution, normalized contact time and normalized deepest overlap at
    ``0 <= s = d v0 <= S_MAX`` (flat arrays; module docstring)."""
    s = np.asarray(s, float)
    if s.size and not (np.all(s >= 0.0) and np.all(s <= S_MAX)):
        raise ValueError(f"hunt_crossley_free serves 0 <= s <= {S_MAX}, got {s!r}")
    e = np.ones_like(s)
    pos = s > 0
    e[pos] = hunt_crossley_restitution(s[pos])
    z_max = np.sqrt(2.0 * _mean(np.zeros_like(s), np.ones_like(s), s))
    return e, _chebyshev_contact_time(s), z_max


def contact_time_quadrature(s: np.ndarray) -> np.ndarray:
    """The normalized contact time at ``0 <= s <= S_MAX`` by the midpoint rule of the
    module docstring (flat arrays): the reference :func:`hunt_crossley_free`'s
    interpolant is built from and tested against."""
    s = np.asarray(s, float)
    e = np.ones_like(s)
    pos = s > 0
    e[pos] = hunt_crossley_restitution(s[pos])
    tau = np.empty_like(s)
    light = s <= 1.0
    for rows, nodes in ((light, 32), (~light, 64)):
        if rows.any():
            tau[rows] = _contact_time(s[rows], e[rows], nodes)
    return tau


@cache
def _chebyshev_table() -> np.ndarray:
    """Chebyshev coefficients of the contact time on ``_PIECES`` equal pieces of
    ``[0, S_MAX]``, interpolating the quadrature at ``_DEGREE + 1`` Chebyshev nodes each."""
    x = np.cos(np.pi * (np.arange(_DEGREE + 1) + 0.5) / (_DEGREE + 1))
    half = 0.5 * S_MAX / _PIECES
    centres = half * (2.0 * np.arange(_PIECES) + 1.0)
    s = (centres[:, None] + half * x[None, :]).ravel()
    tau = contact_time_quadrature(s).reshape(_PIECES, _DEGREE + 1)
    return np.stack([chebyshev.chebfit(x, row, _DEGREE) for row in tau])


def _chebyshev_contact_time(s: np.ndarray) -> np.ndarray:
    """The normalized contact time from the piecewise Chebyshev interpolant (Clenshaw on
    whole arrays; each element with its piece's coefficients)."""
    coef = _chebyshev_table()
    half = 0.5 * S_MAX / _PIECES
    piece = np.minimum((s / (2.0 * half)).astype(np.intp), _PIECES - 1)
    x = (s - half * (2.0 * piece + 1.0)) / half
    b1 = np.zeros_like(s)
    b2 = np.zeros_like(s)
    for j in range(_DEGREE, 0, -1):
        b1, b2 = coef[piece, j] + 2.0 * x * b1 - b2, b1
    return coef[piece, 0] + x * b1 - b2


def _contact_time(s: np.ndarray, e: np.ndarray, nodes: int) -> np.ndarray:
    c, r = 0.5 * (1.0 - e), 0.5 * (1.0 + e)
    theta = (np.arange(nodes) + 0.5) * np.pi / nodes
    w = c[:, None] + r[:, None] * np.cos(theta)[None, :]
    ss, ee = np.broadcast_to(s[:, None], w.shape), np.broadcast_to(e[:, None], w.shape)
    up = w >= c[:, None]  # each node on its own half only (half the work of both)
    low = ~up
    h = np.empty_like(w)
    wu, su, eu = w[up], ss[up], ee[up]
    h[up] = 2.0 * _mean(wu, 1.0 - wu, su) / (wu + eu)
    wl, sl, el = w[low], ss[low], ee[low]
    h[low] = -2.0 * _mean(-el, wl + el, sl) / (1.0 - wl)
    return np.pi / nodes * np.sum(1.0 / (np.sqrt(h) * (1.0 + ss * w)), axis=1)


def start_stiffness(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, size: np.ndarray, *, size_name: str,
    damped: bool,
) -> np.ndarray:  # fmt: skip
    """The stiffness (N/m) at which the continuous law without gravity gives the contact
    time or largest overlap ``size`` (``size_name``): ``k = m (T/size)^2`` with ``T`` the
    dimensionless contact time ``tau0`` or ``z0 v`` of :func:`hunt_crossley_free` at the
    damping number of the restitution ``e`` (``damped``), else the undamped ``pi`` and
    ``v``. The exact designs' first stiffness (at a step the damped law's: an undamped
    start may lie where the step restitutes less than the target). Flat arrays, SI."""
    timed = size_name == "contact_time"
    unit = np.pi if timed else v
    if damped:
        _, tau0, z0 = free_scales(e)
        unit = tau0 if timed else z0 * v
    return m * (unit / size) ** 2


def free_scales(e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(s, tau0, z0)``: the damping number of the restitution ``e`` without gravity
    (:func:`~impactsym.contact.lawclosed.hunt_crossley_parameter`), and the normalized
    contact time and deepest overlap of :func:`hunt_crossley_free` there (at
    :data:`S_MAX` beyond it: the scales designs start from, not designs). Flat arrays."""
    s = hunt_crossley_parameter(e)
    _, tau0, z0 = hunt_crossley_free(np.minimum(s, S_MAX))
    return s, tau0, z0
