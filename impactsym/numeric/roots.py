"""Vectorized bracketed root finders (NumPy only).

* :func:`bracketed_newton` polishes many roots at once, each inside its own sign-change
  bracket, with Newton steps that fall back to bisection whenever they would leave the
  bracket (so it converges for every point, even near a double root);
* :func:`bracketed_illinois` does the same without derivatives (regula falsi with the
  Illinois modification);
* :func:`bracketed_newton_scalar` is :func:`bracketed_newton` for one root in plain
  Python floats, for callers that polish one root at a time (an event loop), where
  NumPy's cost per call on one-element arrays would dominate;
* :func:`newton_system` solves many small nonlinear systems at once (no bracket
  exists in several unknowns) by Newton steps on a finite-difference Jacobian, each
  step bounded in size.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

ArrayFunction = Callable[..., np.ndarray]


def bracketed_newton(
    g: ArrayFunction,
    dg: ArrayFunction | None,
    lo: np.ndarray,
    hi: np.ndarray,
    params: Sequence[np.ndarray] = (),
    *,
    rtol: float = 4e-15,
    max_iter: int = 200,
    g_lo: np.ndarray | None = None,
    g_hi: np.ndarray | None = None,
    start: np.ndarray | None = None,
) -> np.ndarray:
    """Solve ``g(x, *params) = 0`` elementwise for ``x`` in ``[lo, hi]``.

    Every bracket must hold a sign change (``g(lo) * g(hi) <= 0``). Newton steps use
    ``dg``; as in *rtsafe* (Numerical Recipes), a step that would leave the current
    bracket, or that is not less than half the step before last, is replaced by
    bisection, so every element converges at least linearly. Only the elements not
    yet converged are evaluated.

    Parameters
    ----------
    g, dg
        Function and its derivative in ``x``, called as ``g(x, *params)`` on
        1-D arrays. With ``dg=None``, ``g`` returns the pair ``(g, dg)`` (one call per
        iteration where both share work).
    lo, hi
        Bracket ends, broadcastable with ``params``.
    params
        Extra arrays passed to ``g`` and ``dg``, one value per root.
    rtol
        Relative tolerance on the step (absolute near ``x = 0``).
    max_iter
        Iteration limit; more is an error, not a silent result.
    g_lo, g_hi
        ``g`` at ``lo`` and ``hi`` when the caller already has them (exactly as ``g``
        would return them); else evaluated here.
    start
        First iterates inside the brackets (e.g. the secant's root between the ends,
        which saves steps where ``g`` is nearly linear); else the brackets' midpoints.

    >>> root = bracketed_newton(lambda x, c: x**2 - c, lambda x, c: 2 * x,
    ...                         np.zeros(2), np.full(2, 3.0), [np.array([2.0, 4.0])])
    >>> bool(np.abs(root - [np.sqrt(2.0), 2.0]).max() < 1e-15)
    True
    """
    shape = np.broadcast_shapes(np.shape(lo), np.shape(hi), *(np.shape(p) for p in params))
    lo = np.broadcast_to(np.asarray(lo, dtype=np.float64), shape).ravel().copy()
    hi = np.broadcast_to(np.asarray(hi, dtype=np.float64), shape).ravel().copy()
    params = [np.broadcast_to(np.asarray(p, dtype=np.float64), shape).ravel() for p in params]
    if lo.size == 0:
        return lo.reshape(shape)
    value = g if dg is not None else (lambda x, *q: g(x, *q)[0])
    with np.errstate(all="ignore"):
        g_lo = value(lo, *params) if g_lo is None else np.broadcast_to(g_lo, shape).ravel()
        g_hi = value(hi, *params) if g_hi is None else np.broadcast_to(g_hi, shape).ravel()
    if np.any(g_lo * g_hi > 0) or not np.all(np.isfinite(g_lo) & np.isfinite(g_hi)):
        raise ValueError("bracketed_newton needs a finite sign change in every bracket")
    rising = g_lo < g_hi
    x = 0.5 * (lo + hi)
    if start is not None:  # (one outside its bracket, or nan: the midpoint)
        start = np.broadcast_to(np.asarray(start, dtype=np.float64), shape).ravel()
        x = np.where((start > lo) & (start < hi), start, x)
    step_before_last = hi - lo  # per element, as in rtsafe
    last_step = hi - lo
    x = np.where(g_lo == 0, lo, np.where(g_hi == 0, hi, x))
    active = np.flatnonzero((g_lo != 0) & (g_hi != 0))
    for _ in range(max_iter):
        if active.size == 0:
            return x.reshape(shape)
        p = [q[active] for q in params]
        xa, la, ha = x[active], lo[active], hi[active]
        with np.errstate(all="ignore"):
            gx, dgx = (g(xa, *p), dg(xa, *p)) if dg is not None else g(xa, *p)
            step = gx / dgx
        below = (gx < 0) == rising[active]
        la = np.where(below, xa, la)
        ha = np.where(below, ha, xa)
        new = xa - step
        scale = np.maximum(np.abs(xa), 1.0) * rtol
        converged = np.abs(step) <= scale  # also when rounding puts it on a bracket end
        slow = np.abs(step) > 0.5 * np.abs(step_before_last[active])
        bisect = (~((new > la) & (new < ha)) | slow) & ~converged  # NaN steps bisect too
        new = np.where(bisect, 0.5 * (la + ha), np.clip(new, la, ha))
        done = (gx == 0) | converged | (ha - la <= scale)
        step_before_last[active] = last_step[active]
        last_step[active] = new - xa
        x[active], lo[active], hi[active] = np.where(gx == 0, xa, new), la, ha
        active = active[~done]
    raise RuntimeError(
        f"bracketed_newton: {active.size} roots did not converge in {max_iter} steps"
    )


def bracketed_newton_scalar(
    g: Callable[[float], tuple[float, float]],
    lo: float,
    hi: float,
    *,
    rtol: float = 4e-15,
    max_iter: int = 200,
    g_lo: float | None = None,
    g_hi: float | None = None,
) -> float:
    """Solve ``g(x) = 0`` for one ``x`` in ``[lo, hi]``, in plain Python floats.

    The same iteration as :func:`bracketed_newton` (Newton steps inside the shrinking
    sign-change bracket, bisection where a step would leave it or is not less than
    half the step before last, the same stopping rule), one element at a time: for a
    single root the per-call cost of NumPy on one-element arrays would dominate.

    Parameters
    ----------
    g
        ``g(x) -> (value, derivative)`` at a float.
    lo, hi
        The bracket; ``g(lo)`` and ``g(hi)`` must be finite and not of the same sign.
    rtol, max_iter
        As for :func:`bracketed_newton`.
    g_lo, g_hi
        ``g(lo)`` and ``g(hi)`` (values only) when the caller already has them.

    >>> root = bracketed_newton_scalar(lambda x: (x * x - 2.0, 2.0 * x), 0.0, 3.0)
    >>> bool(abs(root - 2.0**0.5) < 1e-15)
    True
    """
    lo, hi = float(lo), float(hi)
    g_lo = g(lo)[0] if g_lo is None else float(g_lo)
    g_hi = g(hi)[0] if g_hi is None else float(g_hi)
    if g_lo * g_hi > 0 or not (math.isfinite(g_lo) and math.isfinite(g_hi)):
        raise ValueError("bracketed_newton_scalar needs a finite sign change in the bracket")
    if g_lo == 0:
        return lo
    if g_hi == 0:
        return hi
    rising = g_lo < g_hi
    x = 0.5 * (lo + hi)
    step_before_last = last_step = hi - lo
    for _ in range(max_iter):
        gx, dgx = g(x)
        if dgx != 0.0:
            step = gx / dgx
        else:  # as NumPy divides: +-inf, or NaN for 0/0 (both bisect)
            step = math.nan if gx == 0.0 or math.isnan(gx) else math.copysign(math.inf, gx)
        if (gx < 0) == rising:
            lo = x
        else:
            hi = x
        new = x - step
        scale = max(abs(x), 1.0) * rtol
        converged = abs(step) <= scale
        slow = abs(step) > 0.5 * abs(step_before_last)
        if (not (lo < new < hi) or slow) and not converged:
            new = 0.5 * (lo + hi)
        else:
            new = min(max(new, lo), hi)
        step_before_last, last_step = last_step, new - x
        if gx == 0:
            return x
        x = new
        if converged or hi - lo <= scale:
            return x
    raise RuntimeError(f"bracketed_newton_scalar: no convergence in {max_iter} steps")


def bracketed_illinois(
    fun: Callable[[np.ndarray, np.ndarray], np.ndarray],
    lo: np.ndarray,
    hi: np.ndarray,
    *,
    log: bool = False,
    rtol: float = 1e-13,
    atol: float = 0.0,
    max_iter: int = 400,
    f_lo: np.ndarray | None = None,
    f_hi: np.ndarray | None = None,
) -> np.ndarray:
    """Solve ``fun(x, index) = 0`` elementwise in ``[lo, hi]``, ``fun(lo) <= 0 < fun(hi)``.

    Derivative-free companion of :func:`bracketed_newton`: the Illinois method
    (modified regula falsi), in ``x`` or in ``log x``, is superlinear where ``fun`` is
    smooth and still converges where it jumps. ``fun`` receives the trial points and
    the flat indices of the elements they belong to; only unconverged elements are
    evaluated. An element is done when its bracket is narrower than
    ``max(atol, rtol * |x|)`` (``rtol`` alone in ``log x``) or ``fun`` is exactly zero.
    A bracket without the sign change (or with NaN at an end) raises ``ValueError``:
    the method would otherwise return a bracket end as if it were a root.
    ``f_lo``, ``f_hi`` are ``fun`` at the bracket ends when the caller already has them
    (exactly as ``fun`` returns them), saving those two evaluations.

    >>> targets = np.array([2.0, 9.0])
    >>> root = bracketed_illinois(lambda x, i: x**2 - targets[i], np.ones(2), np.full(2, 4.0))
    >>> bool(np.abs(root - [np.sqrt(2.0), 3.0]).max() < 1e-12)
    True
    """
    to, back = (np.log, np.exp) if log else (np.asarray, np.asarray)
    a = to(np.asarray(lo, dtype=float)).ravel().copy()
    b = to(np.asarray(hi, dtype=float)).ravel().copy()
    every = np.arange(a.size)
    fa = np.asarray(fun(back(a), every) if f_lo is None else f_lo, dtype=float).ravel().copy()
    fb = np.asarray(fun(back(b), every) if f_hi is None else f_hi, dtype=float).ravel().copy()
    bad = ~((fa <= 0) & (fb >= 0))  # NaN fails both
    if bad.any():
        i = np.flatnonzero(bad)[0]
        raise ValueError(
            f"bracketed_illinois needs a sign change, fun(lo) <= 0 <= fun(hi), in every "
            f"bracket; element "
            f"{i} has fun({float(back(a[i])):.6g}) = {fa[i]:.6g}, "
            f"fun({float(back(b[i])):.6g}) = {fb[i]:.6g}"
        )
    x = np.where(fa == 0, a, b)
    side = np.zeros(a.size, dtype=int)
    active = np.flatnonzero((fa != 0) & (fb != 0))
    for _ in range(max_iter):
        if active.size == 0:
            return back(x)
        aa, bb, faa, fbb = a[active], b[active], fa[active], fb[active]
        with np.errstate(invalid="ignore", divide="ignore"):
            xx = (aa * fbb - bb * faa) / (fbb - faa)
        xx = np.where(np.isfinite(xx) & (xx > aa) & (xx < bb), xx, 0.5 * (aa + bb))
        fx = np.asarray(fun(back(xx), active), dtype=float)
        right = fx > 0  # the root is in [aa, xx]
        keep = side[active]
        fa[active] = np.where(right, np.where(keep == 1, 0.5 * faa, faa), fx)
        fb[active] = np.where(right, fx, np.where(keep == -1, 0.5 * fbb, fbb))
        a[active], b[active] = np.where(right, aa, xx), np.where(right, xx, bb)
        side[active] = np.where(right, 1, -1)
        x[active] = xx
        scale = 1.0 if log else np.maximum(np.abs(xx), np.finfo(float).tiny)
        done = (fx == 0) | (b[active] - a[active] <= np.maximum(atol, rtol * scale))
        active = active[~done]
    raise RuntimeError(f"bracketed_illinois: {active.size} roots did not converge")


def newton_system(
    residual: Callable[[np.ndarray], np.ndarray],
    u0: np.ndarray,
    *,
    eps: float = 1e-6,
    max_step: float = 0.5,
    tol: float = 1e-9,
    max_iter: int = 12,
    shrink: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``residual(u) = 0`` for ``n`` independent systems of ``k`` unknowns each.

    ``u`` has shape ``(k, n)`` and ``residual`` maps it to the same shape (column ``j``
    of the result depends on column ``j`` of ``u`` only). Each iteration builds the
    ``k x k`` Jacobians by forward differences of step ``eps`` (``k + 1`` calls of
    ``residual`` for all systems together), solves them batched and clips every
    component of the Newton step to ``[-max_step, max_step]``: a trust bound that keeps
    a poor start from jumping out of the region where ``residual`` is defined (use it
    in unknowns scaled to order one, e.g. logarithms). Meant for smooth residuals that
    are expensive to evaluate (a numerical integration) and have a good start.

    Returns ``(u, r)`` after at most ``max_iter`` steps, or as soon as every
    ``|r| < tol``; ``r = residual(u)``. Whether ``r`` is small enough is the caller's
    decision (no exception here): a system that did not converge shows in ``r``.

    ``shrink=True`` stops each system at its own convergence: ``residual(u, idx)`` is
    then called with the columns ``idx`` (indices into all systems) still at some
    ``|r| >= tol`` only, and a start already below ``tol`` takes no step. Meant for
    many systems with good starts, most of which converge at once: the others no
    longer make every system pay for their iterations.

    >>> u, r = newton_system(lambda u: u**2 - np.array([[2.0, 9.0]]), np.ones((1, 2)))
    >>> bool(np.abs(u - [[np.sqrt(2.0), 3.0]]).max() < 1e-9)
    True
    """
    if shrink:
        return _newton_shrinking(residual, u0, eps, max_step, tol, max_iter)
    u = np.asarray(u0, dtype=float)
    r = residual(u)
    for _ in range(max_iter):
        u = _newton_step(residual, u, r, eps, max_step)
        r = residual(u)
        if np.all(np.abs(r) < tol):
            break
    return u, r


def _newton_step(residual, u, r, eps, max_step, *index):
    """One Newton step of :func:`newton_system` from ``u`` with residual ``r``
    (forward-difference Jacobians; ``index``: the columns, passed on to ``residual``)."""
    J = np.empty((u.shape[0], u.shape[0], u.shape[1]))
    for j in range(u.shape[0]):
        du = np.zeros_like(u)
        du[j] = eps
        J[:, j] = (residual(u + du, *index) - r) / eps
    step = np.linalg.solve(np.moveaxis(J, -1, 0), np.moveaxis(r, -1, 0)[..., None])[..., 0]
    return u - np.clip(np.moveaxis(step, 0, -1), -max_step, max_step)


def _newton_shrinking(residual, u0, eps, max_step, tol, max_iter):
    """:func:`newton_system` with ``shrink=True``: only unconverged columns iterate."""
    u = np.array(u0, dtype=float)
    active = np.arange(u.shape[1])
    r = np.asarray(residual(u, active), dtype=float)
    active = active[~np.all(np.abs(r) < tol, axis=0)]
    for _ in range(max_iter):
        if active.size == 0:
            break
        u[:, active] = _newton_step(residual, u[:, active], r[:, active], eps, max_step, active)
        r[:, active] = residual(u[:, active], active)
        active = active[~np.all(np.abs(r[:, active]) < tol, axis=0)]
    return u, r
