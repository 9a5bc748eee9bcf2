r"""The stick/release boundary of every contact law: the paper's Fig. 1b for each law.

**What.** For a damping number :math:`\delta` of a law of :mod:`impactsym.contact.laws`
(``D``, ``s``, ``alpha`` or ``beta``), :func:`law_stick_boundary` returns the pressing
number :math:`f^*(\delta)` at which the body starts to stick: it releases for
:math:`f < f^*` and sticks at :math:`f^*` and a little above (``docs/physics.md``,
"Nonlinear contact laws", *Stick boundary and bounce sequence*). For ``"linear"`` this is
the inverse of :func:`~impactsym.contact.api.stick_boundary`, :math:`D^*(f^*(D)) = D`.

**Which equation.** Sticking is the verdict of one exact impact
(:func:`~impactsym.contact.lawnumbers.law_impact`): :math:`z'' = b - \varphi(z, z')`,
:math:`z(0) = 0`, :math:`z'(0) = 1` never ends under the contact condition. No closed
boundary equation is known for the nonlinear laws, so the boundary is the root of that
verdict in ``f``.

**Why this numerics.** The verdict is a step function of ``f``, so no Newton or Illinois
iteration applies; bisection would need about 35 impacts per point. Instead every pass
evaluates :data:`SECTIONS` ``- 1`` interior trial values per point in one vectorized call of
the integrator (whose cost hardly grows with the number of elements on small arrays: it
is one loop over steps on whole arrays), so each pass shrinks the bracket
:data:`SECTIONS`-fold in :math:`\ln f`: about nine passes from a bracket of one decade
to a relative width of :math:`10^{-10}`. The first bracket comes from ``f = 0`` and
``f = 1``, then from powers of ten upwards (while the body releases) or downwards
(while it sticks), never below :data:`F_MIN`: at tiny pressing numbers a heavily damped
body creeps towards rest for a very long normalized time, and the integration with it.
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.lawnumbers import law_impact, law_inputs
from impactsym.validation import finish

ArrayLike = float | np.ndarray

#: The first bracket: f = 0 and 1, then powers of ten (SCAN per call) up to F_MAX or down
#: to F_MIN.
F_MIN, F_MAX, SCAN = 1e-12, 1e12, 3
#: The lowest f tried for the linear law (its closed forms; D* = f^(-1/4)/2 there).
F_MIN_LINEAR = 1e-200
#: Sub-intervals of the bracket per pass (interior trial values + 1).
SECTIONS = 16


def _sticks(law: str, delta, f, q, condition: str) -> np.ndarray:
    return np.isinf(law_impact(law, delta, f, q, condition=condition)[0])


def law_stick_boundary(
    law: str,
    damping_number: ArrayLike,
    *,
    exponent: ArrayLike = 1.5,
    condition: str,
    rtol: float = 1e-10,
) -> ArrayLike:
    r"""Pressing number :math:`f^*(\delta)` at which the body starts to stick.

    Parameters
    ----------
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
        The contact law (:mod:`impactsym.contact.laws`).
    damping_number : float or array_like
        The law's damping number :math:`\delta \ge 0`: ``D`` (linear, hertz-linear),
        ``s = lambda v0`` (Hunt–Crossley), ``alpha`` (Tsuji), ``beta = 3A/(2T)``
        (viscoelastic).
    exponent : float or array_like
        ``p >= 1`` of the laws that have one; broadcasts with ``damping_number``.
    condition : {"position", "force", "clipped"}
        How the contact ends (``"clipped"``: the engines' force :math:`\max(0, F)` on the
        overlap, :func:`~impactsym.contact.nonlinear.impact`); for ``"linear"`` clipped,
        the body sticks where the force-condition release speed is below :math:`8D^2 f`.
    rtol : float
        Relative width of the final bracket, in ``[1e-14, 1e-2]``.

    Returns
    -------
    float or ndarray
        :math:`f^*` (the law's pressing number: :math:`F_0/(c v_0)` for ``"linear"``,
        :math:`F_0 T/(m v_0)` otherwise); ``0`` where the body sticks already without
        pressing force, ``inf`` where :math:`\delta = 0` (no dissipation: it never
        sticks). The upper end of a bracket of relative width ``rtol`` around the change
        of the verdict.

    Notes
    -----
    The accuracy is that of the sticking verdict: under every condition it agrees with
    an independent integration to :math:`10^{-4}` (the tests' resolution; near the force
    condition's boundary the force dips below zero inside one step, which the kernel
    finds by locating the force minimum in the step, ``docs/physics.md``).

    Raises
    ------
    ValueError
        Where the body still releases at ``f = F_MAX`` (a damping number so small that
        the boundary lies beyond the scan), or sticks at ``F_MIN`` but not at 0 with a
        boundary below it.

    Examples
    --------
    The linear law inverts the paper's boundary :math:`D^*(f)`:

    >>> from impactsym.contact import stick_boundary
    >>> f_star = law_stick_boundary("linear", 0.5, condition="position")
    >>> round(stick_boundary(f_star, condition="position"), 8)
    0.5
    >>> law_stick_boundary("tsuji", [0.0, 2.5], condition="position")  # zeta >= 1 at f = 0
    array([inf,  0.])
    """
    (delta,), q, shape, scalar = law_inputs(
        law, condition=condition, exponent=exponent, damping_number=damping_number
    )
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 1e-14 <= rtol <= 1e-2:
        raise ValueError(f"rtol must be a float in [1e-14, 1e-2], got {rtol!r}")
    result = np.full(delta.shape, np.inf)
    todo = np.flatnonzero(delta > 0)
    if todo.size:
        result[todo] = _boundary(law, delta[todo], q[todo], condition, rtol)
    return finish(result.reshape(shape), scalar)


def _boundary(law: str, delta, q, condition: str, rtol: float) -> np.ndarray:
    """f* for damping numbers > 0 (flat arrays)."""
    n = delta.size
    both = _sticks(law, np.repeat(delta, 2), np.tile([0.0, 1.0], n), np.repeat(q, 2), condition)
    at_zero, at_one = both[0::2], both[1::2]
    result = np.zeros(n)
    lo, hi = np.zeros(n), np.ones(n)
    # upward from f = 1 while it releases, downward while it sticks (never below F_MIN;
    # the closed forms of the linear law are fast anywhere: down to F_MIN_LINEAR)
    floor = F_MIN_LINEAR if law == "linear" else F_MIN
    for up in (True, False):
        rows = np.flatnonzero(~at_zero & (at_one != up))
        current = np.ones(rows.size)
        while rows.size:
            limit = current >= F_MAX if up else current <= floor
            if limit.any():
                i = rows[int(np.argmax(limit))]
                where = f"releases at f = {F_MAX:g}" if up else f"sticks at f = {floor:g}"
                raise ValueError(
                    f"law_stick_boundary({law!r}): with damping number {delta[i]!r} the body "
                    f"still {where} ({condition} condition); its stick boundary lies beyond "
                    "the scan"
                )
            steps = 10.0 ** (np.arange(1, SCAN + 1) if up else -np.arange(1, SCAN + 1))
            trial = current[:, None] * steps
            stuck = _sticks(
                law,
                np.repeat(delta[rows], SCAN),
                trial.ravel(),
                np.repeat(q[rows], SCAN),
                condition,
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
        stuck = _sticks(
            law,
            np.repeat(delta[rows], SECTIONS - 1),
            trial.ravel(),
            np.repeat(q[rows], SECTIONS - 1),
            condition,
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
