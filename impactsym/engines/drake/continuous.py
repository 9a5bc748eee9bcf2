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
impacts.
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.lawclosed import hunt_crossley_restitution

__all__ = ["S_MAX", "hunt_crossley_free"]

#: Largest damping number ``s = d v0`` the quadrature serves (module docstring).
S_MAX = 3.0


def _one_minus_log_ratio(q: np.ndarray) -> np.ndarray:
    """``(1 - log1p(q)/q) / q`` for ``q >= 0``: a series below ``1e-3``."""
    small = q < 1e-3
    qs = np.where(small, q, 0.0)
    series = 0.5 - qs / 3 + qs**2 / 4 - qs**3 / 5 + qs**4 / 6 - qs**5 / 7
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = (1.0 - np.log1p(q) / q) / q
    return np.where(small, series, direct)


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
    tau = np.empty_like(s)
    light = s <= 1.0
    for rows, nodes in ((light, 32), (~light, 64)):
        if rows.any():
            tau[rows] = _contact_time(s[rows], e[rows], nodes)
    return e, tau, z_max


def _contact_time(s: np.ndarray, e: np.ndarray, nodes: int) -> np.ndarray:
    c, r = 0.5 * (1.0 - e), 0.5 * (1.0 + e)
    theta = (np.arange(nodes) + 0.5) * np.pi / nodes
    w = c[:, None] + r[:, None] * np.cos(theta)[None, :]
    ss, ee = s[:, None], e[:, None]
    h_up = 2.0 * _mean(w, 1.0 - w, ss) / (w + ee)
    h_low = -2.0 * _mean(-ee, w + ee, ss) / (1.0 - w)
    h = np.where(w >= c[:, None], h_up, h_low)
    return np.pi / nodes * np.sum(1.0 / (np.sqrt(h) * (1.0 + ss * w)), axis=1)
