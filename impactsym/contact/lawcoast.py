r"""The force-free phases of a nonlinear contact: a coast inside the overlap, the element's
relaxation after a release, the re-contact (normalized, on whole arrays).

**What.** Two motions of :mod:`impactsym.contact.lawkernel` in which the contact force is
zero (``docs/physics.md``, "Nonlinear contact laws", *The clipped condition* and *Bounce
sequences under the force condition*):

* the **coast** of the ``"clipped"`` condition (the engines' contact: a geometric overlap
  ``z > 0`` with the force :math:`\max(0, \varphi)`): where the force would turn tensile
  the body flies freely, :math:`z'' = b`, inside the overlap, until it leaves at
  ``z = 0`` or the force comes back (:func:`coast`);
* the **relaxation** of the massless element after a force-condition release: its force
  stays zero, :math:`\varphi(z_e, z_e') = 0`, i.e. :math:`z_e' = w_0(z_e)`, while the body
  flies; the next contact starts where the body meets it (:func:`recontact`).

**Which equations.** Every law's reduced force (the sign of :math:`\varphi`) is
:math:`r(z, w) = R(z) + c\, w` with :math:`R(z) = z^a` (linear, viscoelastic ``a = 1``;
hertz-linear ``a = p``; Tsuji ``a = (p+1)/2``; Hunt–Crossley :math:`R = 1`, ``a = 0``)
and :math:`c > 0` the damping number's coefficient.

* Coast from a force zero :math:`(z_1, w_1)`, :math:`w_1 < 0`: :math:`z(s) = z_1 + w_1 s +
  b s^2/2`. Along it :math:`r(s)` is convex (:math:`R` convex and increasing, ``z(s)``
  convex) with :math:`r(0) = 0`, :math:`r'(0) \le 0`; at ``z = 0``, :math:`r = c w \le 0`.
  So the body leaves iff the free flight reaches ``z = 0``, :math:`w_1^2 \ge 2 b z_1`, at
  :math:`s = 2 z_1 / (-w_1 + \sqrt{w_1^2 - 2 b z_1})` with speed
  :math:`\sqrt{w_1^2 - 2 b z_1}`; otherwise the force returns at the unique root of ``r``
  in :math:`(0, -w_1/b)` (where :math:`r(-w_1/b) = R(z_{min}) > 0`).
* Relaxation: :math:`z_e^{1-a} = z_c^{1-a} + (a - 1) s / c` (:math:`z_c e^{-s/c}` for
  ``a = 1``). The gap :math:`\Delta = z_e - z_b` to the flying body has
  :math:`\Delta(0) = \Delta'(0) = 0`, :math:`\Delta'' = a z_e^{2a-1}/c^2 - b` falling in
  time for :math:`a \ge 1/2`: exactly one re-contact, after the inflection.

**Why this numerics.** Closed forms where they exist; the two roots by Newton's iteration
from the right end of their bracket, where the function is convex and rising (the
coast's ``r`` beyond its minimum, :math:`-\Delta` beyond its inflection), so the iterates
fall monotonically onto the root; vectorized over elements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Newton iterations at most (monotone, quadratic at a simple root).
NEWTON = 200


@dataclass(frozen=True)
class Coast:
    """The outcome of one coast per element: ``leaves`` (else the force returns),
    ``duration``, the end state ``z``, ``w`` (at a departure ``z = 0``, ``w < 0``)."""

    leaves: np.ndarray
    duration: np.ndarray
    z: np.ndarray
    w: np.ndarray


def coast(fns, z1, w1, delta, b, q) -> Coast:
    r"""The coast that starts at the force zero :math:`(z_1, w_1)` (clipped condition).

    ``fns`` is the law's :class:`~impactsym.contact.lawkernel.LawFunctions`; flat arrays.
    """
    z1, w1 = np.maximum(np.asarray(z1, float), 0.0), np.asarray(w1, float)
    disc = w1 * w1 - 2.0 * b * z1
    leaves = disc >= 0.0
    with np.errstate(all="ignore"):
        root = np.sqrt(np.maximum(disc, 0.0))
        s_exit = np.where(z1 > 0, 2.0 * z1 / (root - w1), 0.0)
        s = -w1 / b  # the turning point of the free flight: r > 0 there
        for _ in range(NEWTON):
            z, w = z1 + s * (w1 + 0.5 * b * s), w1 + b * s
            g = fns.reduced(np.maximum(z, 0.0), w, delta, q)
            slope = (
                fns.reduced_z(np.maximum(z, 0.0), w, delta, q) * w
                + fns.reduced_w(z, w, delta, q) * b
            )
            step = np.where(leaves | ~(slope > 0), 0.0, g / slope)
            s = s - np.maximum(step, 0.0)
            if not np.any(step > 1e-16 * np.abs(s)):
                break
    s = np.where(leaves, s_exit, s)
    z = np.where(leaves, 0.0, z1 + s * (w1 + 0.5 * b * s))
    w = np.where(leaves, -root, w1 + b * s)
    return Coast(leaves=leaves, duration=s, z=z, w=w)


def relax_power(fns, delta, q) -> np.ndarray:
    """The power ``a`` of :math:`R(z) = z^a` in the reduced force, per element."""
    return np.asarray(fns.relax_power(np.ones_like(delta), 0.0 * delta, delta, q), float)


def element(fns, zc, s, delta, q) -> np.ndarray:
    r"""The relaxing element's deflection :math:`z_e(s)` after a release at :math:`z_c`."""
    a = relax_power(fns, delta, q)
    c = fns.reduced_w(np.ones_like(delta), 0.0 * delta, delta, q)
    with np.errstate(all="ignore"):
        x = (a - 1.0) * s * zc ** (a - 1.0) / c
        power = zc * np.exp(-np.log1p(x) / (a - 1.0))
        linear = zc * np.exp(-s / c)
        out = np.where(a == 1.0, linear, power)
        out = np.where((a < 1.0) & (x <= -1.0), 0.0, out)  # reached 0 in finite time
    return np.where(zc > 0, np.nan_to_num(out, nan=0.0), 0.0)


@dataclass(frozen=True)
class Recontact:
    """Where the flying body meets the relaxing element: ``flight`` (time from the
    release), the element's deflection ``z`` and the body's rate ``w`` there (positive
    into the contact; negative where the element catches the body from behind)."""

    flight: np.ndarray
    z: np.ndarray
    w: np.ndarray


def recontact(fns, zc, wc, delta, b, q) -> Recontact:
    r"""The next contact after a force-condition release at :math:`(z_c, w_c)`, ``b > 0``.

    A release at ``z_c = 0`` (the force vanished with the overlap) leaves an undeformed
    element: the body returns to ``z = 0`` after :math:`-2 w_c / b`.
    """
    a = relax_power(fns, delta, q)
    c = fns.reduced_w(np.ones_like(delta), 0.0 * delta, delta, q)
    s = -2.0 * wc / b  # the body is back at z_c, beyond the element
    deflected = zc > 0
    with np.errstate(all="ignore"):
        for _ in range(NEWTON):
            ze = element(fns, zc, s, delta, q)
            gap = zc + s * (wc + 0.5 * b * s) - ze  # body minus element: convex, rising
            slope = wc + b * s + ze**a / c
            step = np.where(deflected & (slope > 0), gap / slope, 0.0)
            s = s - np.maximum(step, 0.0)
            if not np.any(step > 1e-16 * np.abs(s)):
                break
    return Recontact(flight=s, z=element(fns, zc, s, delta, q), w=wc + b * s)


def escape_energy(fns, delta, b, q) -> np.ndarray:
    r"""The least energy :math:`E = w^2/2 + V(z) - bz` from which a clipped contact can
    still leave (``b > 0``): a coast leaves only from a force zero with
    :math:`w_0(z)^2 \ge 2 b z`, i.e. :math:`z \ge z_e` (:math:`R(z)^2/z` rises), and
    :math:`E` never increases; so :math:`E_\mathrm{esc} = \min_{z \ge z_e} [w_0^2/2 + V -
    bz]`, a convex bracket (its minimizer by bisection of its slope). ``0`` (the position
    condition's bound) where the reduced force can be positive at ``z = 0`` (``a < 1``:
    Hunt–Crossley) or there is no damping."""
    a = relax_power(fns, delta, q)
    lo, hi = np.full(delta.shape, -700.0), np.full(delta.shape, 700.0)
    with np.errstate(all="ignore"):
        for _ in range(100):  # ln z_e by bisection; the lower end is kept (conservative)
            mid = 0.5 * (lo + hi)
            zm = np.exp(mid)
            up = fns.release(zm, 0.0, delta, q) ** 2 >= 2.0 * b * zm
            hi, lo = np.where(up, mid, hi), np.where(up, lo, mid)
        z_e = np.exp(lo)
        z_s = np.where(b > 0, b ** (1.0 / q), 0.0)
        lo, hi = np.zeros_like(z_s), z_s.copy()
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            slope = fns.release_slope(mid, 0.0, delta, q) + fns.spring(mid, 0.0, delta, q) - b
            up = ~(slope < 0)
            hi, lo = np.where(up, mid, hi), np.where(up, lo, mid)
        z = np.maximum(z_e, 0.5 * (lo + hi))
        value = 0.5 * fns.release(z, 0.0, delta, q) ** 2 + fns.potential(z, 0.0, delta, q)
        value = value - b * z
    bad = ~np.isfinite(value) | (a < 1.0) | ~(delta > 0) | ~(b > 0)
    return np.where(bad, 0.0, np.maximum(value, 0.0))
