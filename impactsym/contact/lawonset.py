r"""Where a sticking verdict sets in along the pressing number: multisection on arrays.

**What.** :func:`stick_onset` returns, for each damping number :math:`\delta > 0` of a
contact law, the pressing number :math:`f^*` at which a given verdict ``sticks(delta, f,
q)`` turns from release to stick (``docs/physics.md``, "Nonlinear contact laws", *Stick
boundary and bounce sequence*). :func:`~impactsym.contact.lawstick.law_stick_boundary`
asks it with the verdict of one exact impact; the tables of the pressed impact
(:mod:`impactsym.contact.lawpressed`) ask it with the plain order-8 integration, which
they must not consult themselves.

**Why this numerics.** The verdict is a step function of ``f``, so no Newton or Illinois
iteration applies; bisection would need about 35 impacts per point. Instead every pass
evaluates :data:`SECTIONS` ``- 1`` interior trial values per point in one vectorized call
of the verdict (whose cost hardly grows with the number of elements on small arrays: it
is one loop over steps on whole arrays), so each pass shrinks the bracket
:data:`SECTIONS`-fold in :math:`\ln f`: about nine passes from a bracket of one decade to
a relative width of :math:`10^{-10}`. The first bracket comes from ``f = 0`` and
``f = 1``, then from powers of ten upwards (while the body releases) or downwards (while
it sticks), never below ``floor``: at tiny pressing numbers a heavily damped body creeps
towards rest for a very long normalized time, and the integration with it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: The first bracket: f = 0 and 1, then powers of ten (SCAN per call) up to F_MAX.
F_MAX, SCAN = 1e12, 3
#: Sub-intervals of the bracket per pass (interior trial values + 1).
SECTIONS = 16

Verdict = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def stick_onset(
    sticks: Verdict,
    delta: np.ndarray,
    q: np.ndarray,
    *,
    floor: float,
    rtol: float,
    label: str,
    below_floor: float | None = None,
) -> np.ndarray:
    """``f*`` for damping numbers ``delta > 0`` and exponents ``q`` (flat arrays): ``0``
    where ``sticks(delta, 0, q)``, else the upper end of a bracket of relative width
    ``rtol`` around the change of the verdict. ``label`` names the caller in errors. A
    body that still sticks at ``floor`` (but not at 0) raises, or gets ``below_floor``
    if given; one that still releases at :data:`F_MAX` raises.

    >>> onset = stick_onset(lambda d, f, q: f >= 0.25 / d, np.array([1.0, 2.0]),
    ...                     np.ones(2), floor=1e-12, rtol=1e-12, label="demo")
    >>> np.round(onset, 10).tolist()
    [0.25, 0.125]
    """
    n = delta.size
    both = sticks(np.repeat(delta, 2), np.tile([0.0, 1.0], n), np.repeat(q, 2))
    at_zero, at_one = both[0::2], both[1::2]
    result = np.zeros(n)
    lo, hi = np.zeros(n), np.ones(n)
    # upward from f = 1 while it releases, downward while it sticks (never below floor)
    for up in (True, False):
        rows = np.flatnonzero(~at_zero & (at_one != up))
        current = np.ones(rows.size)
        while rows.size:
            limit = current >= F_MAX if up else current <= floor
            if below_floor is not None and not up and limit.any():
                result[rows[limit]] = below_floor
                at_zero[rows[limit]] = True  # no bisection either
                rows, current = rows[~limit], current[~limit]
                continue
            if limit.any():
                i = rows[int(np.argmax(limit))]
                where = f"releases at f = {F_MAX:g}" if up else f"sticks at f = {floor:g}"
                raise ValueError(
                    f"{label}: with damping number {float(delta[i])!r} the body still {where}; "
                    "its stick boundary lies beyond the scan"
                )
            steps = 10.0 ** (np.arange(1, SCAN + 1) if up else -np.arange(1, SCAN + 1))
            trial = current[:, None] * steps
            stuck = sticks(
                np.repeat(delta[rows], SCAN), trial.ravel(), np.repeat(q[rows], SCAN)
            ).reshape(rows.size, SCAN)
            change = stuck if up else ~stuck
            found = change.any(axis=1)
            j = np.argmax(change, axis=1)
            take = np.arange(rows.size)
            before = np.where(j > 0, trial[take, np.maximum(j - 1, 0)], current)
            if up:
                lo[rows[found]], hi[rows[found]] = before[found], trial[take, j][found]
            else:
                lo[rows[found]], hi[rows[found]] = trial[take, j][found], before[found]
            current = trial[:, -1][~found]
            rows = rows[~found]
    rows = np.flatnonzero(~at_zero)
    lo, hi = lo[rows], hi[rows]
    fractions = np.arange(1, SECTIONS) / SECTIONS
    while rows.size:
        trial = lo[:, None] * (hi / lo)[:, None] ** fractions
        stuck = sticks(
            np.repeat(delta[rows], SECTIONS - 1),
            trial.ravel(),
            np.repeat(q[rows], SECTIONS - 1),
        ).reshape(rows.size, SECTIONS - 1)
        # the new bracket: the last release below the first sticking trial
        onset = np.where(stuck.any(axis=1), np.argmax(stuck, axis=1), SECTIONS - 1)
        take = np.arange(rows.size)
        new_hi = np.where(onset < SECTIONS - 1, trial[take, np.minimum(onset, SECTIONS - 2)], hi)
        new_lo = np.where(onset > 0, trial[take, np.maximum(onset - 1, 0)], lo)
        lo, hi = new_lo, new_hi
        done = (hi - lo) <= rtol * hi
        result[rows[done]] = hi[done]
        keep = ~done
        rows, lo, hi = rows[keep], lo[keep], hi[keep]
    return result
