r"""What the usual damping design formulas really deliver (``docs/physics.md``, "What the
usual formulas deliver").

The published design formulas give a law's damping parameter from a target coefficient
of restitution ``e`` (and the impact speed :math:`v_0`). Each was derived with an
approximation (small dissipation, an assumed hysteresis loop, a linearized energy
balance), and none is exact. Here each is a function, and :func:`delivered_restitution`
sends its design through the exact :func:`~impactsym.contact.nonlinear.impact` of the
law it was made for:

==========================  ==============================================  =============
formula                     damping parameter                               law
==========================  ==============================================  =============
``"lankarani-nikravesh"``   :math:`\lambda = 3(1 - e^2)/(4 v_0)`            Hunt–Crossley
``"hunt-crossley-1975"``    :math:`\lambda = 3(1 - e)/(2 v_0)`              Hunt–Crossley
``"flores"``                :math:`\lambda = 8(1 - e)/(5 e v_0)`            Hunt–Crossley
``"gonthier"``              :math:`\lambda = (1 - e^2)/(e v_0)`             Hunt–Crossley
``"hu-guo"``                :math:`\lambda = 3(1 - e)/(2 e v_0)`            Hunt–Crossley
``"tsuji-kept"``            :math:`\alpha = -\sqrt5\,\beta` (DEM formula)   Tsuji, p = 3/2
``"tsuji-cut"``             the same, tensile force cut                     Tsuji, p = 3/2
==========================  ==============================================  =============

with :math:`\beta = \ln e/\sqrt{\ln^2 e + \pi^2}`. The Hunt–Crossley force
:math:`k d^p (1 + \lambda d')` stays compressive through the whole impact (the rebound
speed stays below :math:`1/\lambda`), so both conditions give the same restitution,
which is the exact :math:`(1 + W_0(-(1+s)e^{-(1+s)}))/s`, :math:`s = \lambda v_0`, for
every ``k``, ``m`` and ``p``: a formula's delivered ``e`` depends on the target only.

The DEM formula (Tsuji et al. 1992, as written in LIGGGHTS, yade, Chrono SMC:
:math:`\gamma_n = -2\sqrt{5/6}\,\beta\sqrt{S_n m}`, :math:`S_n = 2E^*\sqrt{R^* d}`, on
the Hertz spring :math:`\tfrac43 E^*\sqrt{R^*} d^{3/2}`) is the package's ``"tsuji"``
law with :math:`k = \tfrac43 E^*\sqrt{R^*}`, ``p = 3/2`` and :math:`\alpha = 2\sqrt{5/6}
\sqrt{3/2}\,|\beta| = \sqrt5\,|\beta|` (:math:`S_n = \tfrac32 k d^{1/2}`), which maps
onto the linear contact with :math:`\zeta = \alpha/\sqrt5 = |\beta|` (Antypov & Elliott
2011): the textbook inverse of the linear restitution under the **position** condition.
So it is exact where the engine keeps the tensile force at the end of contact (the
position condition, ``"tsuji-kept"``) and misses where it cuts it (``if (F < 0) F =
0``: the force condition, ``"tsuji-cut"``), where no underdamped setting goes below
:math:`e \approx 0.135`.

References
----------
Hunt, K. H., Crossley, F. R. E. (1975) Coefficient of restitution interpreted as damping
in vibroimpact. J. Appl. Mech. 42:440–445.
Lankarani, H. M., Nikravesh, P. E. (1990) A contact force model with hysteresis damping
for impact analysis of multibody systems. J. Mech. Des. 112:369–376.
Tsuji, Y., Tanaka, T., Ishida, T. (1992) Lagrangian numerical simulation of plug flow of
cohesionless particles in a horizontal pipe. Powder Technol. 71:239–250,
doi:10.1016/0032-5910(92)88030-L.
Gonthier, Y., McPhee, J., Lange, C., Piedbœuf, J.-C. (2004) A regularized contact model
with asymmetric damping and dwell-time dependent friction. Multibody Syst. Dyn.
11:209–233.
Flores, P., Machado, M., Silva, M. T., Martins, J. M. (2011) On the continuous contact
force models for soft materials in multibody dynamics. Multibody Syst. Dyn. 25:357–375.
Hu, S., Guo, X. (2015) A dissipative contact force model for impact analysis in
multibody dynamics. Multibody Syst. Dyn. 35:131–151, doi:10.1007/s11044-015-9453-z.
Antypov, D., Elliott, J. A. (2011) On an analytical solution for the damped Hertzian
spring. EPL 94:50004.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.contact.nonlinear import impact
from impactsym.records import ArrayRecord
from impactsym.validation import finish, real_array

ArrayLike = float | np.ndarray

#: The formulas, in the order of the table.
FORMULAS = (
    "lankarani-nikravesh",
    "hunt-crossley-1975",
    "flores",
    "gonthier",
    "hu-guo",
    "tsuji-kept",
    "tsuji-cut",
)

#: The law and the condition each formula's design is run under.
FORMULA_LAWS = {
    "lankarani-nikravesh": ("hunt-crossley", "position"),
    "hunt-crossley-1975": ("hunt-crossley", "position"),
    "flores": ("hunt-crossley", "position"),
    "gonthier": ("hunt-crossley", "position"),
    "hu-guo": ("hunt-crossley", "position"),
    "tsuji-kept": ("tsuji", "position"),
    "tsuji-cut": ("tsuji", "force"),
}

#: Short labels for tables and figures.
LABELS = {
    "lankarani-nikravesh": "Lankarani–Nikravesh",
    "hunt-crossley-1975": "Hunt–Crossley 1975",
    "flores": "Flores",
    "gonthier": "Gonthier",
    "hu-guo": "Hu–Guo",
    "tsuji-kept": "DEM Tsuji, tensile force kept",
    "tsuji-cut": "DEM Tsuji, tensile force cut",
}


def _target(restitution: object) -> tuple[np.ndarray, bool]:
    e, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if (e > 1.0).any():
        raise ValueError(f"restitution must be in (0, 1], got {float(e[e > 1.0].flat[0])!r}")
    return e, scalar


def _speed(speed: object) -> np.ndarray:
    return real_array("speed", speed, lower=0.0, strict=True)[0]


def lankarani_nikravesh(restitution: ArrayLike, *, speed: ArrayLike) -> ArrayLike:
    r"""Lankarani–Nikravesh (1990): :math:`\lambda = 3(1 - e^2)/(4 v_0)` for
    :math:`k d^p (1 + \lambda d')` (energy balance of a small hysteresis loop).

    >>> lankarani_nikravesh(0.5, speed=2.0)
    0.28125
    """
    e, scalar = _target(restitution)
    return finish(3.0 * (1.0 - e * e) / (4.0 * _speed(speed)), scalar and np.ndim(speed) == 0)


def hunt_crossley_1975(restitution: ArrayLike, *, speed: ArrayLike) -> ArrayLike:
    r"""Hunt–Crossley (1975): :math:`\lambda = 3(1 - e)/(2 v_0)`, from
    :math:`e \approx 1 - \tfrac23 \lambda v_0` (first order in the damping).

    >>> hunt_crossley_1975(0.5, speed=1.0)
    0.75
    """
    e, scalar = _target(restitution)
    return finish(1.5 * (1.0 - e) / _speed(speed), scalar and np.ndim(speed) == 0)


def flores(restitution: ArrayLike, *, speed: ArrayLike) -> ArrayLike:
    r"""Flores et al. (2011): :math:`\lambda = 8(1 - e)/(5 e v_0)` (soft materials).

    >>> flores(0.5, speed=1.0)
    1.6
    """
    e, scalar = _target(restitution)
    return finish(1.6 * (1.0 - e) / (e * _speed(speed)), scalar and np.ndim(speed) == 0)


def gonthier(restitution: ArrayLike, *, speed: ArrayLike) -> ArrayLike:
    r"""Gonthier et al. (2004): :math:`\lambda = (1 - e^2)/(e v_0)`.

    >>> gonthier(0.5, speed=1.0)
    1.5
    """
    e, scalar = _target(restitution)
    return finish((1.0 - e * e) / (e * _speed(speed)), scalar and np.ndim(speed) == 0)


def hu_guo(restitution: ArrayLike, *, speed: ArrayLike) -> ArrayLike:
    r"""Hu and Guo (2015): :math:`\lambda = 3(1 - e)/(2 e v_0)`.

    >>> hu_guo(0.5, speed=1.0)
    1.5
    """
    e, scalar = _target(restitution)
    return finish(1.5 * (1.0 - e) / (e * _speed(speed)), scalar and np.ndim(speed) == 0)


def tsuji_beta(restitution: ArrayLike) -> ArrayLike:
    r""":math:`\beta = \ln e / \sqrt{\ln^2 e + \pi^2}` of the DEM formula (negative).

    >>> round(tsuji_beta(0.5), 6)
    -0.215454
    """
    e, scalar = _target(restitution)
    log_e = np.log(e)
    return finish(log_e / np.sqrt(log_e * log_e + np.pi**2), scalar)


def tsuji_gamma(
    restitution: ArrayLike, *, normal_stiffness: ArrayLike, mass: ArrayLike
) -> ArrayLike:
    r"""The DEM damping coefficient :math:`\gamma_n = -2\sqrt{5/6}\,\beta\sqrt{S_n m}`
    (N s/m, positive as a dashpot), with the tangent stiffness :math:`S_n = 2E^*\sqrt{R^*
    d}` at the current overlap (``normal_stiffness``) and the effective mass ``mass``.

    >>> round(tsuji_gamma(0.5, normal_stiffness=1.5, mass=1.0), 6)
    0.481769
    """
    beta = np.asarray(tsuji_beta(restitution))
    sn = real_array("normal_stiffness", normal_stiffness, lower=0.0, strict=True)[0]
    m = real_array("mass", mass, lower=0.0, strict=True)[0]
    scalar = all(np.ndim(v) == 0 for v in (restitution, normal_stiffness, mass))
    return finish(-2.0 * np.sqrt(5.0 / 6.0) * beta * np.sqrt(sn * m), scalar)


def tsuji_alpha(restitution: ArrayLike) -> ArrayLike:
    r"""The DEM formula as the ``"tsuji"`` law's :math:`\alpha` (``p = 3/2``): with
    :math:`S_n = \tfrac32 k d^{1/2}` (the slope of :math:`k d^{3/2}`),
    :math:`\gamma_n = \alpha\sqrt{mk}\,d^{1/4}` for :math:`\alpha = -\sqrt5\,\beta`.

    >>> round(tsuji_alpha(0.5) / 5 ** 0.5, 6)  # zeta = |beta|
    0.215454
    """
    return finish(-np.sqrt(5.0) * np.asarray(tsuji_beta(restitution)), np.ndim(restitution) == 0)


_HC_DESIGNS = {
    "lankarani-nikravesh": lankarani_nikravesh,
    "hunt-crossley-1975": hunt_crossley_1975,
    "flores": flores,
    "gonthier": gonthier,
    "hu-guo": hu_guo,
}


def check_formula(formula: object) -> str:
    """``formula`` if it names a known design formula, else raise listing them.

    >>> check_formula("flores")
    'flores'
    """
    known = ", ".join(repr(name) for name in FORMULAS)
    if not isinstance(formula, str):
        raise TypeError(f"formula must be a string, one of {known}; got {formula!r}")
    if formula not in FORMULAS:
        raise ValueError(f"formula must be one of {known}; got {formula!r}")
    return formula


def design(formula: str, restitution: ArrayLike, *, speed: ArrayLike = 1.0) -> ArrayLike:
    r"""The damping parameter a formula gives for target ``restitution``: ``lambda``
    (s/m) of the Hunt–Crossley law, or ``alpha`` of the Tsuji law (``speed`` unused).

    >>> design("hu-guo", 0.5, speed=2.0), round(design("tsuji-cut", 0.5), 6)
    (0.75, 0.481769)
    """
    check_formula(formula)
    if formula in _HC_DESIGNS:
        return _HC_DESIGNS[formula](restitution, speed=speed)
    return tsuji_alpha(restitution)


def delivered_restitution(
    formula: str,
    restitution: ArrayLike,
    *,
    stiffness: ArrayLike = 1.0,
    mass: ArrayLike = 1.0,
    speed: ArrayLike = 1.0,
) -> ArrayLike:
    r"""The restitution a formula's design really delivers, from the exact
    :func:`~impactsym.contact.nonlinear.impact` of its law and condition
    (:data:`FORMULA_LAWS`; ``p = 3/2``, no pressing force).

    The result does not depend on ``stiffness``, ``mass`` and ``speed`` (the formulas
    scale with :math:`v_0` exactly as the law's damping number does); they are there to
    show it. Arrays broadcast.

    >>> round(delivered_restitution("lankarani-nikravesh", 0.2), 3)
    0.672
    >>> round(delivered_restitution("tsuji-cut", 0.5), 3)
    0.55
    """
    e, scalar = _target(restitution)
    law, condition = FORMULA_LAWS[check_formula(formula)]
    parameter = design(formula, e, speed=speed)
    result = impact(
        law,
        stiffness=stiffness,
        damping=parameter,
        mass=mass,
        speed=speed,
        exponent=1.5,
        condition=condition,
    ).restitution
    scalar = scalar and all(np.ndim(v) == 0 for v in (stiffness, mass, speed))
    return finish(np.asarray(result), scalar)


@dataclass(frozen=True, eq=False)
class FormulaTable(ArrayRecord):
    """Targets and the restitution each design formula delivers.

    Attributes
    ----------
    target
        The target restitutions, shape ``(n,)``.
    formulas
        The formulas, the rows of ``delivered`` (:data:`FORMULAS`).
    delivered
        ``delivered[i, j]``: what formula ``formulas[i]`` delivers for ``target[j]``.
    """

    target: np.ndarray
    formulas: tuple[str, ...]
    delivered: np.ndarray

    def error(self) -> np.ndarray:
        """``delivered - target``, row by row."""
        return self.delivered - self.target

    def plot(self, *, ax=None):
        """The figure of :func:`impactsym.plotting.lawformulas.plot_formula_errors`."""
        from impactsym.plotting.lawformulas import plot_formula_errors

        return plot_formula_errors(
            self.target, self.delivered, [LABELS[f] for f in self.formulas], ax=ax
        )


def formula_table(targets: ArrayLike | None = None) -> FormulaTable:
    """What every formula delivers for ``targets`` (default ``e = 0.05, 0.10, ..., 0.95``).

    >>> table = formula_table([0.2])
    >>> [round(float(v), 3) for v in table.delivered[:3, 0]]
    [0.672, 0.547, 0.156]
    """
    if targets is None:
        targets = np.round(np.linspace(0.05, 0.95, 19), 2)
    e, _ = _target(targets)
    e = np.atleast_1d(e).ravel()
    delivered = np.stack([delivered_restitution(f, e) for f in FORMULAS])
    return FormulaTable(target=e, formulas=FORMULAS, delivered=delivered)
