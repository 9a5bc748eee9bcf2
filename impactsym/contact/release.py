r"""The loaded section-2 oscillator and its first release: the one solver of it.

Paper section 2 with two generalizations, shared by the engine models
(:mod:`impactsym.engines.mujoco`, :mod:`impactsym.engines.lammps`): the pressing load
and the threshold of the contact force are independent, and contact ends at whichever
of two thresholds comes first. In the section-2 normalization (``tau = omega0 t``,
``z = x omega0 / v0``)

.. math::

    z'' + 2 D z' + z = c, \qquad z(0) = 0, \quad z'(0) = 1, \qquad
    \lambda(\tau) = 2 D z' + z + \delta,

and the contact ends at the first ``tau > 0`` where ``lambda <= 0`` (force threshold)
or ``z <= 0`` (position threshold). The paper's force condition is ``c = 2 D f``,
``delta = 0``; MuJoCo's soft contact has ``c = (1 - d) gamma``, ``delta = d gamma``.

Every quantity is a constant plus a homogeneous solution ``h``, evaluated by the
section-2 kernel (:class:`impactsym.contact.kernel.Homogeneous`) from the closed forms
of :mod:`impactsym.contact.derivation`, so the solution exists once. Why this numerics:
the extrema of a damped oscillation shrink and alternate in sign, so a crossing of a
level ``L >= 0`` reached from above happens before the second extremum of ``h`` or
never; the extrema (roots of ``h'``, closed form) bracket every first root, which
:func:`impactsym.numeric.roots.bracketed_newton` polishes to ``rtol = 1e-13``. The
paper's plane is left to :func:`impactsym.contact.contact_time`. Above ``D = 2`` the
kernel's ``e^{-D tau}(cosh, sinh)`` form loses the slow mode (amplitude ``~1/D^3`` of
the force, left as a difference of terms ``~D^2``: relative error ``~1e-4`` of the
contact time at ``D ~ 1e3``, false sticking beyond); there ``h`` is the sum of the
modes ``e^{-r_s tau}``, ``e^{-r_f tau}`` (``r_s = 1/(D + mu)``, ``r_f = D + mu``) with
amplitudes in closed forms free of cancellation, and its extremum and zero are
logarithms. Tolerances and checks:
See `docs/physics.md#loaded-oscillator`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.contact.kernel import homogeneous
from impactsym.numeric.roots import bracketed_newton
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = [
    "LinearRelease",
    "derivative_modes",
    "first_crossing",
    "homogeneous_at",
    "homogeneous_extrema",
    "homogeneous_modes",
    "linear_release",
    "release_margin",
]

_SERIES = 1e-3  # below this |mu| tau the arctanh quotient is taken from its series


#: Damping ratio above which the over-damped ``h`` is evaluated as two decaying modes
#: with exact amplitudes (:func:`homogeneous_modes`): the kernel's cosh/sinh form cancels there.
_D_MODES = 2.0


def _rates(D: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decay rates ``r_s = 1/(D + mu)``, ``r_f = D + mu`` and ``w = r_f - r_s = 2 mu``
    (``mu = sqrt(D^2 - 1)``), without cancellation; placeholders where ``D <= _D_MODES``."""
    d = np.where(D > _D_MODES, D, 2.0 * _D_MODES)
    mu = np.sqrt(d - 1.0) * np.sqrt(d + 1.0)
    fast = d + mu
    return 1.0 / fast, fast, 2.0 * mu


def homogeneous_modes(
    D: np.ndarray, h0: np.ndarray, h1: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Mode numerators ``(a_s, a_f) = (h1 + r_f h0, -(h1 + r_s h0))`` of
    ``h = (a_s e^{-r_s tau} + a_f e^{-r_f tau}) / w``, from the initial values.

    Accurate for the position solution (``1 - r_f c``, ``r_s c - 1``); the force
    solution has its own closed forms (:func:`_force_modes`).
    """
    slow, fast, _ = _rates(D)
    return h1 + fast * h0, -(h1 + slow * h0)


def _force_modes(D: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mode numerators of ``-z''`` (``h0 = 2D - c``, ``h1 = 2D (c - 2D) + 1``).

    ``h1 + r_f h0 = r_s (c - r_s)`` and ``h1 + r_s h0 = r_f (c - r_f)`` (``r_s + r_f = 2D``,
    ``r_s r_f = 1``): the slow amplitude, of size ``1/D^3``, is not left as the difference
    of terms of size ``D^2`` that the generic form would make of it.
    """
    slow, fast, _ = _rates(D)
    return slow * (c - slow), fast * (fast - c)


_Modes = tuple[np.ndarray, np.ndarray]


def homogeneous_at(
    tau: np.ndarray, D: np.ndarray, h0: np.ndarray, h1: np.ndarray, modes: _Modes
) -> tuple[np.ndarray, np.ndarray]:
    """``h`` and ``h'`` with ``h(0) = h0``, ``h'(0) = h1`` (the section-2 kernel's closed
    forms, :class:`impactsym.contact.kernel.Homogeneous`), broadcast to one shape; above
    ``_D_MODES`` as two decaying modes with the numerators ``modes`` (:func:`homogeneous_modes`)."""
    a_s, a_f = modes
    shape = np.broadcast_shapes(*(np.shape(x) for x in (tau, D, h0, h1, a_s, a_f)))
    t, d, a, b, ms, mf = (
        np.broadcast_to(np.asarray(x, float), shape).ravel() for x in (tau, D, h0, h1, a_s, a_f)
    )
    over = d > _D_MODES
    if not over.any():
        h, dh = homogeneous()(t, d, a, b)
        return h.reshape(shape), dh.reshape(shape)
    h, dh = np.empty(t.shape), np.empty(t.shape)
    k = ~over
    if k.any():
        h[k], dh[k] = homogeneous()(t[k], d[k], a[k], b[k])
    slow, fast, w = _rates(d[over])
    e_s, e_f = ms[over] * np.exp(-slow * t[over]), mf[over] * np.exp(-fast * t[over])
    h[over] = (e_s + e_f) / w
    dh[over] = -(slow * e_s + fast * e_f) / w
    return h.reshape(shape), dh.reshape(shape)


def _mode_time(D: np.ndarray, modes: _Modes, extremum: bool) -> np.ndarray:
    """Above ``_D_MODES``: the one positive zero of ``h'`` (``extremum``) or of ``h``,
    ``ln(-r_f^k a_f / (r_s^k a_s)) / w`` with ``k = 1`` or ``0``; ``inf`` where none."""
    a_s, a_f = modes
    _, fast, w = _rates(D)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.log(-a_f / a_s)
        if extremum:
            q = q + 2.0 * np.log(fast)  # r_f / r_s = r_f^2
        return np.where(q > 0.0, q / w, np.inf)


def homogeneous_extrema(
    D: np.ndarray, h0: np.ndarray, h1: np.ndarray, modes: _Modes
) -> tuple[np.ndarray, np.ndarray]:
    """First two positive roots of ``h'`` (``inf`` where there are fewer)."""
    p = h0 + D * h1  # h' = e^{-D tau} [h1 C - p S]
    mu = np.sqrt(np.abs(1.0 - D * D))
    under = D < 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.arctan2(mu * h1, p)  # tan(mu tau) = mu h1 / p
        phi = np.mod(phi, np.pi)
        phi = np.where(phi <= 0.0, np.pi, phi)
        t1_under = phi / np.where(under, mu, 1.0)
        t2_under = t1_under + np.pi / np.where(under, mu, 1.0)
        # D >= 1: tanh(mu tau)/mu = h1 / p (tau = h1/p at D = 1)
        ratio = h1 / p
        arg = mu * ratio
        t1_over = np.where(
            # arctanh(x)/mu = ratio (1 + x^2/3 + x^4/5 + ...), x = mu ratio: to x^6/7 ~ 1e-18
            mu * np.abs(ratio) < _SERIES,
            ratio * (1.0 + arg * arg * (1.0 / 3.0 + arg * arg / 5.0)),
            np.arctanh(np.clip(arg, -1.0, 1.0)) / mu,
        )
        ok = (ratio > 0) & (arg < 1.0)
    t1 = np.where(under, t1_under, np.where(ok, t1_over, np.inf))
    t2 = np.where(under, t2_under, np.inf)
    over = D > _D_MODES
    if np.any(over):
        t1 = np.where(over, _mode_time(D, modes, extremum=True), t1)
    return t1, t2


def _extreme_values(D, level, h0, h1, modes, skip=None, extrema=None):
    """First two extrema of ``h`` and the values of ``level + h`` there.

    Where ``skip`` is True the values are not evaluated and reported as ``inf``;
    ``extrema`` are the extrema when the caller has them.
    """
    t1, t2 = homogeneous_extrema(D, h0, h1, modes) if extrema is None else extrema
    if skip is not None and skip.any():
        g1, g2 = np.full(np.shape(t1), np.inf), np.full(np.shape(t2), np.inf)
        k = ~skip
        if k.any():
            sub = tuple(m[k] for m in modes)
            g1[k], g2[k] = _values_at(t1[k], t2[k], D[k], level[k], h0[k], h1[k], sub)
        return t1, t2, g1, g2
    return (t1, t2, *_values_at(t1, t2, D, level, h0, h1, modes))


def _values_at(t1, t2, D, level, h0, h1, modes):
    g1 = level + homogeneous_at(np.where(np.isfinite(t1), t1, 0.0), D, h0, h1, modes)[0]
    g2 = level + homogeneous_at(np.where(np.isfinite(t2), t2, 0.0), D, h0, h1, modes)[0]
    return np.where(np.isfinite(t1), g1, np.inf), np.where(np.isfinite(t2), g2, np.inf)


def _oscillator_inputs(
    D: object, load: object, offset: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``D``, ``load`` and ``offset`` as float arrays of one shape, each finite and
    ``>= 0``; a bad one is refused by name."""
    checked = {
        name: real_array(name, value, lower=0.0)[0]
        for name, value in (("D", D), ("load", load), ("offset", offset))
    }
    shape = broadcast(**checked)
    return tuple(np.broadcast_to(a, shape) for a in checked.values())


def release_margin(D, load, offset):
    r"""Smallest value the thresholds reach while the body stays: ``> 0`` where it sticks.

    With both thresholds active (MuJoCo) the contact never ends exactly when neither
    ``lambda`` nor ``z`` dips to zero before the second extremum (module notes), so

    .. math::

        \mathrm{margin} = \min(\lambda(\tau_1^\lambda), \lambda(\tau_2^\lambda),
                                 z(\tau_2^z)),

    the minimum over those extrema that exist, capped by the long-time values
    ``c + delta`` and ``c``. The stick/release boundary is ``margin = 0``; it needs a
    pressing load (``c > 0``).

    >>> float(release_margin(0.2, 0.0, 0.0)) < 0, float(release_margin(1.0, 2.0, 1.0)) > 0
    (True, True)
    """
    D, c, delta = _oscillator_inputs(D, load, offset)
    a2 = c - 2.0 * D
    a3 = -2.0 * D * a2 - 1.0
    _, _, f1, f2 = _extreme_values(D, c + delta, -a2, -a3, _force_modes(D, c))
    one = np.ones_like(D)
    _, _, _, p2 = _extreme_values(D, c, -c, one, homogeneous_modes(D, -c, one))
    return np.minimum.reduce([f1, f2, p2, c + delta, c])


def derivative_modes(D: np.ndarray, modes: _Modes) -> _Modes:
    """Internal: the mode numerators of ``h'`` from those of ``h`` (:func:`homogeneous_modes`;
    exact: each mode is multiplied by its rate, ``-r_s`` and ``-r_f``)."""
    slow, fast, _ = _rates(D)
    return -slow * modes[0], -fast * modes[1]


def first_crossing(
    D: np.ndarray,
    level: np.ndarray,
    h0: np.ndarray,
    h1: np.ndarray,
    modes: _Modes,
    *,
    exclude_start: np.ndarray,
    before: np.ndarray | None = None,
    rtol: float = 1e-13,
) -> np.ndarray:
    """Internal: first ``tau > 0`` with ``level + h(tau) <= 0``, ``inf`` where never.

    ``h`` is the homogeneous solution from ``(h0, h1)`` with the mode numerators
    ``modes`` (:func:`homogeneous_modes`), and the threshold starts on or above zero,
    ``level + h0 >= 0`` (up to rounding). ``exclude_start``: the start lies on the
    threshold and is not a crossing (the crossing comes after the first extremum).
    Why this numerics (module docstring): a crossing of ``level >= 0`` comes before the
    second extremum of ``h`` or never; for ``level < 0`` an under-damped ``h`` crosses
    by its second extremum too, an over-damped one (at most one extremum, then decaying
    to zero) after its extremum or the start, bracketed by doubling. The bracket is
    polished by :func:`impactsym.numeric.roots.bracketed_newton` to ``rtol``.

    With ``before``, a crossing proven to come after it is not solved for and reported
    as ``inf`` (``level + h`` falls monotonically across its bracket, so it comes after
    ``before`` when the bracket starts after it or the threshold is still positive there).
    """
    tau = np.full(np.shape(D), np.inf)
    # level 0: the first zero of h itself, in closed form (h' has the initial values
    # (h1, -2 D h1 - h0), so the zeros of h are the "extrema" of that function's integral)
    zero = level == 0.0
    if zero.any():
        dz = D[zero]
        unused = (dz, dz)  # modes of that integral: replaced above _D_MODES just below
        z1, _ = homogeneous_extrema(dz, -h1[zero] - 2.0 * dz * h0[zero], h0[zero], unused)
        over = dz > _D_MODES  # above _D_MODES: the zero of the two modes directly
        if over.any():
            sub = tuple(m[zero] for m in modes)
            z1 = np.where(over, _mode_time(dz, sub, extremum=False), z1)
        tau[zero] = z1
        if zero.all():
            return tau
    # a crossing that must wait for the first extremum comes after ``before`` when that
    # extremum does: its threshold values are not needed
    extrema = homogeneous_extrema(D, h0, h1, modes)
    skip = None if before is None else exclude_start & (extrema[0] > before)
    t1, t2, g1, g2 = _extreme_values(D, level, h0, h1, modes, skip, extrema)
    first = np.isfinite(t1) & (g1 <= 0) & ~exclude_start
    second = ~first & np.isfinite(t2) & (g2 <= 0)
    lo = np.where(first, 0.0, np.where(second, t1, 0.0))
    hi = np.where(first, t1, np.where(second, t2, 1.0))
    # the threshold at the bracket ends is known: level + h0 at 0, g1 and g2 at t1, t2
    g_lo = np.where(first, level + h0, g1)
    g_hi = np.where(first, g1, g2)
    # below a negative level an over-damped h (no second extremum) crosses on its way to 0
    tail = ~first & ~second & ~zero & (level < 0.0) & ~np.isfinite(t2)
    if tail.any():
        k = np.flatnonzero(tail)
        past = np.isfinite(t1[k])
        lo[k] = np.where(past, t1[k], 0.0)
        g_lo[k] = np.where(past, g1[k], level[k] + h0[k])
        sub = tuple(m[k] for m in modes)
        hi[k], g_hi[k] = _tail_bracket(D[k], level[k], h0[k], h1[k], sub, lo[k])
    found = (first | second | tail) & ~zero
    if before is not None:
        late = np.array(found & (lo > before))  # an array also when 0-d (item assignment)
        k = found & ~late & (hi > before)
        if k.any():
            sub = tuple(m[k] for m in modes)
            late[k] = level[k] + homogeneous_at(before[k], D[k], h0[k], h1[k], sub)[0] > 0
        found &= ~late
    if found.any():
        params = [a[found] for a in (D, level, h0, h1, *modes)]

        def g_dg(t, d, lv, a, b, ms, mf):
            h, dh = homogeneous_at(t, d, a, b, (ms, mf))
            return lv + h, dh

        tau[found] = bracketed_newton(
            g_dg,
            None,
            lo[found],
            hi[found],
            params,
            rtol=rtol,
            g_lo=np.maximum(g_lo[found], 0.0),  # the bracket's signs, rounding aside
            g_hi=np.minimum(g_hi[found], 0.0),
        )
    return tau


def _tail_bracket(D, level, h0, h1, modes, lo):
    """A time after ``lo`` at which ``level + h < 0`` (``level < 0``) and the value there,
    by doubling (``h`` decays to zero)."""
    hi = np.maximum(2.0 * lo, 1.0)
    g = level + homogeneous_at(hi, D, h0, h1, modes)[0]
    for _ in range(2100):  # 2^2100 > any float time: h has long underflowed by then
        more = g > 0.0
        if not more.any():
            break
        hi = np.where(more, 2.0 * hi, hi)
        g = np.where(more, level + homogeneous_at(hi, D, h0, h1, modes)[0], g)
    return hi, np.minimum(g, 0.0)


@dataclass(frozen=True, eq=False)
class LinearRelease(ArrayRecord):
    """First release of the normalized oscillator (arrays of one shape; dimensionless).

    Attributes
    ----------
    contact_time
        Normalized contact time :math:`\\tau_c = \\omega_0 t_c` (``inf`` when the body sticks).
    restitution
        :math:`-z'(\\tau_c)` (``0.0`` when it sticks).
    released_by_position
        True where the penetration vanishes before the force does.
    max_penetration
        Largest penetration :math:`\\max z` during contact.
    peak_force
        Largest contact force :math:`\\max \\lambda` during contact.
    """

    contact_time: np.ndarray
    restitution: np.ndarray
    released_by_position: np.ndarray
    max_penetration: np.ndarray
    peak_force: np.ndarray

    @property
    def sticks(self) -> np.ndarray:
        """True where contact never ends."""
        return np.isinf(self.contact_time)


def linear_release(
    D: np.ndarray,
    load: np.ndarray,
    offset: np.ndarray,
    *,
    force: bool = True,
    position: bool = True,
    extremes: bool = True,
) -> LinearRelease:
    r"""Release of ``z'' + 2 D z' + z = load`` at ``2 D z' + z + offset <= 0`` or ``z <= 0``.

    Parameters
    ----------
    D
        Lehr's damping ratio (``>= 0``).
    load
        Normalized pressing load ``c >= 0`` (``2 D f`` in the paper).
    offset
        Force threshold ``delta >= 0``: contact force is ``2 D z' + z + delta``.
    force, position
        Which thresholds end the contact (at least one).
    extremes
        Whether to compute ``max_penetration`` and ``peak_force`` (else they are left
        ``nan``; design loops that need only the contact time and restitution skip them).

    Returns
    -------
    LinearRelease

    Notes
    -----
    The force crossing uses ``lambda = c + delta - z''`` with the homogeneous ``z''``
    (``z''(0) = c - 2D``, ``z'''(0) = -2 D z''(0) - 1``); the position crossing
    ``z = c + h`` with ``h(0) = -c``, ``h'(0) = 1``.

    Without load and offset it is the paper's force condition:

    >>> from impactsym.contact import contact_time, restitution
    >>> r = linear_release(np.array([0.0, 0.5]), np.zeros(2), np.zeros(2))
    >>> np.round(r.contact_time, 6).tolist(), np.round(r.restitution, 6).tolist()
    ([3.141593, 2.418399], [1.0, 0.298436])
    >>> f = {"condition": "force"}
    >>> round(contact_time(0.5, 0.0, **f), 6), round(restitution(0.5, 0.0, **f), 6)
    (2.418399, 0.298436)
    """
    D, c, delta = _oscillator_inputs(D, load, offset)
    for name, flag in (("force", force), ("position", position), ("extremes", extremes)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name} must be True or False, got {flag!r}")
    if not (force or position):
        raise ValueError("linear_release needs the force or the position threshold")
    # force: lambda = (c + delta) - z''  with z'' homogeneous
    a2 = c - 2.0 * D
    a3 = -2.0 * D * a2 - 1.0
    one = np.ones_like(D)
    force_modes, position_modes = _force_modes(D, c), homogeneous_modes(D, -c, one)
    tau_f = (
        first_crossing(D, c + delta, -a2, -a3, force_modes, exclude_start=np.zeros(D.shape, bool))
        if force
        else np.full(D.shape, np.inf)
    )
    # position: z = c + h, h(0) = -c, h'(0) = 1 (z(0) = 0 is not a release)
    # without load and offset the force vanishes first (z = -2 D z' > 0 there)
    needed = position and not (force and not c.any() and not delta.any() and (D > 0).all())
    # (solved only where it may come before the force release: the first one counts)
    tau_p = (
        first_crossing(
            D, c, -c, one, position_modes, exclude_start=np.ones(D.shape, bool), before=tau_f
        )
        if needed
        else np.full(D.shape, np.inf)
    )
    tau_c = np.minimum(tau_f, tau_p)
    finite = np.isfinite(tau_c)
    rate = homogeneous_at(np.where(finite, tau_c, 0.0), D, -c, one, position_modes)[1]
    e = np.where(finite, -rate, 0.0)
    if not extremes:
        nan = np.full(D.shape, np.nan)
        return LinearRelease(tau_c, e, finite & (tau_p <= tau_f), nan, nan)
    # largest penetration: at z' = 0 (first extremum of h), else the static value c
    t_z, _ = homogeneous_extrema(D, -c, one, position_modes)
    reach = np.isfinite(t_z) & (t_z < tau_c)
    z_at = c + homogeneous_at(np.where(reach, t_z, 0.0), D, -c, one, position_modes)[0]
    z_max = np.where(reach, z_at, np.where(finite, 0.0, c))
    z_max = np.where(finite, z_max, np.maximum(z_max, c))
    # largest force: at the first minimum of z'' if it comes before release
    lam_modes = (-force_modes[0], -force_modes[1])
    t_l, _ = homogeneous_extrema(D, a2, a3, lam_modes)
    reach_l = np.isfinite(t_l) & (t_l < tau_c)
    lam_at = c + delta - homogeneous_at(np.where(reach_l, t_l, 0.0), D, a2, a3, lam_modes)[0]
    lam0 = 2.0 * D + delta
    force_max = np.maximum(lam0, np.where(reach_l, lam_at, lam0))
    force_max = np.where(finite, force_max, np.maximum(force_max, c + delta))
    return LinearRelease(tau_c, e, finite & (tau_p <= tau_f), z_max, force_max)
