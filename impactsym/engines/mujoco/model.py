r"""MuJoCo's soft contact law: impedance, ``solref`` coefficients, refsafe, effective mass.

For one frictionless contact (``condim="1"``) MuJoCo makes the constrained acceleration
along the normal satisfy ``a1 + d (b v + k r) = (1 - d) a0`` with ``f >= 0``
(documentation, *Computation*, soft constraints). With penetration ``x = -r``, gravity
``g`` pressing along the normal and the effective impedance ``d'`` this is the loaded
oscillator

.. math::

    x'' + d' b\,x' + d' d \bar k\,x = (1 - d')\,g, \qquad
    f = m\,d'\,(g + b\,x' + d \bar k\,x),

i.e. paper section 2 in ``tau = omega0 t``, ``z = x omega0 / v0`` with
``omega0^2 = d' d kbar``, ``D = d' b / (2 omega0)``, load ``c = (1 - d') gamma`` and
force offset ``delta = d' gamma``, ``gamma = g / (omega0 v0)``
(`docs/physics.md#simulation-engines`). This module holds the law's ingredients;
:mod:`~impactsym.engines.mujoco.prediction` solves the contact and
:mod:`~impactsym.engines.mujoco.design` inverts it.

Why closed forms and not the SymPy expressions of
:class:`impactsym.engines.derivation.MujocoContact` lambdified: the four coefficients
are one line each, the integrator of a varying impedance evaluates ``d'`` at every
Runge-Kutta stage, and importing SymPy and simplifying the derivation costs seconds in
every process that predicts or designs (the command line included), which the NumPy-only
wing avoids. The derivation stays the reference: ``tests/test_engines_mujoco_model.py``
checks :func:`oscillator` and :func:`coefficients` against it at random points.

All quantities are SI: seconds, metres, m/s, m/s^2, kilograms.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = ["DEFAULT_SOLIMP", "DEFAULT_TIMECONST", "Coefficients", "Oscillator", "impedance"]

#: MuJoCo's default ``solimp``: ``(d_min, d_max, width, midpoint, power)``.
DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
#: MuJoCo's default ``timeconst`` (seconds).
DEFAULT_TIMECONST = 0.02
#: MuJoCo clamps the impedance to ``[MIN_IMPEDANCE, MAX_IMPEDANCE]`` (internal).
MIN_IMPEDANCE, MAX_IMPEDANCE = 1e-4, 0.9999
#: the smallest normal float: products and quotients below it have lost digits
TINY = float(np.finfo(float).tiny)


def check_solimp(solimp: object) -> tuple[float, ...]:
    """``solimp`` as MuJoCo uses it: five floats (three are completed with MuJoCo's
    ``0.5, 2``), ``d_min``, ``d_max`` and the midpoint clamped to ``[1e-4, 0.9999]`` as
    ``getsolparam`` clamps them before the impedance is interpolated (clamping the
    interpolated value instead was up to 2.2e-2 off in the restitution at
    ``d_min = 5e-5``); or raise.

    Internal: used by :mod:`~impactsym.engines.mujoco.prediction` and ``design``.

    >>> check_solimp((0.9, 0.95, 0.001))
    (0.9, 0.95, 0.001, 0.5, 2.0)
    """
    if isinstance(solimp, (str, bytes)) or not hasattr(solimp, "__len__"):
        raise TypeError(f"solimp must be 3 or 5 real numbers, got {solimp!r}")
    if len(solimp) not in (3, 5):
        raise TypeError(f"solimp must be 3 or 5 real numbers, got {solimp!r}")
    values = []
    for i, v in enumerate(solimp):
        arr, scalar = real_array(f"solimp[{i}]", v)
        if not scalar:
            raise TypeError(f"solimp must be 3 or 5 real numbers, got {solimp!r}")
        values.append(float(arr))
    if len(values) == 3:
        values += [0.5, 2.0]
    dmin, dmax, width, mid, power = values
    if not (0 < dmin < 1 and 0 < dmax < 1):
        raise ValueError(f"solimp d_min, d_max must lie in (0, 1), got {solimp!r}")
    if width < 0 or not (0 < mid < 1) or power < 1:
        raise ValueError(f"solimp needs width >= 0, 0 < midpoint < 1, power >= 1, got {solimp!r}")
    dmin, dmax, mid = (min(MAX_IMPEDANCE, max(MIN_IMPEDANCE, a)) for a in (dmin, dmax, mid))
    return (dmin, dmax, width, mid, power)


def is_flat(solimp: tuple[float, ...]) -> bool:
    """Whether the impedance is constant (``d_min == d_max`` or zero width). Internal."""
    return solimp[0] == solimp[1] or solimp[2] <= 1e-15


def impedance(depth: Any, solimp: Any = DEFAULT_SOLIMP) -> float | np.ndarray:
    r"""MuJoCo's impedance ``d(r)`` at penetration ``depth`` (metres, ``>= 0``).

    .. math::

        d = d_\min + y(x)\,(d_\max - d_\min), \quad x = \min(1, \mathrm{depth}/w),\quad
        y = \begin{cases} x^p / m^{p-1} & x \le m \\
                           1 - (1 - x)^p / (1 - m)^{p-1} & x > m \end{cases}

    with ``solimp = (d_min, d_max, w, m, p)``; flat (``(d_min + d_max)/2``) when
    ``d_min = d_max`` or ``w = 0``; ``d_min``, ``d_max`` and ``m`` clamped to
    ``[1e-4, 0.9999]`` first, as in MuJoCo (`docs/physics.md#simulation-engines`).

    >>> impedance([0.0, 0.0003, 0.0007, 0.002])
    array([0.9  , 0.909, 0.941, 0.95 ])
    """
    solimp = check_solimp(solimp)
    x_arr, scalar = real_array("depth", depth)
    out = impedance_at(np.abs(x_arr), solimp)
    return float(out) if scalar else out


def impedance_at(depth: np.ndarray, solimp: tuple[float, ...]) -> np.ndarray:
    """:func:`impedance` on a checked ``solimp`` and depth array, unvalidated. Internal."""
    dmin, dmax, width, mid, power = solimp
    if is_flat(solimp):
        return np.full(np.shape(depth), np.clip(0.5 * (dmin + dmax), MIN_IMPEDANCE, MAX_IMPEDANCE))
    # np.minimum/np.maximum rather than np.clip: the same values without np.clip's
    # Python-level overhead, which dominated the exact Euler recurrence's small steps
    x = np.minimum(np.maximum(depth / width, 0.0), 1.0)
    low = x**power / mid ** (power - 1)
    high = 1.0 - (1.0 - x) ** power / (1.0 - mid) ** (power - 1)
    y = np.where(x <= mid, low, high)
    return np.minimum(np.maximum(dmin + y * (dmax - dmin), MIN_IMPEDANCE), MAX_IMPEDANCE)


def d_max(solimp: tuple[float, ...]) -> float:
    """The clamped ``d_max`` that scales ``b`` and ``k`` (MuJoCo's ``solref`` rule). Internal."""
    return float(np.clip(solimp[1], MIN_IMPEDANCE, MAX_IMPEDANCE))


@dataclass(frozen=True, eq=False)
class Coefficients(ArrayRecord):
    """MuJoCo's reference-acceleration coefficients of a ``solref`` (arrays or floats).

    Attributes
    ----------
    damping
        ``b``, 1/s: ``a_ref = -b v - k r``.
    stiffness
        ``kbar = k / d``, 1/s^2 (the impedance-free part of ``k``).
    rate
        ``sqrt(kbar)``, 1/s, formed from ``solref`` without ``kbar`` (``None``: from
        ``stiffness``). It stays representable where ``kbar`` over- or underflows
        (``timeconst = 1e-160`` gives ``kbar = 1e320``), so that the natural
        frequency of :func:`oscillator` is scale-free.
    """

    damping: np.ndarray
    stiffness: np.ndarray
    rate: Any = None

    def in_time_unit(self, unit: np.ndarray) -> Coefficients:
        """The coefficients in time unit ``unit`` (s): ``b unit`` and ``kbar unit^2``.

        Exact (unchanged) where ``unit == 1``; elsewhere ``kbar unit^2`` is formed as
        ``(sqrt(kbar) unit)^2``, which stays in range. Internal (see :func:`time_unit`).
        """
        root = self.root_stiffness()
        with np.errstate(over="ignore", under="ignore"):
            stiff = np.where(unit == 1.0, self.stiffness, (root * unit) ** 2)
            return Coefficients(self.damping * unit, stiff, root * unit)

    def root_stiffness(self) -> np.ndarray:
        """``sqrt(kbar)``: from ``stiffness`` where it is a normal float, else ``rate``."""
        with np.errstate(over="ignore", under="ignore"):
            root = np.sqrt(self.stiffness)
        if self.rate is None:
            return root
        normal = np.isfinite(self.stiffness) & (self.stiffness >= TINY)
        return np.where(normal, root, self.rate)

    def solref(self, solimp: tuple[float, ...], *, form: str = "timeconst") -> tuple[Any, Any]:
        """The ``solref`` pair with these coefficients (inverse of :func:`coefficients`).

        >>> c = coefficients((0.02, 0.5), (0.9, 0.9, 0.001, 0.5, 2.0), None)
        >>> [round(float(v), 12) for v in c.solref((0.9, 0.9, 0.001, 0.5, 2.0))]
        [0.02, 0.5]
        """
        dmax = d_max(solimp)
        if form == "stiffness":
            return -self.stiffness * dmax**2, -self.damping * dmax
        timeconst = 2.0 / (dmax * self.damping)
        return timeconst, 1.0 / (dmax * timeconst * np.sqrt(self.stiffness))


def time_unit(coeffs: Coefficients) -> np.ndarray:
    """Per contact, a time unit ``T`` (s) that brings extreme ``kbar`` and ``b`` to order one.

    ``T = 1 / sqrt(kbar)`` where ``kbar`` or ``b`` lies outside ``[1e-100, 1e100]``
    (``timeconst = 1e-160`` or ``1e160``), ``1.0`` elsewhere, where the results stay as
    they were. Internal: the Runge-Kutta phase runs in these units
    (:meth:`Coefficients.in_time_unit`, speed ``v T``, gravity ``g T^2``).
    """
    damp, stiff = np.asarray(coeffs.damping), np.asarray(coeffs.stiffness)

    def moderate(x):
        return np.isfinite(x) & (x >= 1e-100) & (x <= 1e100)

    extreme = ~(moderate(stiff) & ((damp == 0) | moderate(damp)))
    if coeffs.rate is None or not extreme.any():
        return np.ones(np.shape(stiff))
    with np.errstate(over="ignore", divide="ignore"):
        return np.where(extreme, 1.0 / coeffs.root_stiffness(), 1.0)


def refsafe(timeconst: Any, timestep: float | None) -> Any:
    """MuJoCo's *refsafe*: ``timeconst`` raised to ``2 timestep`` when shorter. Internal."""
    return timeconst if timestep is None else np.maximum(timeconst, 2.0 * timestep)


def coefficients(solref: Any, solimp: tuple[float, ...], timestep: float | None) -> Coefficients:
    """``b`` and ``kbar`` of ``solref`` (either form), with refsafe when ``timestep`` is given.

    ``solref = (timeconst, dampratio) > 0``: ``b = 2 / (d_max timeconst)``,
    ``kbar = 1 / (d_max^2 timeconst^2 dampratio^2)``; ``solref = (-stiffness,
    -damping)``: ``b = damping / d_max``, ``kbar = stiffness / d_max^2``
    (read back from MuJoCo 4's ``efc_KBIP``; `docs/physics.md#simulation-engines`).
    Internal: used by ``predict`` and ``design``.
    """
    if isinstance(solref, (str, bytes)) or not hasattr(solref, "__len__") or len(solref) != 2:
        raise TypeError(f"solref must be a pair (timeconst, dampratio), got {solref!r}")
    a, _ = real_array("solref[0]", solref[0])
    b, _ = real_array("solref[1]", solref[1])
    shape = broadcast(**{"solref[0]": a, "solref[1]": b})
    a, b = np.broadcast_to(a, shape), np.broadcast_to(b, shape)
    positive = a > 0
    if np.any(positive & (b <= 0)) or np.any(~positive & (b > 0)) or np.any(a == 0):
        raise ValueError(
            f"solref must be (timeconst > 0, dampratio > 0) or "
            f"(-stiffness < 0, -damping <= 0), got {solref!r}"
        )
    dmax = np.clip(solimp[1], MIN_IMPEDANCE, MAX_IMPEDANCE)
    tc = refsafe(a, timestep)
    with np.errstate(divide="ignore", over="ignore", under="ignore", invalid="ignore"):
        damp = np.where(positive, 2.0 / (dmax * tc), -b / dmax)
        stiff = np.where(positive, 1.0 / (dmax**2 * tc**2 * b**2), -a / dmax**2)
        # sqrt(kbar) without kbar: 1 / (d_max timeconst dampratio) or sqrt(stiffness) / d_max
        rate = np.where(positive, 1.0 / (dmax * tc * b), np.sqrt(np.abs(a)) / dmax)
    bad = ~np.isfinite(damp) | ~np.isfinite(rate) | (rate < TINY)
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        pair = (float(a.ravel()[i]), float(b.ravel()[i]))
        raise ValueError(
            f"solref = {pair!r} (element {i}) is beyond the float range: its damping "
            f"rate {float(damp.ravel()[i]):.3g} 1/s or natural frequency "
            f"{float(rate.ravel()[i]):.3g} 1/s is not a finite normal float"
        )
    return Coefficients(damp, stiff, rate)


def effective_impedance(d: Any, rho: Any) -> Any:
    """``d' = d rho / (d rho + 1 - d)``, ``rho = A / A_diag`` (``d' = d``: one body). Internal."""
    return d * rho / (d * rho + 1.0 - d)


@dataclass(frozen=True, eq=False)
class Oscillator(ArrayRecord):
    """Paper section 2's coefficients of MuJoCo's contact with constant impedance.

    Attributes
    ----------
    omega0
        Natural frequency ``sqrt(d' d kbar)``, 1/s.
    damping_ratio
        Lehr's ``D = d' b / (2 omega0)``.
    load, offset
        ``c = (1 - d') gamma`` and ``delta = d' gamma``, ``gamma = g / (omega0 v0)``:
        the normalized pressing load and the offset of the force threshold.
    """

    omega0: np.ndarray
    damping_ratio: np.ndarray
    load: np.ndarray
    offset: np.ndarray


def oscillator(coeffs: Coefficients, d: Any, rho: Any, gravity: Any, speed: Any) -> Oscillator:
    """The :class:`Oscillator` of ``coeffs`` at impedance ``d`` (the equation above). Internal.

    >>> o = oscillator(Coefficients(2.0 / (0.9 * 0.02), 1.0 / (0.9**2 * 0.02**2 * 0.25)),
    ...                0.9, 1.0, 0.0, 1.0)
    >>> round(float(o.omega0), 9), round(float(o.damping_ratio), 12)
    (100.0, 0.5)
    """
    dp = effective_impedance(d, rho)
    with np.errstate(over="ignore", under="ignore"):
        omega = np.sqrt(dp * d * coeffs.stiffness)
        if coeffs.rate is not None:  # scale-free where kbar has left the float range
            normal = np.isfinite(omega) & (omega >= TINY)
            omega = np.where(normal, omega, np.sqrt(dp * d) * coeffs.root_stiffness())
        gamma = gravity / (omega * speed)
        gamma = np.where(np.isfinite(gamma), gamma, gravity / omega / speed)
    return Oscillator(omega, dp * coeffs.damping / (2.0 * omega), (1.0 - dp) * gamma, dp * gamma)


def check_timestep(timestep: Any) -> float:
    """``timestep`` as one positive float (seconds), or raise. Internal."""
    value, scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    return float(value)


def check_mass(mass: Any) -> float | None:
    """``mass`` as one positive float (kilograms) or ``None``. Internal."""
    if mass is None:
        return None
    value, scalar = real_array("mass", mass, lower=0.0, strict=True)
    if not scalar:
        raise ValueError("mass must be one number (the effective mass of the contact)")
    return float(value)


def weight_ratio(mass: float | None, inverse_weight: Any) -> Any:
    """``rho = A / A_diag = (1 / mass) / inverse_weight`` (``1.0`` by default). Internal.

    ``A_diag`` is MuJoCo's ``efc_diagA``, its estimate of the inverse effective mass
    from the bodies' ``body_invweight0``; exact (``rho = 1``) for one free or
    slide-jointed body.
    """
    if inverse_weight is None:
        return 1.0
    if mass is None:
        raise ValueError("inverse_weight needs mass (rho = (1/mass) / inverse_weight)")
    w, _ = real_array("inverse_weight", inverse_weight, lower=0.0, strict=True)
    return (1.0 / mass) / w
