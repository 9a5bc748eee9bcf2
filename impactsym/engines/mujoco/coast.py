r"""The coast after a force zero: free flight inside the overlap, stepped by RK4, in closed form.

After the contact force of a MuJoCo contact reaches zero the body may still overlap; it
flies freely (``a = g`` at every stage) until the overlap is gone or the force comes back.
The classical Runge-Kutta step integrates free flight exactly, so the states lie on the
parabola ``X(n) = x + v t + g t^2 / 2``, ``V(n) = v + g t``, ``t = n h``, and the four
stage states of step ``n`` are ``(X, V)``, ``(X + hV/2, V + hg/2)``,
``(X + hV/2 + h^2 g/4, V + hg/2)``, ``(X + hV + h^2 g/2, V + hg)``: every stage's
penetration ``x_j`` and force bound ``g + b v_j + d_hi kbar x_j`` is a quadratic in ``n``.
:func:`coast_steps` finds the first step at which a stage may push again or the state has
left the overlap, from the roots of these quadratics (the first integer of a union of
intervals is 1 or next to one of their endpoints), so that a slow coast of thousands of
steps costs one evaluation (`docs/physics.md`, *MuJoCo's RK4 step*).
"""

from __future__ import annotations

import numpy as np

__all__ = ["coast_steps"]

#: relative margin by which the conditions are widened (the bound stops early, never late)
_MARGIN = 1e-12


def _roots(a, b, c):
    """Real roots of ``a n^2 + b n + c`` (NaN where absent), two per quadratic."""
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = b * b - 4.0 * a * c
        root = np.sqrt(np.where(disc >= 0, disc, np.nan))
        q = -0.5 * (b + np.copysign(root, b))
        quad = (q / a, c / q)
        lin = -c / b
        return tuple(np.where(a == 0, lin, r) for r in quad)


def coast_steps(
    x: np.ndarray,
    v: np.ndarray,
    gravity: np.ndarray,
    damping: np.ndarray,
    stiffness_bound: np.ndarray,
    timestep: np.ndarray,
) -> np.ndarray:
    """Free RK4 steps before a stage may push again or the overlap is gone (arrays, SI).

    Parameters
    ----------
    x, v
        Penetration (m) and penetration rate (m/s) of the present state.
    gravity, damping
        ``g`` pressing along the normal and ``b``.
    stiffness_bound
        An upper bound of ``d(x) kbar`` over the penetrations (``d_max kbar``).
    timestep
        ``h``.

    Returns
    -------
    numpy.ndarray
        The first ``n >= 1`` at which the state ``n`` has left the overlap (``X(n) < 0``)
        or a stage of step ``n`` has ``x_j >= 0`` and ``g + b v_j + d_hi kbar x_j > 0``
        (float; ``inf`` where neither ever happens). Steps ``0 .. n-1`` are free flight
        provided step 0 is: the bound only stops early, never late.

    >>> float(coast_steps(np.array(0.001), np.array(-0.01), np.array(0.0),
    ...                   np.array(100.0), np.array(100.0), np.array(1e-3)))
    100.0
    """
    h, g = timestep, gravity
    # state n: X = g h^2/2 n^2 + v h n + x, V = g h n + v
    ax, bx, cx = 0.5 * g * h * h, v * h, x
    av, bv = g * h, v
    stages = (
        ((0, 0), 0.0, 0.0),
        ((0.5, 0), 0.5, 0.0),
        ((0.5, 0.25), 0.5, 0.0),
        ((1.0, 0.5), 1.0, 0.0),
    )
    conds = []  # (kind, (a, b, c)): kind 0 -> x_j >= 0 and f_j > 0; 1 -> X < 0
    for (cv, cg), cvel, _ in stages:
        # x_j = X + cv h V + cg h^2 g ;  v_j = V + cvel h g
        xa, xb, xc = ax, bx + cv * h * av, cx + cv * h * bv + cg * h * h * g
        va, vb = av, bv + cvel * h * g
        fa = stiffness_bound * xa
        fb = damping * va + stiffness_bound * xb
        fc = g + damping * vb + stiffness_bound * xc
        conds.append(((xa, xb, xc), (fa, fb, fc)))
    candidates = [np.ones(np.shape(x))]
    polys = [p for pair in conds for p in pair] + [(ax, bx, cx)]
    for a, b, c in polys:
        for r in _roots(np.broadcast_to(a, np.shape(x)), np.broadcast_to(b, np.shape(x)), c):
            base = np.where(np.isfinite(r) & (r >= 1), np.ceil(r), 1.0)
            candidates += [base, base + 1]

    def bounds(a, b, c, n):  # the quadratic at n, less and plus a margin of its terms' size
        terms = (a * n * n, b * n, c)
        value, size = sum(terms), _MARGIN * sum(np.abs(t) for t in terms)
        return value - size, value + size

    best = np.full(np.shape(x), np.inf)
    for n in candidates:
        stop = bounds(ax, bx, cx, n)[0] < 0
        for xq, fq in conds:
            stop |= (bounds(*xq, n)[1] >= 0) & (bounds(*fq, n)[1] > 0)
        best = np.where(stop, np.minimum(best, n), best)
    return best
