r"""Many continuous designs under gravity, read off one Chebyshev table: :func:`pressed_designs`.

In the units of :mod:`impactsym.contact.laws` (:math:`T = \sqrt{m/k}`, :math:`L = v T`)
Drake's continuous point contact under the pressing acceleration ``g`` is

.. math:: z'' = -z\,(1 + s z') - b, \qquad s = d v, \quad b = g T / v,

so its restitution :math:`E(s, b)`, normalized contact time :math:`\tau(s, b)` and deepest
overlap :math:`\zeta(s, b)` depend on the damping number ``s`` and the pressing number
``b`` alone, whatever the mass, speed and gravity (``docs/physics.md``, "Drake point
contact"). With :math:`T = b v / g` a target restitution ``e`` and contact time ``t_c``
(or deepest overlap ``x``) ask for

.. math:: E(s, b) = e, \qquad b\,\tau(s, b) = t_c g / v \quad (b\,\zeta(s, b) = x g / v^2),

and then :math:`k = m (g / (b v))^2`, :math:`d = s / v`. So every target of one call with
``g > 0`` reads its design off one table of :math:`(E, \tau, \zeta)` over ``(s, b)``:

* **The box** holds each target's design without gravity (``s0`` from the Lambert-W
  inverse, ``b0`` from the free contact time or overlap at ``s0``) and the part below it
  that gravity moves the design into (it lowers both; the box reaches down to half of
  each).
* **The table** is the tensor-product Chebyshev interpolant through
  :data:`NODES_S` by :data:`NODES_B` first-kind points of the box, from one call of the
  exact :func:`impactsym.contact.nonlinear.normalized_impact` (order-8 integration).
  The functions are analytic where no node sticks (no steps, no kinks), so the
  coefficients fall geometrically and the interpolation error is of the order of the
  last ones: the table is accepted when, for each quantity, the coefficients of the last
  :data:`TAIL_TERMS` degrees in either variable sum to at most :data:`TAIL` times its
  largest value (measured: ``2e-15`` for the restitution, ``9e-15`` for the contact time
  on the benchmark's box). Otherwise it is built again with twice the points in both
  variables. The box's four corners are evaluated first: the body sticks above a
  pressing number ``b*(s)`` that falls with ``s``, so a node sticks only where the corner
  of largest ``s`` and ``b`` does (heavy damping under a strong pressing force, e.g.
  every target with ``e <= 0.02`` at ``g = 9.81``), and then the nodes are not
  evaluated. Where a corner or node sticks, or
  the tail stays too large, the targets are split in two halves along the wider side of
  their box (relative width, at the median), each with its own box, down to
  :data:`MIN_GROUP` targets; the targets of a group that finds no table are left to the
  caller.
* **The inversion** is Newton's method on the two equations (the second in logarithms)
  with the interpolant's own derivatives, from ``(s0, b0)``, all targets at once. A
  design is read off where the steps fall below ``1e-13`` relative inside the box; it
  then meets both equations of the interpolant to rounding, so the exact restitution and
  size miss their targets by the table's error, about ``1e-14`` relative. The caller
  designs the other targets by its exact iteration.

One table costs ``NODES_S * NODES_B = 512`` exact impacts (the work of about 30 designs by
the exact iteration), the reading a few matrix products per Newton step; the caller
(:func:`~impactsym.engines.drake.design.point_contact_for`) uses it from
:data:`MIN_TARGETS` continuous targets with ``g > 0`` in one call, a rule of the call
alone: smaller calls are designed by the exact iteration, as before.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawtable import chebyshev_points, chebyshev_transform
from impactsym.contact.nonlinear import normalized_impact
from impactsym.engines.drake.continuous import free_scales

__all__ = [
    "MIN_GROUP",
    "MIN_TARGETS",
    "NODES_B",
    "NODES_S",
    "TAIL",
    "TAIL_TERMS",
    "pressed_designs",
]

#: Targets with ``g > 0`` per call from which their designs are read off a table.
MIN_TARGETS = 128
#: Targets per table below which a failed table's targets are not split again.
MIN_GROUP = 32
#: Chebyshev points of the first table in ``s`` and in ``b`` (doubled once if needed).
NODES_S, NODES_B = 32, 16
#: Degrees per variable whose coefficients bound the interpolation error.
TAIL_TERMS = 3
#: Largest tail accepted, relative to the quantity's largest value on the box.
TAIL = 1e-13
_NEGLIGIBLE = 1e-17  # coefficients below this times the largest value are dropped
_NEWTON = 30  # Newton steps at most
_STEP = 1e-13  # relative step below which a design has converged


def pressed_designs(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, g: np.ndarray, target: np.ndarray,
    size_name: str,
) -> tuple[np.ndarray, ...]:  # fmt: skip
    """Designs of continuous contacts under gravity ``g > 0`` read off one table (flat
    arrays; module docstring): ``(ok, k, d, restitution, contact_time, max_penetration)``,
    ``ok`` marking the targets designed (the other entries ``nan``).

    >>> e, one = np.linspace(0.4, 0.8, 5), np.ones(5)
    >>> ok, k, d, e_read, t_read, _ = pressed_designs(e, one, 0.1 * one, 9.81 * one,
    ...                                               5e-3 * one, "contact_time")
    >>> bool(ok.all()), bool(np.allclose(e_read, e, rtol=1e-13, atol=0))
    (True, True)
    """
    n = e.size
    out = [np.zeros(n, bool), *(np.full(n, np.nan) for _ in range(5))]
    # the design without gravity, and the box gravity moves it in
    s0, tau0, z0 = free_scales(e)
    per_b = target * g / v if size_name == "contact_time" else target * g / v**2
    b0 = per_b / (tau0 if size_name == "contact_time" else z0)
    column = 1 if size_name == "contact_time" else 2
    groups = [np.arange(n)]
    while groups:
        rows = groups.pop()
        box = (0.5 * s0[rows].min(), 1.01 * s0[rows].max(), 0.5 * b0[rows].min(),
               1.01 * b0[rows].max())  # fmt: skip
        table = _table(box) if np.all(np.isfinite(box)) else None
        if table is None:  # split the targets in two along the wider side of their box
            if rows.size >= 2 * MIN_GROUP:
                wide_s = box[1] / box[0] >= box[3] / box[2]
                key = s0[rows] if wide_s else b0[rows]
                order = rows[np.argsort(key, kind="stable")]
                groups += [order[: rows.size // 2], order[rows.size // 2 :]]
            continue
        s, b, ok = _newton(table, box, column, e[rows], np.log(per_b[rows]), s0[rows],
                           b0[rows])  # fmt: skip
        i = rows[ok]
        e_t, tau_t, z_t = _evaluate(table, box, s[ok], b[ok])
        time = b[ok] * v[i] / g[i]  # T
        out[0][i] = True
        out[1][i] = m[i] / time**2
        out[2][i] = s[ok] / v[i]
        out[3][i], out[4][i], out[5][i] = e_t, tau_t * time, z_t * v[i] * time
    return tuple(out)


def _table(box):
    """Chebyshev coefficients ``(3, ns, nb)`` of ``(E, tau, zeta)`` on ``box``, with
    :data:`NODES_S` by :data:`NODES_B` points or twice as many, or ``None`` where a
    quantity is not finite on a node (a node sticks) or its tail stays above
    :data:`TAIL`."""
    s_lo, s_hi, b_lo, b_hi = box
    # a sticking corner (a strong pressing force on heavy damping) fails the table: its
    # four impacts cost a hundredth of the nodes' (failed builds cost 7 s each, measured
    # at e <= 0.02 under gravity)
    corner_s, corner_b = np.array([s_lo, s_lo, s_hi, s_hi]), np.array([b_lo, b_hi, b_lo, b_hi])
    corners = normalized_impact("hunt-crossley", corner_s, corner_b, np.ones(4),
                                condition="position")  # fmt: skip
    if not np.all(np.isfinite(np.stack(corners[:3]))):
        return None
    for ns, nb in ((NODES_S, NODES_B), (2 * NODES_S, 2 * NODES_B)):
        s = 0.5 * (s_lo + s_hi) + 0.5 * (s_hi - s_lo) * chebyshev_points(ns)
        b = 0.5 * (b_lo + b_hi) + 0.5 * (b_hi - b_lo) * chebyshev_points(nb)
        S, B = np.meshgrid(s, b, indexing="ij")
        tau, e, z, _ = normalized_impact("hunt-crossley", S.ravel(), B.ravel(),
                                         np.ones(S.size), condition="position")  # fmt: skip
        values = np.stack([e, tau, z]).reshape(3, ns, nb)
        if not np.all(np.isfinite(values)):
            return None
        coef = _coefficients(values)
        if coef is not None:
            return coef
    return None


def _coefficients(values):
    """The Chebyshev coefficients of the ``(3, ns, nb)`` node values, trimmed of the
    degrees that add nothing, or ``None`` where a tail is above :data:`TAIL`."""
    ns, nb = values.shape[1:]
    ms, mb = chebyshev_transform(ns), chebyshev_transform(nb)
    coef = np.einsum("ij,fjk,lk->fil", ms, values, mb)
    a = np.abs(coef)
    tail = a[:, -TAIL_TERMS:, :].sum(axis=(1, 2)) + a[:, :, -TAIL_TERMS:].sum(axis=(1, 2))
    top = np.abs(values).max(axis=(1, 2))
    if np.any(tail > TAIL * top):
        return None
    # the degrees whose coefficients are all below the rounding of the values add nothing
    small = a <= _NEGLIGIBLE * top[:, None, None]
    keep_s = ns - np.argmin(small.all(axis=(0, 2))[::-1])
    keep_b = nb - np.argmin(small.all(axis=(0, 1))[::-1])
    return coef[:, :keep_s, :keep_b]


def _evaluate(coef, box, s, b, fields=(0, 1, 2), derivatives=False):
    """The quantities ``fields`` of ``(E, tau, zeta)`` at ``(s, b)``, ``(len(fields),
    size)``, and with ``derivatives`` also their derivatives in ``s`` and in ``b``."""
    s_lo, s_hi, b_lo, b_hi = box
    c = coef[list(fields)]
    ns, nb = c.shape[1:]
    if derivatives:
        d_s = np.pad(chebyshev.chebder(c, axis=1), ((0, 0), (0, 1), (0, 0))) * 2 / (s_hi - s_lo)
        d_b = np.pad(chebyshev.chebder(c, axis=2), ((0, 0), (0, 0), (0, 1))) * 2 / (b_hi - b_lo)
        c = np.concatenate([c, d_s, d_b])
    xs = (2.0 * s - (s_lo + s_hi)) / (s_hi - s_lo)
    xb = (2.0 * b - (b_lo + b_hi)) / (b_hi - b_lo)
    vs, vb = chebyshev.chebvander(xs, ns - 1), chebyshev.chebvander(xb, nb - 1)
    rows = (vs @ c.transpose(1, 0, 2).reshape(ns, -1)).reshape(s.size, c.shape[0], nb)
    values = np.einsum("ifk,ik->fi", rows, vb)
    if not derivatives:
        return values
    f = len(fields)
    return values[:f], values[f : 2 * f], values[2 * f :]


def _newton(coef, box, column, e, log_c, s, b):
    """Newton's method on ``E(s, b) = e`` and ``log b + log Q(s, b) = log_c`` (``Q`` the
    quantity in ``column``: 1 contact time, 2 overlap) from ``(s, b)``: the roots and
    where they converged inside the box."""
    s_lo, s_hi, b_lo, b_hi = box
    s, b = np.clip(s, s_lo, s_hi), np.clip(b, b_lo, b_hi)
    ok = np.zeros(e.size, bool)
    live = np.arange(e.size)
    for _ in range(_NEWTON):
        if live.size == 0:
            break
        val, der_s, der_b = _evaluate(coef, box, s[live], b[live], (0, column), True)
        q = val[1]
        f1, f2 = val[0] - e[live], np.log(b[live] * q) - log_c[live]
        j11, j12 = der_s[0], der_b[0]
        j21, j22 = der_s[1] / q, 1.0 / b[live] + der_b[1] / q
        det = j11 * j22 - j12 * j21
        with np.errstate(all="ignore"):
            ds = (f1 * j22 - f2 * j12) / det
            db = (j11 * f2 - j21 * f1) / det
        new_s, new_b = s[live] - ds, b[live] - db
        inside = (new_s >= s_lo) & (new_s <= s_hi) & (new_b >= b_lo) & (new_b <= b_hi)
        small = (np.abs(ds) <= _STEP * np.abs(new_s)) & (np.abs(db) <= _STEP * np.abs(new_b))
        s[live], b[live] = np.clip(new_s, s_lo, s_hi), np.clip(new_b, b_lo, b_hi)
        ok[live[small & inside]] = True
        # a failed step: that design is left to the caller (as is one that never settles)
        keep = ~small & np.isfinite(ds) & np.isfinite(db)
        live = live[keep]
    return s, b, ok
