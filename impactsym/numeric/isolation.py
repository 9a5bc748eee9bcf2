r"""Certified search for the first sign change of a smooth function on many intervals.

NumPy only. Used by :mod:`impactsym.rod.contact_times` for the rod's contact times
(rigid: one reflection interval at a time; finite stiffness: ``[0, t_max]``). On a cell
``[a, b]``, ``h = b - a``, with a rigorous bound ``|g''| <= M`` supplied by the caller
and the values and slopes at the ends,

.. math::

    g \ge \min\bigl(g(a), g(b)\bigr) - \frac{M h^2}{8}, \qquad
    \Bigl|g' - \frac{g'(a) + g'(b)}{2}\Bigr| \le \frac{M h}{2}

(with Taylor lower bounds from either end): a positive lower bound proves the cell
zero-free, a slope of one sign proves it monotone, and an undecided cell is halved.
Why: sampling can miss a dip, these bounds cannot; every cell before the first with
``g(a) > 0 >= g(b)`` is proved zero-free and that one monotone, then refined by
:func:`impactsym.numeric.bracketed_newton`. Only a dip shallower than ``tol``
(``M h^2 / 8 <= tol``) may be passed over; a tangential touch is no sign change. With
``certify=True`` the search also reports the owners on which it *proved* ``g > 0``
(every cell cleared by a bound or by monotonicity, none only for its depth ``tol``).
The argument in full: See `docs/physics.md#cell-search`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.numeric.roots import bracketed_newton

#: Dips of the contact function shallower than this may be passed over.
TOLERANCE = 1e-12


def first_sign_change(
    evaluate: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    bound: Callable[..., np.ndarray],
    nodes: np.ndarray,
    owner: np.ndarray,
    n_owners: int,
    *,
    tol: float = TOLERANCE,
    max_rounds: int = 80,
    max_cells: int = 2**24,
    certify: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """First point where ``g`` goes from ``> 0`` to ``<= 0``, per owner; NaN if none.

    Parameters
    ----------
    evaluate
        ``evaluate(x, owner) -> (g, dg, aux)`` at 1-D arrays (``aux``: one more
        per-point value that the bound needs).
    bound
        ``bound(a, b, owner, aux_a, aux_b, dg_a, dg_b) -> M`` with ``|g''| <= M`` on
        ``[a, b]``.
    nodes, owner
        Initial nodes (sorted within each owner, owners contiguous and ascending) and
        the owner of each; ``g`` must be positive at each owner's first node.
    n_owners
        Number of owners; the result has this length.
    tol, max_rounds, max_cells
        Acceptance depth (see the module notes) and work limits; beyond the limits a
        ``RuntimeError`` is raised, never a guess.
    certify
        Also return ``positive``: per owner, ``True`` where ``g > 0`` is proved on
        the whole span of its nodes (then the root is NaN), ``False`` where a root was
        found or a cell was only accepted for its depth (module notes).

    Returns
    -------
    numpy.ndarray or tuple of numpy.ndarray
        The first sign change per owner (NaN if none); with ``certify``, the pair
        ``(roots, positive)``.

    Examples
    --------
    ``g = cos(x) - c`` with ``|g''| <= 1``: the first zero is ``arccos(c)``, also where
    two coarse nodes would straddle a second zero or none:

    >>> c = np.array([0.5, 0.999])
    >>> def evaluate(x, owner):
    ...     return np.cos(x) - c[owner], -np.sin(x), np.zeros_like(x)
    >>> def bound(a, b, owner, *ends):
    ...     return np.ones_like(a)
    >>> nodes, owner = np.tile([0.0, 7.0], 2), np.repeat([0, 1], 2)
    >>> root = first_sign_change(evaluate, bound, nodes, owner, 2)
    >>> bool(np.allclose(root, np.arccos(c), rtol=0, atol=1e-14))
    True

    With ``certify``: ``cos(x) + 1.5`` is proved positive on ``[0, 7]``; the touch of
    ``cos(x) + 1`` at ``pi`` is no sign change, but not a proof of ``g > 0`` either:

    >>> c = np.array([-1.5, -1.0])
    >>> roots, positive = first_sign_change(evaluate, bound, nodes, owner, 2, certify=True)
    >>> roots.tolist(), positive.tolist()
    ([nan, nan], [True, False])
    """
    result = np.full(n_owners, np.nan)
    # owners where g > 0 is not proved: a cell accepted for its depth only, or g <= 0
    weak = np.zeros(n_owners, dtype=bool)
    if nodes.size == 0:
        return (result, ~weak) if certify else result
    g, dg, aux = evaluate(nodes, owner)
    left = np.flatnonzero(owner[1:] == owner[:-1])
    right = left + 1
    # one row per cell quantity: a, b, g(a), g(b), g'(a), g'(b), aux(a), aux(b)
    cells = np.stack(
        [nodes[left], nodes[right], g[left], g[right], dg[left], dg[right], aux[left], aux[right]]
    )
    own = owner[left]
    found, found_own = [], []  # rows a, b, g(a), g(b) of the decided cells
    for _ in range(max_rounds):
        if own.size > max_cells:
            raise RuntimeError(
                f"first_sign_change: more than {max_cells} cells needed (the bound on "
                "|g''| is too coarse to certify the sign)"
            )
        # cells after a sign change play no part; a cell may start at a zero of g
        # where g rises (g(0) = 0 for finite contact stiffness)
        ga, da = cells[2], cells[4]
        keep = (ga > 0) | ((ga == 0) & (da > 0))
        if not keep.all():
            if certify:
                weak[own[~keep]] = True
            cells, own = cells[:, keep], own[keep]
        if own.size == 0:
            break
        a, b, ga, gb, da, db, ea, eb = cells
        h = b - a
        M = bound(a, b, own, ea, eb, da, db)
        q = M * h * h
        lower = np.maximum(
            np.minimum(ga, gb) - q / 8,
            np.maximum(np.minimum(ga, ga + da * h - q / 2), np.minimum(gb, gb - db * h - q / 2)),
        )
        rising = da + db - M * h > 0
        falling = da + db + M * h < 0
        at_zero = ga == 0  # then g > 0 just after a only if g' > M h / 2, else halve
        lower = np.where(at_zero, np.where(da - q / (2 * h) > 0, np.inf, -np.inf), lower)
        change = (gb <= 0) & ~at_zero
        tiny = (q / 8 <= tol) | (h <= 4 * np.finfo(float).eps * np.maximum(np.abs(a), 1.0))
        proved = (lower > 0) | ((rising | falling) & ~at_zero)
        clear = ~change & (proved | tiny)
        if certify:
            weak[own[(clear & ~proved) | at_zero | (gb <= 0)]] = True
        decided = change & (rising | falling | tiny)
        # the first sign-change cell of each owner (sorted assignment: the smallest
        # a is written last); later cells play no part
        first_change = np.full(n_owners, np.inf)
        idx = np.flatnonzero(change)
        if idx.size:
            idx = idx[np.argsort(-a[idx], kind="stable")]
            first_change[own[idx]] = a[idx]
        relevant = ~clear & (a <= first_change[own])
        undecided = relevant & ~decided
        # an owner is done when its first sign-change cell is decided and no
        # undecided cell lies before it
        pending = np.zeros(n_owners, dtype=bool)
        pending[own[undecided]] = True
        done = relevant & decided & ~pending[own] & (a == first_change[own])
        if done.any():
            found.append(cells[:4, done])
            found_own.append(own[done])
        if not undecided.any():
            break
        carry = relevant & pending[own] & ~undecided  # decided, waiting for earlier cells
        split, own_split = cells[:, undecided], own[undecided]
        mid = 0.5 * (split[0] + split[1])
        gm, dm, em = evaluate(mid, own_split)
        halves = np.empty((8, 2 * mid.size))
        halves[:, : mid.size] = split
        halves[:, mid.size :] = split
        halves[1, : mid.size], halves[0, mid.size :] = mid, mid
        halves[3, : mid.size], halves[2, mid.size :] = gm, gm
        halves[5, : mid.size], halves[4, mid.size :] = dm, dm
        halves[7, : mid.size], halves[6, mid.size :] = em, em
        cells = np.concatenate([halves, cells[:, carry]], axis=1)
        own = np.concatenate([own_split, own_split, own[carry]])
    else:  # pragma: no cover - the halving ends at the tolerance long before
        raise RuntimeError("first_sign_change: cells not decided")
    if not found:
        return (result, ~weak) if certify else result
    lo, hi, g_lo, g_hi = np.concatenate(found, axis=1)
    who = np.concatenate(found_own)
    if who.size:
        cache: dict = {}

        def g_only(x, w):
            value, slope, _ = evaluate(x, w.astype(np.int64))
            cache["x"], cache["slope"] = x, slope
            return value

        def dg_only(x, w):
            if cache.get("x") is x:
                return cache["slope"]
            return evaluate(x, w.astype(np.int64))[1]

        result[who] = bracketed_newton(
            g_only, dg_only, lo, hi, [who.astype(np.float64)], g_lo=g_lo, g_hi=g_hi
        )
    if certify:
        return result, ~weak & np.isnan(result)
    return result
