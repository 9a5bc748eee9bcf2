r"""A bracketed secant for a root in the touch phase, vectorized over brackets.

MuJoCo's Euler phase summary (:mod:`~impactsym.engines.mujoco.discrete`) locates two
kinds of phase by it: a jump of the end step, a root of the continuous end value
(:func:`~impactsym.engines.mujoco.euler.euler_end_value`), and a phase where a state's
penetration crosses a kink of the impedance
(:mod:`~impactsym.engines.mujoco.euler_kinks`). Both functions are smooth near their
root, so Illinois steps converge superlinearly; each step also takes a second point a
little beyond the secant point, so that a secant point within that distance of the
root closes the bracket at once instead of creeping up to it from one side.

Internal. Dimensionless (phases in ``[0, 1]``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["SECANT_ROUNDS", "secant_bracket"]

#: Illinois rounds per bracket before bisection takes over
SECANT_ROUNDS = 12


def secant_bracket(
    value: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    a: np.ndarray,
    c: np.ndarray,
    m: np.ndarray,
    rising: np.ndarray,
    width: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Brackets ``[a, c]`` no wider than ``width`` of the root of ``value(i, p, m)``.

    ``value(i, p, m)`` is the function of brackets ``i`` at phases ``p`` (``m``: a
    parameter per bracket passed through, the end step or the state); ``value <= 0``
    holds at ``a`` where ``rising``, at ``c`` elsewhere (``a``, ``c`` are overwritten).
    Illinois steps on ``s value`` (``s = +-1``: negative at ``a``), each with a second
    point ``0.4 width`` from the secant point towards the far end of the bracket, so
    that a secant point within that of the root closes the bracket at once; at most
    ``SECANT_ROUNDS`` rounds, then bisection. Returns ``(a, c, ok)``; ``ok`` where the
    bracket closed with the sign change kept (else ``a, c`` are returned unchanged).
    """
    a0, c0 = a.copy(), c.copy()
    n = a.size
    idx = np.arange(n)
    sign = np.where(rising, 1.0, -1.0)

    def on_a_side(h, j):
        return (h <= 0) == rising[j]

    both = value(np.concatenate([idx, idx]), np.concatenate([a, c]), np.concatenate([m, m]))
    ok = on_a_side(both[:n], idx) & ~on_a_side(both[n:], idx)
    fa, fc = sign * both[:n], sign * both[n:]
    live = np.flatnonzero(ok & (c - a > width))
    side = np.zeros(n)  # which end was kept last (-1: a, +1: c) for the Illinois halving
    for r in range(SECANT_ROUNDS + 60):
        if live.size == 0:
            break
        al, cl, fal, fcl, w = a[live], c[live], fa[live], fc[live], width[live]
        x = 0.5 * (al + cl)
        if r < SECANT_ROUNDS:
            with np.errstate(all="ignore"):
                sec = cl - fcl * (cl - al) / (fcl - fal)
            x = np.where(np.isfinite(sec), sec, x)
        x = np.clip(x, al + 0.05 * w, cl - 0.05 * w)
        # the second point: towards the larger part of the bracket
        toward_c = (cl - x) > (x - al)
        x2 = np.where(toward_c, np.minimum(x + 0.4 * w, cl - 0.01 * w),
                      np.maximum(x - 0.4 * w, al + 0.01 * w))  # fmt: skip
        lo_pt, hi_pt = np.minimum(x, x2), np.maximum(x, x2)
        f = value(np.concatenate([live, live]), np.concatenate([lo_pt, hi_pt]),
                  np.concatenate([m[live], m[live]]))  # fmt: skip
        h_lo, h_hi = f[: live.size], f[live.size :]
        # the new bracket: [a, lo], [lo, hi] or [hi, c] by the sides
        in_left = ~on_a_side(h_lo, live)
        in_mid = ~in_left & ~on_a_side(h_hi, live)
        s = sign[live]
        new_a = np.where(in_left, al, np.where(in_mid, lo_pt, hi_pt))
        new_c = np.where(in_left, lo_pt, np.where(in_mid, hi_pt, cl))
        new_fa = np.where(in_left, fal, np.where(in_mid, s * h_lo, s * h_hi))
        new_fc = np.where(in_left, s * h_lo, np.where(in_mid, s * h_hi, fcl))
        # Illinois: an end kept twice in a row has its value halved
        kept = np.where(in_left, -1.0, np.where(in_mid, 0.0, 1.0))
        twice = (kept != 0) & (kept == side[live])
        new_fa = np.where(twice & (kept == -1.0), 0.5 * new_fa, new_fa)
        new_fc = np.where(twice & (kept == 1.0), 0.5 * new_fc, new_fc)
        side[live] = kept
        a[live], c[live], fa[live], fc[live] = new_a, new_c, new_fa, new_fc
        live = live[(c[live] - a[live]) > width[live]]
    ok &= (c - a) <= width
    return np.where(ok, a, a0), np.where(ok, c, c0), ok
