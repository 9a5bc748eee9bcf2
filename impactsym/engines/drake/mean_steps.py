r"""Designs on phase-mean functions by steps from starts: Broyden's method, and the walk
along the restitution's contour next to a plateau's edge.

``mean(s, w, rows)`` gives the phase means ``(E, Q)`` (and optionally a third array:
where they hold) of the designs ``(s, w)`` of the targets ``rows``: the damping number
:math:`s = d v` and the step :math:`w = h \sqrt{k/m}` of
:mod:`~impactsym.engines.drake.step_table`, whose tables give the starts and the
Jacobians. The means are continuous but only piecewise smooth (a kink wherever an end
step enters the phase interval, plateaus of the contact time), which is why
:func:`broyden_steps` keeps a Jacobian's row on a plateau and :func:`contour_steps`
brackets the size along ``E = e`` where Broyden's steps stall next to a plateau's edge.
Flat arrays. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["Mean", "broyden_steps", "contour_steps"]

#: ``mean(s, w, rows)``: the phase means ``(E, Q[, holds])`` of the designs ``rows``.
Mean = Callable[..., tuple[np.ndarray, ...]]


def broyden_steps(
    mean: Mean, s: np.ndarray, w: np.ndarray, jac: np.ndarray, e: np.ndarray, q: np.ndarray,
    s_box: tuple[float, float], w_box: tuple[float, float], *, tol: tuple[float, float],
    steps: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Broyden's method on ``(E, Q)(s, w) = (e, q)`` with the phase means ``mean`` from
    the starts ``(s, w)`` (``nan``: none) and their Jacobians ``jac`` (``n x 2 x 2``,
    updated in place), at most ``steps`` calls of ``mean``: the designs ``(s, w)`` and
    where they are done (within ``tol``: of the restitution, and relative of the size;
    and where ``mean`` returns a third array, where that holds). A step that leaves the
    box ``s_box`` x ``w_box`` ends that design's steps. Where a step leaves ``Q``
    unchanged (a plateau) the Jacobian's row of ``Q`` is kept: a zero slope would send
    the next step out of the box, the old slope leads back to the plateau's edge."""
    n = e.size
    done = np.zeros(n, bool)
    live = np.flatnonzero(np.isfinite(s) & np.isfinite(w))
    x = np.stack([s, w], axis=1)
    f_prev = x_prev = None
    for _ in range(steps):
        if live.size == 0:
            break
        e_t, q_t, *settled = mean(x[live, 0], x[live, 1], live)
        f = np.stack([e_t - e[live], q_t - q[live]], axis=1)
        hit = (np.abs(f[:, 0]) <= tol[0]) & (np.abs(f[:, 1]) <= tol[1] * q[live])
        if settled:  # the means hold only where they say so
            hit &= settled[0]
        done[live[hit]] = True
        finite = np.all(np.isfinite(f), axis=1)
        if f_prev is not None:  # Broyden's update of the Jacobian along the last step
            dx, df = x[live] - x_prev, f - f_prev
            num = df - np.einsum("nij,nj->ni", jac[live], dx)
            norm = np.einsum("ni,ni->n", dx, dx)
            with np.errstate(all="ignore"):
                upd = num[:, :, None] * dx[:, None, :] / norm[:, None, None]
            # on a plateau (Q unchanged) the slope of Q is kept: it holds off the plateau
            upd[np.abs(df[:, 1]) <= 1e-13 * q[live], 1, :] = 0.0
            good = np.isfinite(upd).all(axis=(1, 2)) & (norm > 0)
            jac[live[good]] += upd[good]
        keep = ~hit & finite
        live, f = live[keep], f[keep]
        x_prev, f_prev = x[live].copy(), f
        a, b, c, dd = jac[live, 0, 0], jac[live, 0, 1], jac[live, 1, 0], jac[live, 1, 1]
        with np.errstate(all="ignore"):  # (a step that is not finite is refused below)
            det = a * dd - b * c
            step_s = (dd * f[:, 0] - b * f[:, 1]) / det
            step_w = (a * f[:, 1] - c * f[:, 0]) / det
        new = x[live] - np.stack([step_s, step_w], axis=1)
        inside = (
            np.isfinite(new).all(axis=1)
            & (new[:, 0] > s_box[0]) & (new[:, 0] < s_box[1])
            & (new[:, 1] > w_box[0]) & (new[:, 1] < w_box[1])
        )  # fmt: skip
        x[live[inside]] = new[inside]
        live, x_prev, f_prev = live[inside], x_prev[inside], f_prev[inside]
    return x[:, 0], x[:, 1], done


def contour_steps(
    mean: Mean, rows: np.ndarray, s: np.ndarray, w: np.ndarray, jac: np.ndarray,
    e: np.ndarray, q: np.ndarray, w_box: tuple[float, float], *, tol: tuple[float, float],
    steps: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """The designs ``rows`` (of ``mean``'s) that Broyden's steps left, solved along the
    contour ``E = e``: each step moves ``w`` and corrects ``s`` by Newton's step on ``E``
    (the slopes of ``jac``'s first row); ``w`` first walks, the step doubling, until
    ``Q - q`` changes sign (off a plateau of ``Q``, which stalls the secant), then
    Illinois steps in that bracket, at most ``steps`` calls of ``mean``. Returns
    ``(s, w, done)`` (done within ``tol``, as :func:`broyden_steps`); a bracket shut
    without the size meeting its target (the size jumps there) is left undone."""
    n = rows.size
    done = np.zeros(n, bool)
    e_s, e_w = jac[:, 0, 0], jac[:, 0, 1]
    e_t, q_t = mean(s, w, rows)
    f_e, f_q = e_t - e, q_t - q
    a_w, a_f = w.copy(), f_q.copy()  # the end walked from, and the far end once seen
    b_w, b_f = np.full(n, np.nan), np.full(n, np.nan)
    side = np.zeros(n, int)
    step = 1e-6 * w
    live = np.flatnonzero(np.isfinite(f_e) & np.isfinite(f_q))
    for _ in range(steps):
        if live.size == 0:
            break
        bracketed = np.isfinite(b_w[live])
        with np.errstate(all="ignore"):
            falsi = (a_w[live] * b_f[live] - b_w[live] * a_f[live]) / (b_f[live] - a_f[live])
        lo, hi = np.fmin(a_w[live], b_w[live]), np.fmax(a_w[live], b_w[live])
        falsi = np.where((falsi > lo) & (falsi < hi), falsi, 0.5 * (lo + hi))
        walk = a_w[live] + np.sign(a_f[live]) * step[live]  # Q falls with w
        w_new = np.where(bracketed, falsi, walk)
        s_new = s[live] - (f_e[live] + e_w[live] * (w_new - w[live])) / e_s[live]
        inside = np.isfinite(s_new) & (w_new > w_box[0]) & (w_new < w_box[1])
        live, w_new, s_new, bracketed = (a[inside] for a in (live, w_new, s_new, bracketed))
        e_t, q_t = mean(s_new, w_new, rows[live])
        s[live], w[live], f_e[live], f_q[live] = s_new, w_new, e_t - e[live], q_t - q[live]
        fq = f_q[live]
        hit = (np.abs(f_e[live]) <= tol[0]) & (np.abs(fq) <= tol[1] * q[live])
        done[live[hit]] = True
        same = np.sign(fq) == np.sign(a_f[live])
        # walking: on the same side the walk goes on, twice as far; across, the bracket
        walked = ~bracketed & same
        a_w[live[walked]], a_f[live[walked]] = w_new[walked], fq[walked]
        step[live[walked]] *= 2.0
        crossed = ~bracketed & ~same
        i = live[crossed]
        b_w[i], b_f[i], a_w[i], a_f[i] = a_w[i], a_f[i], w_new[crossed], fq[crossed]
        # in the bracket: the end on the trial's side moves (Illinois: the other end's
        # value halves where the same end moved last time too)
        for moved, end_w, end_f, other_f, mark in (
            (bracketed & same, a_w, a_f, b_f, 1),
            (bracketed & ~same, b_w, b_f, a_f, -1),
        ):
            i = live[moved]
            other_f[i] = np.where(side[i] == mark, 0.5 * other_f[i], other_f[i])
            end_w[i], end_f[i], side[i] = w_new[moved], fq[moved], mark
        # a bracket shut without the size meeting its target: the size jumps there
        # (an interval of phases with another end step, narrower than the grid of
        # phase_summary, enters it), the iteration decides
        shut = np.abs(b_w[live] - a_w[live]) <= 1e-15 * a_w[live]
        live = live[~hit & ~shut & np.isfinite(fq) & np.isfinite(f_e[live])]
    return s, w, done
