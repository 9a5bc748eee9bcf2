r"""The damping parameter of a contact law that delivers a coefficient of restitution.

:func:`damping_for` inverts :func:`~impactsym.contact.nonlinear.impact` in the law's
damping number (``docs/physics.md``, "Nonlinear contact laws"):

* Hunt–Crossley without pressing force: the exact inverse of the Lambert-W restitution
  (:func:`~impactsym.contact.lawclosed.hunt_crossley_parameter`);
* the linear and (through the Tsuji map) the Tsuji contact without pressing force: the
  inverse of the linear contact's restitution
  (:func:`~impactsym.contact.lawclosed.linear_damping_ratio`);
* everywhere else a bracketed root of the exact restitution (the closed forms of the
  linear contact, the Tsuji map, or the order-8 integration; without pressing force, in
  a call of at least :data:`~impactsym.contact.nonlinear.TABLE_MIN` designs of one
  exponent, the Hertz-linear and viscoelastic restitution of the table of
  :func:`~impactsym.contact.nonlinear.free_table`, the one
  :func:`~impactsym.contact.nonlinear.impact` then uses; with a pressing force, in a
  call of at least :data:`~impactsym.contact.nonlinear.PRESSED_MIN` pressed designs of
  one exponent, the restitution of :func:`~impactsym.contact.nonlinear.pressed_table`),
  which falls monotonically
  from 1 at zero damping: the bracket grows by factors of 4, then Illinois steps (bisection
  where the upper end sticks) shrink it to a relative width of :math:`10^{-13}`.

Under the force condition with a pressing force the restitution does not fall to zero
continuously: at the stick boundary it jumps from a positive value to 0 (the force
touches zero with the body still moving). Targets below that value cannot be reached by
any damping and are refused with the reason and the lowest value that can. Under the
``"clipped"`` condition the departure speed at ``z = 0`` falls continuously to 0 at its
stick boundary (the coast's free flight just reaches ``z = 0``), so every target is
reachable; without pressing force a clipped coast keeps the force condition's speed,
whose inverses (linear, Tsuji map, Hunt–Crossley) apply unchanged.
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.api import restitution as linear_restitution
from impactsym.contact.lawclosed import (
    hunt_crossley_parameter,
    linear_damping_ratio,
    tsuji_zeta,
)
from impactsym.contact.laws import contact_law
from impactsym.contact.nonlinear import (
    check_law_condition,
    clipped_linear,
    normalize,
    normalized_impact,
    pressed_mask,
    pressed_tabulated,
    table_mask,
    tabulated,
)
from impactsym.validation import broadcast, finish, real_array

ArrayLike = float | np.ndarray

#: Damping numbers searched before a target is declared out of reach.
DELTA_MAX = 1e6
_WIDTH = 1e-13


def restitution_of(law: str, delta, b, q, *, condition: str) -> np.ndarray:
    """The exact restitution at damping numbers ``delta`` (flat arrays, ``delta > 0``)."""
    if law == "linear":
        released = "force" if condition == "clipped" else condition
        with np.errstate(divide="ignore", invalid="ignore"):
            e = np.asarray(linear_restitution(delta, b / (2.0 * delta), condition=released))
            if condition == "clipped":
                tau = np.where(e > 0, 0.0, np.inf)  # only the sticking verdict is used
                e = clipped_linear(tau, e, delta, b)[1]
        return e
    return normalized_impact(law, delta, b, q, condition=condition)[1]


def design_number(law: str, target, b, q, *, condition: str) -> np.ndarray:
    """The damping number at which the restitution is ``target`` (flat arrays)."""
    n = target.size
    result = np.zeros(n)
    todo = target < 1.0
    free = todo & (b == 0)
    if law == "hunt-crossley":
        result[free] = hunt_crossley_parameter(target[free])
        todo &= ~free
    elif law in ("linear", "tsuji") and free.any():  # the linear contact inverted
        # without pressing force a clipped coast keeps the force condition's speed
        released = "force" if condition == "clipped" else condition
        zeta = linear_damping_ratio(target[free], condition=released)
        result[free] = zeta if law == "linear" else zeta * np.sqrt(2.0 * (q[free] + 1.0))
        todo &= ~free
    idx = np.flatnonzero(todo)
    if idx.size == 0:
        return result
    t, bb, qq = target[idx], b[idx], q[idx]
    # unpressed designs of a large call invert the table of the unpressed impact, pressed
    # ones those of the pressed impact (decided once for the call)
    free = table_mask(bb, qq) if law in ("hertz-linear", "viscoelastic") else None
    pressed = pressed_mask(law, bb, qq, condition=condition)

    def e_of(delta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        out = np.full(delta.shape, np.nan)
        done = np.zeros(delta.shape, dtype=bool)
        for mask, table in ((free, tabulated), (pressed, pressed_tabulated)):
            use = np.zeros(delta.shape, dtype=bool) if mask is None else mask[rows]
            if use.any():
                r = rows[use]
                (e,), inside = table(law, delta[use], bb[r], qq[r], condition=condition,
                                     mask=np.ones(r.size, dtype=bool), rows=(1,))  # fmt: skip
                at = np.flatnonzero(use)[inside]
                out[at], done[at] = e[inside], True
        if law == "tsuji":  # unpressed, the map: restitution of the linear contact
            free_map = ~done & (bb[rows] == 0)
            zeta = tsuji_zeta(delta[free_map], qq[rows][free_map])
            released = "force" if condition == "clipped" else condition
            out[free_map] = linear_restitution(zeta, 0.0, condition=released)
            done |= free_map
        other = np.flatnonzero(~done)
        if other.size:
            r = rows[other]
            out[other] = restitution_of(law, delta[other], bb[r], qq[r], condition=condition)
        return out

    lo, hi = np.zeros(idx.size), np.ones(idx.size)
    e_lo, e_hi = np.ones(idx.size), e_of(hi, np.arange(idx.size))
    high = e_hi > t
    while high.any():
        rows = np.flatnonzero(high)
        if hi[rows].max() >= DELTA_MAX:
            bad = rows[np.argmax(hi[rows])]
            raise ValueError(
                f"restitution {float(t[bad])!r} is out of reach of the {law} contact under the "
                f"{condition} condition: it stays at {float(e_hi[bad])!r} or above up to damping "
                f"number {hi[bad]:g}; ask for a larger restitution"
            )
        lo[rows], e_lo[rows] = hi[rows], e_hi[rows]
        hi[rows] *= 4.0
        e_hi[rows] = e_of(hi[rows], rows)
        high[rows] = e_hi[rows] > t[rows]
    side = np.zeros(idx.size, dtype=int)
    g_lo, g_hi = e_lo - t, e_hi - t
    active = np.ones(idx.size, dtype=bool)
    for _ in range(200):
        rows = np.flatnonzero(active)
        if rows.size == 0:
            break
        sticking = e_hi[rows] == 0
        with np.errstate(all="ignore"):
            trial = (lo[rows] * g_hi[rows] - hi[rows] * g_lo[rows]) / (g_hi[rows] - g_lo[rows])
        mid = 0.5 * (lo[rows] + hi[rows])
        bad = sticking | ~np.isfinite(trial) | (trial <= lo[rows]) | (trial >= hi[rows])
        trial = np.where(bad, mid, trial)
        e_t = e_of(trial, rows)
        g_t = e_t - t[rows]
        above = g_t > 0
        r_up, r_down = rows[above], rows[~above]
        lo[r_up], g_lo[r_up], e_lo[r_up] = trial[above], g_t[above], e_t[above]
        hi[r_down], g_hi[r_down], e_hi[r_down] = trial[~above], g_t[~above], e_t[~above]
        g_hi[r_up] = np.where(side[r_up] == 1, 0.5 * g_hi[r_up], g_hi[r_up])
        g_lo[r_down] = np.where(side[r_down] == -1, 0.5 * g_lo[r_down], g_lo[r_down])
        side[r_up], side[r_down] = 1, -1
        narrow = (hi[rows] - lo[rows] <= _WIDTH * hi[rows]) | (g_t == 0)
        active[rows[narrow]] = False
    jump = (e_hi == 0) & (g_lo > 1e-9)
    if jump.any():
        bad = np.flatnonzero(jump)[0]
        raise ValueError(
            f"restitution {float(t[bad])!r} is out of reach of the {law} contact under the "
            f"{condition} condition with this pressing force: the body sticks for damping "
            f"numbers above {hi[bad]:.10g}, where the restitution still is {e_lo[bad]:.6g}; "
            "a smaller pressing force, or the position condition, reaches lower values"
        )
    result[idx] = np.where(np.abs(g_lo) <= np.abs(g_hi), lo, hi)
    return result


def damping_for(
    law: str,
    *,
    restitution: ArrayLike,
    stiffness: ArrayLike,
    mass: ArrayLike,
    speed: ArrayLike,
    force: ArrayLike = 0.0,
    exponent: ArrayLike = 1.5,
    condition: str,
) -> ArrayLike:
    r"""The law's damping parameter (``c``, ``lambda``, ``alpha`` or ``A``) at which
    :func:`~impactsym.contact.nonlinear.impact` restitutes ``restitution``.

    Parameters
    ----------
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
    restitution : float or array_like
        Target coefficient of restitution, ``0 < e <= 1``.
    stiffness, mass, speed, force, exponent, condition
        As in :func:`~impactsym.contact.nonlinear.impact`.

    Returns
    -------
    float or ndarray
        The damping parameter, broadcast over the inputs; ``0`` for ``e = 1``. Large
        unpressed or pressed calls invert the tables of
        :func:`~impactsym.contact.nonlinear.impact` (module docstring): the same target
        in a smaller call may differ at 1e-9.

    Raises
    ------
    ValueError
        For an unknown law (listing the laws), bad input, or a target no damping reaches
        (saying why and what would reach it).

    Examples
    --------
    Hunt–Crossley's exact :math:`\lambda v_0` for e = 0.2 (4.919, where the usual design
    formulas give 0.672, 0.547 or 0.156):

    >>> round(damping_for("hunt-crossley", restitution=0.2, stiffness=1e5, mass=1.0,
    ...                   speed=2.0, condition="force") * 2.0, 3)
    4.919
    """
    law = contact_law(law).name
    check_law_condition(condition)
    values = {
        name: real_array(name, value, lower=lower, strict=strict)
        for name, value, lower, strict in (
            ("restitution", restitution, 0.0, True),
            ("stiffness", stiffness, 0.0, True),
            ("mass", mass, 0.0, True),
            ("speed", speed, 0.0, True),
            ("force", force, 0.0, False),
            ("exponent", exponent, 1.0, False),
        )
    }
    e_arr = values["restitution"][0]
    if (e_arr > 1.0).any():
        raise ValueError(
            f"restitution must be <= 1 (no contact law here adds energy), got "
            f"{float(e_arr[e_arr > 1.0].flat[0])!r}"
        )
    scalar = all(flag for _, flag in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    e, k, m, v0, F, p = (np.broadcast_to(a, shape).ravel() for a, _ in values.values())
    T, _, _, b, q = normalize(law, k, np.ones_like(k), m, v0, F, p)
    delta = design_number(law, e, b, q, condition=condition)
    parameter = {
        "linear": 2.0 * delta * np.sqrt(k) * np.sqrt(m),
        "hertz-linear": 2.0 * delta * m / T,
        "hunt-crossley": delta / v0,
        "tsuji": delta,
        "viscoelastic": 2.0 * delta * T / 3.0,
    }[law]
    return finish(parameter.reshape(shape), scalar)
