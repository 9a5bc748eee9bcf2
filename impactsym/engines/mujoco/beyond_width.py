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
doubling). That is the section-2 oscillator's first crossing, solved once for every
caller by :func:`impactsym.contact.release.first_crossing` (closed-form extrema, the
kernel's closed forms, the two decay modes above ``D = 2``), here to ``rtol = 1e-14``, in
units of the passage's own length (its products stay in range at any scale). The largest
penetration and force of the passage are read at the same extrema.

Internal: :func:`~impactsym.engines.mujoco.continuous.varying_phase` calls it. Units: SI
(or the caller's time unit), lengths in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.contact.release import (
    derivative_modes,
    first_crossing,
    homogeneous_at,
    homogeneous_extrema,
    homogeneous_modes,
)

__all__ = ["Passage", "passage"]


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


def _crossing(D, level, h0, h1, modes, g0, dg0):
    """First ``tau >= 0`` where ``level + h <= 0``; ``g0``, ``dg0``: the threshold and its
    rate at the start, from the state itself (the modes' sum need not round to them). A
    start on the threshold counts as a crossing only where the threshold does not rise."""
    start = (g0 < 0.0) | ((g0 == 0.0) & (dg0 <= 0.0))
    tau = np.where(start, 0.0, np.inf)
    k = np.flatnonzero(~start)
    if k.size:
        sub = tuple(m[k] for m in modes)
        tau[k] = first_crossing(D[k], level[k], h0[k], h1[k], sub,
                                exclude_start=g0[k] == 0.0, rtol=1e-14)  # fmt: skip
    return tau


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
    omega, D, gravity, dp, x0, v0, width = (
        np.asarray(a, dtype=float) for a in (omega, D, gravity, dp, x0, v0, width)
    )
    inv2 = 1.0 / (omega * omega)
    x_s = (1.0 - dp) * gravity * inv2
    level_f = gravity * inv2
    f_start = dp * gravity * inv2 + 2.0 * D * v0 / omega + x0  # d' f / (m omega^2)
    # in units of the passage's own length (its products stay in range at any scale)
    unit = np.maximum.reduce([np.abs(a) for a in (x0, x_s, width, v0 / omega, level_f)])
    unit = np.where((unit > 0) & np.isfinite(unit), unit, 1.0)
    h0, h1 = (x0 - x_s) / unit, v0 / (omega * unit)
    modes = homogeneous_modes(D, h0, h1)
    # the force threshold g / omega^2 - h'': its homogeneous part is -h''
    f0, f1 = h0 + 2.0 * D * h1, 2.0 * D * (-2.0 * D * h1 - h0) + h1
    fm = derivative_modes(D, derivative_modes(D, modes))
    f_modes = (-fm[0], -fm[1])
    tau_p = _crossing(D, (x_s - width) / unit, h0, h1, modes, (x0 - width) / unit, h1)
    tau_f = _crossing(D, level_f / unit, f0, f1, f_modes, f_start / unit, f1)
    released = np.isfinite(tau_f) & (tau_f <= tau_p)
    tau = np.minimum(tau_f, tau_p)
    end = np.isfinite(tau)
    h, dh = homogeneous_at(np.where(end, tau, 0.0), D, h0, h1, modes)
    position = np.where(end, x_s + unit * h, x_s)
    velocity = np.where(end, omega * unit * dh, 0.0)
    # the largest penetration and force: at the extrema inside the passage, or its ends
    x_max = np.maximum(x0, position)
    f_max = np.maximum(f_start, np.where(end, 0.0, level_f))
    at = np.where(end, tau, 0.0)
    f_end = level_f + unit * homogeneous_at(at, D, f0, f1, f_modes)[0]
    f_max = np.where(end, np.maximum(f_max, f_end), f_max)
    extrema = (homogeneous_extrema(D, h0, h1, modes), homogeneous_extrema(D, f0, f1, f_modes))
    for t_x, t_f in zip(*extrema, strict=True):
        inside = np.isfinite(t_x) & (t_x < tau)
        x_at = x_s + unit * homogeneous_at(np.where(inside, t_x, 0.0), D, h0, h1, modes)[0]
        x_max = np.where(inside, np.maximum(x_max, x_at), x_max)
        inside = np.isfinite(t_f) & (t_f < tau)
        f_at = level_f + unit * homogeneous_at(np.where(inside, t_f, 0.0), D, f0, f1, f_modes)[0]
        f_max = np.where(inside, np.maximum(f_max, f_at), f_max)
    return Passage(tau / omega, released, position, velocity, x_max, f_max * omega * omega)
