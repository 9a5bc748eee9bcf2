r"""MuJoCo's contact beyond the impedance width: constant impedance, solved in closed form.

For a penetration ``x >= width`` (``solimp[2]``) the impedance is ``d = d_max`` and the
contact equation of :mod:`~impactsym.engines.mujoco.continuous` is linear with constant
coefficients,

.. math::

    x'' + 2 D \omega\,x' + \omega^2 x = (1 - d')\,g, \qquad
    \omega^2 = d' d \bar k, \quad 2 D \omega = d' b,

so from any state ``(x0, v0)`` the motion is ``x = x_s + h(tau)``, ``tau = omega t``, with
the static penetration ``x_s = (1 - d') g / omega^2`` and a homogeneous solution ``h`` of
``h'' + 2 D h' + h = 0`` (``h(0) = x0 - x_s``, ``h'(0) = v0 / omega``). The passage ends
at whichever comes first (:func:`passage`):

* the contact force vanishes, ``d' f / m = g - x'' = omega^2 (g / omega^2 - h'') <= 0``
  (the release, `docs/physics.md#mujoco-prediction`), or
* the penetration returns to the width, ``x_s - w + h <= 0`` (the impedance varies again;
  the caller integrates on);

or never (the body sticks beyond the width). Both thresholds are a level plus a
homogeneous solution, ``G = L + H``. Why this numerics: at an extremum of ``H`` (a zero
of ``H'``) ``H'' = -H``, so every minimum of ``H`` is negative and the minima of ``G``
rise towards ``L`` (their ``|H|`` decays). Hence for ``L >= 0`` a first crossing lies
before the second extremum or never exists; for ``L < 0`` it lies before the first
minimum, which for an over-damped ``H`` may be at infinity (then a bracket is found by
doubling). The extrema are closed forms (``tan``/``tanh`` of the damped frequency, or a
logarithm of the two decay modes above ``D = 2``, where the ``cosh``/``sinh`` form
cancels), and :func:`impactsym.numeric.roots.bracketed_newton` polishes each bracket to
``rtol = 1e-14``. The largest penetration and force of the passage are read at the same
extrema.

Internal: :func:`~impactsym.engines.mujoco.continuous.varying_phase` calls it. Units: SI
(or the caller's time unit), lengths in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.numeric.roots import bracketed_newton

__all__ = ["Passage", "passage"]

_D_MODES = 2.0  # above this damping ratio h is evaluated as two decaying modes


def _spread(D: np.ndarray) -> np.ndarray:
    """``mu = sqrt(|1 - D^2|)`` without cancellation (``D >= 0``)."""
    return np.sqrt(np.abs(1.0 - D)) * np.sqrt(1.0 + D)


def _rates(D: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decay rates ``r_s = 1/(D + mu)``, ``r_f = D + mu`` of the over-damped modes and
    ``r_f - r_s = 2 mu`` (placeholders where ``D < 1``)."""
    real = D >= 1.0
    mu = np.where(real, _spread(D), 1.0)
    fast = np.where(real, D + mu, 2.0)
    return 1.0 / fast, fast, 2.0 * mu


def _as_modes(D, h0, h1):
    """Above ``_D_MODES``: the amplitudes ``(A_s, A_f)`` of ``h = A_s e^{-r_s tau} +
    A_f e^{-r_f tau}`` with ``h(0) = h0``, ``h'(0) = h1``; elsewhere ``(h0, h1)`` unchanged."""
    slow, fast, w = _rates(D)
    over = D > _D_MODES
    w = np.where(over, w, 1.0)
    return (
        np.where(over, (h1 + fast * h0) / w, h0),
        np.where(over, -(h1 + slow * h0) / w, h1),
    )


def _derivative(D, p, q):
    """The representation of ``h'`` from that of ``h`` (see :func:`_as_modes`)."""
    slow, fast, _ = _rates(D)
    over = D > _D_MODES
    return np.where(over, -slow * p, q), np.where(over, -fast * q, -2.0 * D * q - p)


def _value(tau, D, p, q):
    """``h(tau)`` and ``h'(tau)`` from the representation ``(p, q)`` of :func:`_as_modes`.

    Up to ``_D_MODES``: ``h = h0 C + (h1 + D h0) S``, ``h' = h1 C - (h0 + D h1) S`` with
    ``C = e^{-D tau} cos(mu tau)``, ``S = e^{-D tau} sin(mu tau) / mu`` (``cosh``,
    ``sinh`` above ``D = 1``, written with ``e^{-r_s tau}`` and ``expm1`` so that neither
    overflows nor cancels); above it the two modes.
    """
    mu = _spread(D)
    slow, fast, w = _rates(D)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        under = D < 1.0
        decay = np.exp(-np.where(under, D, slow) * tau)
        ang = np.where(under, mu, 0.0) * tau
        em = -np.expm1(-np.where(under, 0.0, w) * tau)  # 1 - e^{-2 mu tau}
        c = decay * np.where(under, np.cos(ang), 1.0 - 0.5 * em)
        s_over = np.where(mu > 0.0, em / np.where(mu > 0.0, w, 1.0), tau)
        s = decay * np.where(under, np.sin(ang) / np.where(under, mu, 1.0), s_over)
        h = c * p + s * (q + D * p)
        dh = c * q - s * (p + D * q)
        over = D > _D_MODES
        if over.any():
            es, ef = np.exp(-slow * tau), np.exp(-fast * tau)
            h = np.where(over, p * es + q * ef, h)
            dh = np.where(over, -slow * p * es - fast * q * ef, dh)
    return h, dh


def _zeros(D, p, q):
    """First two positive zeros of the homogeneous solution ``(p, q)`` (``inf``: none).

    Under-damped: ``e^{D tau} h = R cos(mu tau - theta)``, zeros ``pi / mu`` apart; over-
    damped at most one, where ``tanh(mu tau) / mu = -h0 / (h1 + D h0)``, or above
    ``_D_MODES`` where ``e^{2 mu tau} = -A_f / A_s``.
    """
    mu = _spread(D)
    _, _, w = _rates(D)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        b = q + D * p
        phi = np.mod(np.arctan2(b, mu * p) + 0.5 * np.pi, np.pi)
        phi = np.where(phi > 0.0, phi, np.pi)
        under = D < 1.0
        t1_under = phi / np.where(under, mu, 1.0)
        ratio = -p / b
        arg = mu * ratio
        t1_over = np.where(mu > 0.0, np.arctanh(np.minimum(arg, 1.0)) / mu, ratio)
        t1_over = np.where((ratio > 0.0) & (arg < 1.0), t1_over, np.inf)
        t1_modes = np.log(-q / p) / w
        t1_modes = np.where(np.isfinite(t1_modes) & (t1_modes > 0.0), t1_modes, np.inf)
    t1 = np.where(under, t1_under, np.where(D > _D_MODES, t1_modes, t1_over))
    t2 = np.where(under, t1_under + np.pi / np.where(under, mu, 1.0), np.inf)
    return t1, t2


def _g_dg(tau, D, level, p, q):
    h, dh = _value(tau, D, p, q)
    return level + h, dh


def _first_crossing(D, level, p, q, extrema, g0):
    """First ``tau >= 0`` where ``level + h(tau) <= 0`` (``inf``: never; module notes).

    ``extrema`` are the first two zeros of ``h'``, ``g0`` the threshold at the start
    (from the state itself: the modes' sum need not round to it). A start on the
    threshold counts as a crossing only where ``h`` does not rise there.
    """
    # in units of the threshold's own size (its products stay in range at any scale)
    unit = np.maximum.reduce([np.abs(level), np.abs(g0), np.abs(p), np.abs(q)])
    unit = np.where((unit > 0) & np.isfinite(unit), unit, 1.0)
    level, p, q, g0 = level / unit, p / unit, q / unit, g0 / unit
    dh0 = _value(np.zeros_like(D), D, p, q)[1]
    t1, t2 = extrema
    g1 = level + _value(np.where(np.isfinite(t1), t1, 0.0), D, p, q)[0]
    g2 = level + _value(np.where(np.isfinite(t2), t2, 0.0), D, p, q)[0]
    start = (g0 < 0.0) | ((g0 == 0.0) & (dh0 <= 0.0))
    first = ~start & np.isfinite(t1) & (g1 <= 0.0)
    second = ~start & ~first & np.isfinite(t2) & (g2 <= 0.0)
    # over-damped with a negative level: after its one extremum (or from the start) h
    # decays monotonically to zero, so the threshold crosses on the way to the level
    tail = ~start & ~first & ~second & (level < 0.0) & ~np.isfinite(t2)
    lo = np.where(second, t1, 0.0)
    hi = np.where(first, t1, np.where(second, t2, 1.0))
    g_lo = np.where(second, g1, g0)
    g_hi = np.where(first, g1, g2)
    if tail.any():
        k = np.flatnonzero(tail)
        lo[k] = np.where(np.isfinite(t1[k]), t1[k], 0.0)
        g_lo[k] = np.where(np.isfinite(t1[k]), g1[k], g0[k])
        hi[k], g_hi[k] = _tail_bracket(D[k], level[k], p[k], q[k], lo[k])
    tau = np.where(start, 0.0, np.inf)
    found = first | second | tail
    if found.any():
        k = np.flatnonzero(found)
        tau[k] = bracketed_newton(
            _g_dg,
            None,
            lo[k],
            hi[k],
            [D[k], level[k], p[k], q[k]],
            rtol=1e-14,
            g_lo=np.maximum(g_lo[k], 0.0),
            g_hi=np.minimum(g_hi[k], 0.0),
        )
    return tau


def _tail_bracket(D, level, p, q, lo):
    """A time after ``lo`` at which ``level + h < 0`` (``level < 0``), by doubling."""
    hi = np.maximum(2.0 * lo, 1.0)
    g = level + _value(hi, D, p, q)[0]
    for _ in range(2100):  # 2^2100 > any float time: h has long underflowed by then
        more = g > 0.0
        if not more.any():
            break
        hi = np.where(more, 2.0 * hi, hi)
        g = np.where(more, level + _value(hi, D, p, q)[0], g)
    return hi, np.minimum(g, 0.0)


@dataclass(frozen=True)
class Passage:
    """How a passage beyond the width ends (1-D arrays, one entry per contact).

    Attributes
    ----------
    duration
        Time to the end, in the caller's time unit (``inf`` where the body sticks).
    released
        True where the force vanishes (the release); False where the penetration returns
        to the width first or the body sticks.
    position, velocity
        The state at the end (the static one where it sticks).
    max_penetration, peak_accel
        Largest ``x`` and ``d' f / m = d' (g + b x' + d kbar x)`` over the passage
        (their suprema, the static values included, where it sticks).
    """

    duration: np.ndarray
    released: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    max_penetration: np.ndarray
    peak_accel: np.ndarray


def passage(*, omega, D, gravity, dp, x0, v0, width) -> Passage:
    """The passage beyond ``width`` from the state ``(x0, v0)`` (module docstring).

    Parameters
    ----------
    omega, D
        Natural frequency ``sqrt(d' d_max kbar)`` and damping ratio ``d' b / (2 omega)``
        at ``d_max``.
    gravity, dp
        The pressing acceleration ``g`` and the effective impedance ``d'`` at ``d_max``.
    x0, v0
        The state at the start (``x0 >= width``, up to rounding).
    width
        The penetration at which the impedance starts to vary.
    """
    inv2 = 1.0 / (omega * omega)
    x_s = (1.0 - dp) * gravity * inv2
    p, q = _as_modes(D, x0 - x_s, v0 / omega)
    ext_x = _zeros(D, *_derivative(D, p, q))
    tau_p = _first_crossing(D, x_s - width, p, q, ext_x, x0 - width)
    # the force threshold g / omega^2 - h'' (the homogeneous part -h'')
    fp, fq = _derivative(D, *_derivative(D, p, q))
    fp, fq = -fp, -fq
    level_f = gravity * inv2
    ext_f = _zeros(D, *_derivative(D, fp, fq))
    f0 = dp * gravity * inv2 + 2.0 * D * v0 / omega + x0  # d' f / (m omega^2) at the start
    tau_f = _first_crossing(D, level_f, fp, fq, ext_f, f0)
    released = np.isfinite(tau_f) & (tau_f <= tau_p)
    tau = np.minimum(tau_f, tau_p)
    end = np.isfinite(tau)
    h, dh = _value(np.where(end, tau, 0.0), D, p, q)
    position = np.where(end, x_s + h, x_s)
    velocity = np.where(end, omega * dh, 0.0)
    x_max = np.maximum(x0, position)
    f_max = np.maximum(f0, np.where(end, 0.0, level_f))
    for t_x, t_f in zip(ext_x, ext_f, strict=True):
        inside = np.isfinite(t_x) & (t_x < tau)
        x_at = x_s + _value(np.where(inside, t_x, 0.0), D, p, q)[0]
        x_max = np.where(inside, np.maximum(x_max, x_at), x_max)
        inside = np.isfinite(t_f) & (t_f < tau)
        f_at = level_f + _value(np.where(inside, t_f, 0.0), D, fp, fq)[0]
        f_max = np.where(inside, np.maximum(f_max, f_at), f_max)
    f_end = level_f + _value(np.where(end, tau, 0.0), D, fp, fq)[0]
    f_max = np.where(end, np.maximum(f_max, f_end), f_max)
    return Passage(tau / omega, released, position, velocity, x_max, f_max * omega * omega)
