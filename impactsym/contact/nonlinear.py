r"""One impact on a nonlinear contact law, in physical units: :func:`impact`.

A body of mass ``m`` hits a contact element at speed ``v0`` under a constant pressing
force ``F`` (``docs/physics.md``, "Nonlinear contact laws"). The laws are those of
:mod:`impactsym.contact.laws` (``"linear"``, ``"hertz-linear"``, ``"hunt-crossley"``,
``"tsuji"``, ``"viscoelastic"``), whose damping parameter is ``c``, ``c``, ``lambda``,
``alpha`` and ``A``. The numbers come from

* the exact linear contact (:func:`~impactsym.contact.api.physical_contact`) for the
  contact time and restitution of ``"linear"``, unchanged, and the closed forms of
  :mod:`impactsym.contact.extrema` for its maximum penetration and peak force (position
  and force conditions; the clipped one integrates them);
* the closed forms of :mod:`impactsym.contact.lawclosed` without pressing force: the
  Hunt–Crossley restitution (Lambert W) and the Tsuji map onto the linear contact with
  :math:`\zeta = \alpha/\sqrt{2(p+1)}` (restitution and sticking);
* the order-8 integration of :mod:`impactsym.contact.lawkernel` for everything else
  (contact times, maximum penetration, peak force, and any law with a pressing force);
  in large calls read from tables built once from it: :func:`free_table` without
  pressing force, :func:`pressed_table` with one (:mod:`impactsym.contact.lawpressed`).

Three contact conditions (:data:`LAW_CONDITIONS`): ``"position"`` (contact while the
overlap ``d > 0``), ``"force"`` (while the force is compressive; the element's own
relaxation after it) and ``"clipped"``, what the engines integrate: the force
:math:`\max(0, F(d, \dot d))` on the geometric overlap, so the body may coast inside the
overlap where the force would pull, be caught again by the force, and leaves at
``d = 0`` (LAMMPS ``limit_damping``, Chrono's ``if (forceN < 0) forceN = 0``, Drake's
Hunt–Crossley factor :math:`(1 + d\,\dot x)_+`). For the linear law it is the
force-condition release followed by the closed-form coast (:func:`clipped_linear`, the
LAMMPS continuous ``limit_damping`` contact).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from impactsym.contact import lawpressed
from impactsym.contact.api import contact_time, physical_contact, restitution
from impactsym.contact.extrema import linear_extrema
from impactsym.contact.lawclosed import (
    hunt_crossley_restitution,
    linear_free_restitution,
    tsuji_zeta,
)
from impactsym.contact.lawkernel import integrate
from impactsym.contact.lawpatch import PatchTable
from impactsym.contact.lawrecord import NonlinearImpact
from impactsym.contact.laws import check_law
from impactsym.contact.lawtable import ChebyshevTable, build
from impactsym.validation import CONDITIONS, broadcast, finish, real_array

ArrayLike = float | np.ndarray

#: The contact conditions of the nonlinear-law functions: those of section 2 and the
#: engines' ``"clipped"`` force :math:`\max(0, F)` on the geometric overlap.
LAW_CONDITIONS = (*CONDITIONS, "clipped")


def check_law_condition(value: object) -> str:
    """Return ``value`` if it names a condition of :data:`LAW_CONDITIONS`, else raise.

    >>> check_law_condition("clipped")
    'clipped'
    """
    known = ", ".join(repr(c) for c in LAW_CONDITIONS)
    if not isinstance(value, str):
        raise TypeError(
            f"condition must be one of the strings {known}, got {value!r} of type "
            f"{type(value).__name__}"
        )
    if value not in LAW_CONDITIONS:
        raise ValueError(f"condition must be one of {known}, got {value!r}")
    return value


def clipped_linear(tau_f, e_f, D, b) -> tuple[np.ndarray, np.ndarray]:
    r"""Contact time and restitution of the linear law under the clipped condition, from
    its force-condition release (normalized: :math:`\tau = \omega_0 t`, ``b = 2Df``).

    At the force zero :math:`z = 2De`, :math:`z' = -e`; the body coasts,
    :math:`z = 2De - es + bs^2/2`, and leaves at ``z = 0`` with speed
    :math:`\sqrt{e(e - 4Db)}` where :math:`e \ge 4Db`; otherwise the force returns inside
    the overlap and the body sticks (``docs/physics.md``, *The clipped condition*: the
    linear oscillator's energy then stays below any that could leave). The LAMMPS
    ``limit_damping`` contact (:func:`impactsym.engines.lammps.predict`,
    ``departure_speed``). Returns ``(tau_c, e)``, ``(inf, 0)`` where the body sticks.
    """
    tau_f, e_f, D, b = (np.asarray(a, dtype=float) for a in (tau_f, e_f, D, b))
    z1 = 2.0 * D * e_f
    disc = e_f * (e_f - 4.0 * D * b)
    sticks = np.isinf(tau_f) | (disc < 0)
    with np.errstate(all="ignore"):
        root = np.sqrt(np.maximum(disc, 0.0))
        s = np.where(z1 > 0, 2.0 * z1 / (e_f + root), 0.0)
    return np.where(sticks, np.inf, tau_f + s), np.where(sticks, 0.0, root)


def normalize(law: str, k, c, m, v0, F, p) -> tuple[np.ndarray, ...]:
    """Time scale, length scale, damping number, pressing term ``b`` and the exponent in
    use, on flat arrays (``docs/physics.md``, "Nonlinear contact laws")."""
    q = {"linear": np.ones_like(p), "viscoelastic": np.full_like(p, 1.5)}.get(law, p)
    with np.errstate(all="ignore"):
        T = np.exp((np.log(m) - np.log(k) - (q - 1.0) * np.log(v0)) / (q + 1.0))
        L = v0 * T
        delta = {
            "linear": c / 2.0 / (np.sqrt(k) * np.sqrt(m)),
            "hertz-linear": c * T / (2.0 * m),
            "hunt-crossley": c * v0,
            "tsuji": c,
            "viscoelastic": 1.5 * c / T,
        }[law]
        b = F * T / m / v0
    for label, value in (("time scale T", T), ("damping number", delta), ("pressing term", b)):
        if not np.all(np.isfinite(value)) or not np.all(value >= 0):
            raise ValueError(
                f"{law}: the inputs give a {label} that is not a finite float "
                f"({value[~np.isfinite(value)][:1]}); rescale the units"
            )
    return T, L, delta, b, q


def linear_ends(
    delta: np.ndarray, b: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    """Normalized contact time and restitution of the linear law (flat arrays, ``b = 2Df``)
    by the closed forms of :func:`~impactsym.contact.api.contact_time` and
    :func:`~impactsym.contact.api.restitution` (clipped: :func:`clipped_linear`)."""
    released = "force" if condition == "clipped" else condition
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(b > 0, b / (2.0 * delta), 0.0)
    tau_c = np.asarray(contact_time(delta, f, condition=released), dtype=float).reshape(b.shape)
    e = np.asarray(restitution(delta, f, condition=released), dtype=float).reshape(b.shape)
    if condition == "clipped":
        tau_c, e = clipped_linear(tau_c, e, delta, b)
    return tau_c, e


def integrated_impact(
    law: str, delta: np.ndarray, b: np.ndarray, q: np.ndarray, *, condition: str
) -> tuple[np.ndarray, ...]:
    """Contact time, restitution, maximum penetration and peak force (normalized) of flat
    arrays by the order-8 integration, with the ends the closed forms know: the linear
    law's contact time and restitution (:func:`linear_ends`), and its extrema
    (:func:`~impactsym.contact.extrema.linear_extrema`; integrated under the clipped
    condition only), and the sticking of an over-damped Tsuji contact (position
    condition)."""
    end = np.full(delta.shape, np.nan)
    if law == "linear":
        tau_c, e = linear_ends(delta, b, condition=condition)
        if condition != "clipped":  # the extrema in closed form too
            return tau_c, e, *linear_extrema(delta, b, tau_c)
        end = np.where(np.isinf(tau_c), np.inf, np.nan)
        run = integrate(law, delta, b, q, condition=condition, end_time=end)
        return tau_c, e, run.z_max, run.peak
    if law == "tsuji" and condition == "position":
        end[(b == 0) & (tsuji_zeta(delta, q) >= 1.0)] = np.inf  # the linear contact creeps
    result = integrate(law, delta, b, q, condition=condition, end_time=end)
    return result.tau_c, result.e, result.z_max, result.peak


def linear_free_extrema(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Maximum penetration and peak force of the unpressed linear law by the integration,
    stopped at twice the time :math:`\tau_m` of the maximum penetration (``tan(w tau_m) =
    w/D``, :math:`w = \sqrt{1 - D^2}`; ``tanh`` over-damped): both extrema lie before it
    (the force is largest before ``z' = 0``, where it falls at rate :math:`-2Dz`, and
    later oscillations are smaller), so the table never integrates the long creep near
    ``D = 1``."""
    with np.errstate(all="ignore"):
        w = np.sqrt(np.abs(1.0 - delta * delta))
        t_m = np.where(delta < 1.0, np.arctan2(w, delta) / w, np.arctanh(w / delta) / w)
    t_m = np.where(np.isfinite(t_m) & (t_m > 0), t_m, 1.0)  # D = 1: t_m = 1
    zero = np.zeros_like(delta)
    run = integrate("linear", delta, zero, np.ones_like(delta), condition="position",
                    end_time=2.0 * t_m)  # fmt: skip
    return run.z_max, run.peak


#: Unpressed elements of one law and exponent in one call from which the table of
#: :func:`free_table` is used (fewer are integrated: a table costs a few seconds to
#: build, once per law, exponent and condition). The choice depends on the call alone, so
#: the same call gives the same numbers in any session.
TABLE_MIN = 1000
#: The tables' variable ``u``: :math:`\delta = ` ``TABLE_SCALE`` :math:`\sinh u` (linear
#: near zero damping, logarithmic at large damping).
TABLE_SCALE = 0.1
#: Largest damping number of each law's table (larger ones are integrated).
TABLE_TOP = {"linear": 10.0, "hertz-linear": 10.0, "hunt-crossley": 30.0,
             "tsuji": 10.0, "viscoelastic": 10.0}  # fmt: skip
#: Pieces where a tabled value exceeds this are integrated (near a sticking threshold,
#: where the contact time diverges).
TABLE_CAP = 100.0
#: Narrowest piece of a table (in ``u``): around a kink, a gap this wide is integrated.
TABLE_GAP = 1e-6


def free_table(law: str, exponent: float, *, condition: str) -> ChebyshevTable:
    r"""The unpressed impact of ``law`` at ``exponent`` as a piecewise Chebyshev table in
    :math:`u = \operatorname{asinh}(\delta/0.1)` (:mod:`impactsym.contact.lawtable`),
    built once from :func:`integrated_impact` on the Chebyshev points.

    ``condition``: ``"position"``, rows (contact time, restitution, maximum penetration,
    peak force); or ``"force"``, the same rows and a fifth, the contact time under the
    ``"clipped"`` condition (without pressing force the clipped contact is the force
    condition's, then a free coast at the same speed). Accurate to 1e-10 (relative) against
    an independent integration (``tests/test_contact_lawtable.py``). Kept per process
    (``functools.lru_cache`` on the checked arguments, the last 64 tables;
    ``free_table.cache_clear()`` frees them, ``free_table.cache_info()`` counts them).
    """
    check_law(law)
    exponent = _checked_exponent(exponent)
    if condition not in ("position", "force"):
        raise ValueError(f"a table's condition is 'position' or 'force', got {condition!r}")
    return _built_table(law, exponent, condition)


def _checked_exponent(exponent: object) -> float:
    """``exponent`` as a float if it is a real number >= 1, else raise naming it."""
    if isinstance(exponent, (bool, np.bool_)) or not isinstance(
        exponent, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"exponent must be a real number, got {exponent!r}")
    if not (np.isfinite(exponent) and exponent >= 1.0):
        raise ValueError(f"exponent must be finite and >= 1, got {exponent!r}")
    return float(exponent)


@lru_cache(maxsize=64)
def _built_table(law: str, exponent: float, condition: str) -> ChebyshevTable:
    """:func:`free_table` of checked arguments (the cache keys on them)."""

    def exact(u: np.ndarray) -> np.ndarray:
        delta = TABLE_SCALE * np.sinh(u)
        b, q = np.zeros_like(u), np.full(u.shape, float(exponent))
        if law == "linear":  # contact time and restitution are closed forms: not tabled
            zero = np.zeros_like(u)
            return np.stack((zero, zero, *linear_free_extrema(delta), zero))
        if condition == "position":
            return np.stack(integrated_impact(law, delta, b, q, condition=condition))
        run = integrate(law, delta, b, q, condition="force")
        with np.errstate(divide="ignore", invalid="ignore"):  # clipped: the free coast
            coast = np.where(run.z_end > 0, run.z_end / run.e, 0.0)
        return np.stack((run.tau_c, run.e, run.z_max, run.peak, run.tau_c + coast))

    top = np.arcsinh(TABLE_TOP[law] / TABLE_SCALE)
    return build(exact, 0.0, float(top), min_width=TABLE_GAP, cap=TABLE_CAP)


free_table.cache_clear = _built_table.cache_clear  # type: ignore[attr-defined]
free_table.cache_info = _built_table.cache_info  # type: ignore[attr-defined]


def table_mask(b: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The elements of flat arrays that the tables serve: unpressed, with an exponent that
    at least :data:`TABLE_MIN` unpressed elements of the call share."""
    return shared_exponent(b == 0, q, TABLE_MIN)


def shared_exponent(candidates: np.ndarray, q: np.ndarray, minimum: int) -> np.ndarray:
    """The ``candidates`` (a mask) whose exponent at least ``minimum`` candidates share.

    >>> shared_exponent(np.array([True, True, True, False]), np.array([1.5, 1.5, 2.0, 2.0]),
    ...                 2).tolist()
    [True, True, False, False]
    """
    if np.count_nonzero(candidates) < minimum:
        return np.zeros(q.shape, dtype=bool)
    if q.min() == q.max():
        return candidates
    values, inverse = np.unique(q, return_inverse=True)
    counts = np.bincount(inverse[candidates], minlength=values.size)
    return candidates & (counts[inverse] >= minimum)


def tabulated(
    law: str,
    delta: np.ndarray,
    b: np.ndarray,
    q: np.ndarray,
    *,
    condition: str,
    mask: np.ndarray | None = None,
    rows: tuple[int, ...] = (0, 1, 2, 3),
) -> tuple[np.ndarray, np.ndarray]:
    """The table's ``rows`` of (contact time, restitution, maximum penetration, peak force)
    of flat arrays, shape ``(len(rows), n)``, and where it was used: on the elements of
    ``mask`` (default :func:`table_mask`) inside the table's cover (``nan`` elsewhere)."""
    values = np.full((len(rows), delta.size), np.nan)
    inside = np.zeros(delta.size, dtype=bool)
    mask = table_mask(b, q) if mask is None else mask
    if not mask.any():
        return values, inside
    # the linear law tables only its extrema, the same under every condition
    key = "position" if condition == "position" or law == "linear" else "force"
    if condition == "clipped":
        rows = tuple(4 if r == 0 else r for r in rows)
    exponents = (q[0],) if q.min() == q.max() else np.unique(q[mask])
    for exponent in exponents:
        table = free_table(law, float(exponent), condition=key)
        if len(exponents) == 1 and mask.all():  # the common case: no copies
            return table(np.arcsinh(delta / TABLE_SCALE), rows)
        sel = np.flatnonzero(mask & (q == exponent))
        v, ok = table(np.arcsinh(delta[sel] / TABLE_SCALE), rows)
        values[:, sel[ok]], inside[sel[ok]] = v[:, ok], True
    return values, inside


#: Pressed elements of one law and exponent in one call from which the tables of
#: :func:`pressed_table` are used (by :func:`impact` and
#: :func:`~impactsym.contact.lawdesign.damping_for`; fewer are integrated).
PRESSED_MIN = 1000
#: The laws and conditions with tables of the pressed impact (the linear law has closed
#: forms; the clipped condition is integrated).
PRESSED_LAWS = ("hertz-linear", "hunt-crossley", "tsuji", "viscoelastic")
PRESSED_CONDITIONS = ("position", "force")
#: The parts of the tables of the pressed impact (:mod:`impactsym.contact.lawpressed`).
PRESSED_PARTS = ("boundary", "ends", "extrema")


def pressed_table(
    law: str, exponent: float, *, condition: str, part: str
) -> ChebyshevTable | PatchTable:
    r"""One part of the tables of the pressed impact of ``law`` at ``exponent``
    (:mod:`impactsym.contact.lawpressed`), built once from :func:`integrated_impact`:

    * ``"boundary"``: :math:`\ln f^*` in :math:`u = \operatorname{asinh}(\delta/0.1)`
      (the sticking verdict of :func:`~impactsym.contact.lawkernel.integrate`);
    * ``"ends"``: contact time and restitution where the body releases, in ``u`` and
      :math:`\sigma = -\ln(1 - f/f^*)`;
    * ``"extrema"``: maximum penetration and peak force in ``(u, f)``.

    ``law`` one of :data:`PRESSED_LAWS`, ``condition`` ``"position"`` or ``"force"``.
    Accurate to 1e-10 (relative; restitution absolute) against an independent integration
    (``tests/test_contact_lawpressed.py``). Kept per process like :func:`free_table`
    (``pressed_table.cache_clear()``, ``pressed_table.cache_info()``).
    """
    if law not in PRESSED_LAWS:
        raise ValueError(f"pressed tables exist for the laws {PRESSED_LAWS}, got {law!r}")
    if condition not in PRESSED_CONDITIONS:
        raise ValueError(f"a pressed table's condition is 'position' or 'force', got {condition!r}")
    if part not in PRESSED_PARTS:
        raise ValueError(f"part must be one of {PRESSED_PARTS}, got {part!r}")
    return _pressed_part(law, _checked_exponent(exponent), condition, part)


@lru_cache(maxsize=64)
def _pressed_part(law: str, exponent: float, condition: str, part: str):
    """:func:`pressed_table` of checked arguments (the cache keys on them)."""

    def exact(delta: np.ndarray, b: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, ...]:
        return integrated_impact(law, delta, b, q, condition=condition)

    if part == "boundary":

        def sticks(delta: np.ndarray, f: np.ndarray, q: np.ndarray) -> np.ndarray:
            return integrate(law, delta, f, q, condition=condition, settle=False).sticks

        label = f"pressed_table({law!r}, {exponent!r}), {condition} condition"
        return lawpressed.build_boundary(sticks, exponent, label=label)
    if part == "ends":
        boundary = _pressed_part(law, exponent, condition, "boundary")
        return lawpressed.build_ends(exact, boundary, exponent)
    return lawpressed.build_extrema(exact, exponent)


pressed_table.cache_clear = _pressed_part.cache_clear  # type: ignore[attr-defined]
pressed_table.cache_info = _pressed_part.cache_info  # type: ignore[attr-defined]


def pressed_mask(law: str, b: np.ndarray, q: np.ndarray, *, condition: str) -> np.ndarray:
    """The elements of flat arrays that the tables of :func:`pressed_table` serve: pressed,
    of a law and condition that has them, with an exponent that at least
    :data:`PRESSED_MIN` pressed elements of the call share."""
    if law not in PRESSED_LAWS or condition not in PRESSED_CONDITIONS:
        return np.zeros(b.shape, dtype=bool)
    return shared_exponent(b > 0, q, PRESSED_MIN)


def pressed_tabulated(
    law: str,
    delta: np.ndarray,
    b: np.ndarray,
    q: np.ndarray,
    *,
    condition: str,
    rows: tuple[int, ...] = (0, 1, 2, 3),
    mask: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The rows ``rows`` of (contact time, restitution, maximum penetration, peak force) of
    flat arrays from the tables of :func:`pressed_table`, shape ``(len(rows), n)``, and
    where they were used: on the elements of ``mask`` (default :func:`pressed_mask`)
    inside the tables' cover (``nan`` elsewhere). Only the parts that ``rows`` need are
    built."""
    values = np.full((4, delta.size), np.nan)
    inside = np.zeros(delta.size, dtype=bool)
    mask = pressed_mask(law, b, q, condition=condition) if mask is None else mask
    if not mask.any():
        return values[list(rows)], inside
    ends, extrema = bool({0, 1} & set(rows)), bool({2, 3} & set(rows))
    for exponent in np.unique(q[mask]):
        sel = np.flatnonzero(mask & (q == exponent))
        x = float(exponent)
        v, ok = lawpressed.pressed_values(
            delta[sel],
            b[sel],
            boundary=pressed_table(law, x, condition=condition, part="boundary"),
            ends=pressed_table(law, x, condition=condition, part="ends") if ends else None,
            extrema=pressed_table(law, x, condition=condition, part="extrema") if extrema else None,
        )
        values[:, sel[ok]], inside[sel[ok]] = v[:, ok], True
    return values[list(rows)], inside


def normalized_impact(
    law: str,
    delta: np.ndarray,
    b: np.ndarray,
    q: np.ndarray,
    *,
    condition: str,
    pressed_tables: bool = False,
    rows: tuple[int, ...] = (0, 1, 2, 3),
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Contact time, restitution, maximum penetration, peak force (all normalized) of
    flat arrays: unpressed elements from the table of :func:`free_table` where
    :func:`tabulated` uses it, with ``pressed_tables`` pressed ones from the tables of
    :func:`pressed_table` where :func:`pressed_tabulated` uses them (the rows ``rows``
    only: the others are ``nan`` there), the rest by :func:`integrated_impact`; the
    closed-form restitutions where they hold (Hunt–Crossley, Tsuji without pressing
    force)."""
    # the closed-form restitutions (below) need no table row
    free_rows = (0, 2, 3) if law in ("hunt-crossley", "tsuji") else (0, 1, 2, 3)
    values = np.full((4, delta.size), np.nan)
    values[list(free_rows)], inside = tabulated(
        law, delta, b, q, condition=condition, rows=free_rows
    )
    if pressed_tables:
        got, tabled = pressed_tabulated(law, delta, b, q, condition=condition, rows=rows)
        values[np.ix_(list(rows), np.flatnonzero(tabled))] = got[:, tabled]
        inside |= tabled
    rest = np.flatnonzero(~inside)
    if rest.size:
        exact = integrated_impact(law, delta[rest], b[rest], q[rest], condition=condition)
        values[:, rest] = np.stack(exact)
    tau_c, e, z_max, peak = values
    if law == "linear":
        tau_c, e = linear_ends(delta, b, condition=condition)
    free = b == 0
    # without pressing force a clipped coast keeps its speed: the force condition's e
    released = "force" if condition == "clipped" else condition
    if free.all():  # no copies
        free = slice(None)
    elif not free.any():
        return tau_c, e, z_max, peak
    if law == "hunt-crossley":
        e[free] = hunt_crossley_restitution(delta[free])
    if law == "tsuji":
        e[free] = linear_free_restitution(tsuji_zeta(delta[free], q[free]), condition=released)
    return tau_c, e, z_max, peak


def impact(
    law: str,
    *,
    stiffness: ArrayLike,
    damping: ArrayLike,
    mass: ArrayLike,
    speed: ArrayLike,
    force: ArrayLike = 0.0,
    exponent: ArrayLike = 1.5,
    condition: str,
) -> NonlinearImpact:
    r"""Contact time, restitution, maximum penetration and peak force of one impact.

    A body of mass ``mass`` hits the contact element at ``speed`` under the pressing force
    ``force`` (SI units, or any consistent set); ``m d'' = F - F_law(d, d')`` while in
    contact, :math:`d(0) = 0`, :math:`d'(0) = v_0`.

    Parameters
    ----------
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
        The contact force: :math:`k d + c d'`, :math:`k d^p + c d'`,
        :math:`k d^p (1 + \lambda d')`, :math:`k d^p + \alpha\sqrt{mk}\, d^{(p-1)/2} d'`,
        :math:`k (d^{3/2} + \tfrac32 A d^{1/2} d')`.
    stiffness, damping, mass, speed, force : float or array_like
        ``k > 0``; the law's damping parameter ``c``, ``lambda``, ``alpha`` or ``A``
        (``>= 0``); ``m > 0``; ``v0 > 0``; ``F >= 0``. Arrays broadcast.
    exponent : float or array_like
        ``p >= 1`` of ``"hertz-linear"``, ``"hunt-crossley"`` and ``"tsuji"``; ignored by
        ``"linear"`` and ``"viscoelastic"``.
    condition : {"position", "force", "clipped"}
        Contact while ``d > 0``; or while the contact force is compressive (where the
        force is zero at touch: until it first returns to zero after being positive);
        or ``"clipped"``, the engines' contact: the force :math:`\max(0, F_{law})` acts
        while ``d > 0``, so where it would turn tensile the body coasts inside the
        overlap under the pressing force alone, the force may come back (re-engage),
        and the contact ends at ``d = 0`` (LAMMPS ``limit_damping``, Chrono's
        ``if (forceN < 0) forceN = 0``, Drake's :math:`(1 + d\,\dot x)_+`; restitution is
        the speed at ``d = 0``).

    Returns
    -------
    NonlinearImpact
        ``contact_time = inf`` and ``restitution = 0`` where the body sticks. A call
        with at least :data:`TABLE_MIN` unpressed elements of one exponent reads them
        from :func:`free_table`, one with at least :data:`PRESSED_MIN` pressed elements
        of one exponent (laws other than ``"linear"``, position and force conditions)
        reads those from :func:`pressed_table` (both agree with the integration to
        1e-10; elements next to the stick boundary or outside the tables' range are
        integrated): the same inputs in a smaller call may differ at that level.

    Examples
    --------
    The linear law is the linear contact of :func:`~impactsym.contact.physical_contact`:

    >>> r = impact("linear", stiffness=1e4, damping=20.0, mass=1.0, speed=1.0,
    ...            condition="position")
    >>> from impactsym.contact import physical_contact
    >>> r.restitution == physical_contact(1.0, 1e4, 20.0, 1.0, condition="position").restitution
    True

    Hunt–Crossley without pressing force restitutes :math:`(1 + W_0(-(1+s)e^{-(1+s)}))/s`
    for :math:`s = \lambda v_0`, whatever ``k`` and ``p``:

    >>> round(impact("hunt-crossley", stiffness=1e6, damping=2.083, mass=0.1, speed=1.0,
    ...              condition="force").restitution, 4)
    0.3999

    Clipped, the force of a pressed Tsuji contact ends at 0.529 of the impact speed, then
    the body coasts out of the overlap against the pressing force, leaving later and
    slower:

    >>> kw = dict(stiffness=2000.0, damping=0.5, mass=0.5, speed=1.5, force=1.0)
    >>> f, c = (impact("tsuji", condition=x, **kw) for x in ("force", "clipped"))
    >>> round(f.restitution, 4), round(c.restitution, 4), bool(c.contact_time > f.contact_time)
    (0.5292, 0.4992, True)
    """
    check_law(law)
    check_law_condition(condition)
    values = {
        name: real_array(name, value, lower=lower, strict=strict)
        for name, value, lower, strict in (
            ("stiffness", stiffness, 0.0, True),
            ("damping", damping, 0.0, False),
            ("mass", mass, 0.0, True),
            ("speed", speed, 0.0, True),
            ("force", force, 0.0, False),
            ("exponent", exponent, 1.0, False),
        )
    }
    scalar = all(flag for _, flag in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    k, c, m, v0, F, p = (np.broadcast_to(a, shape).ravel() for a, _ in values.values())
    T, L, delta, b, q = normalize(law, k, c, m, v0, F, p)
    if law == "linear":
        released = "force" if condition == "clipped" else condition
        exact = physical_contact(m, k, c, v0, F, condition=released)
        t_c, e = np.asarray(exact.contact_time), np.asarray(exact.restitution)
        tau_c = np.asarray(exact.normalized_contact_time)
        if condition == "clipped":
            tau_c, e = clipped_linear(tau_c, e, delta, b)
            with np.errstate(over="ignore"):
                t_c = tau_c * T
        (z_max, peak), inside = tabulated(law, delta, b, q, condition=condition, rows=(2, 3))
        rest = np.flatnonzero(~inside)
        if rest.size and condition != "clipped":  # the extrema in closed form
            z_max[rest], peak[rest] = linear_extrema(delta[rest], b[rest], tau_c[rest])
        elif rest.size:
            end = np.where(np.isinf(tau_c), np.inf, np.nan)
            run = integrate(law, delta[rest], b[rest], q[rest], condition=condition,
                            end_time=end[rest])  # fmt: skip
            z_max[rest], peak[rest] = run.z_max, run.peak
        pressing = np.asarray(exact.f)
    else:
        tau_c, e, z_max, peak = normalized_impact(
            law, delta, b, q, condition=condition, pressed_tables=True
        )
        with np.errstate(over="ignore"):
            t_c = tau_c * T
        pressing = b
    unit = m * v0 / T
    fields = {
        "damping_number": delta,
        "pressing_number": pressing,
        "time_scale": T,
        "length_scale": L,
        "contact_time": t_c,
        "restitution": e,
        "max_penetration": z_max * L,
        "peak_force": peak * unit,
    }
    return NonlinearImpact(
        law=law,
        condition=condition,
        **{
            name: finish(np.asarray(v, dtype=float).reshape(shape), scalar)
            for name, v in fields.items()
        },
    )
