r"""Rigid-contact rod kernel: :math:`y(t)` and :math:`N(t)` in plain NumPy.

Evaluates exactly the inverted series terms whose delay has arrived
(:meth:`impactsym.rod.RodImpact.time_terms`, eq. (2) of the paper, rigid contact
:math:`\kappa \to \infty`). This module imports nothing but NumPy; its source is what
:func:`impactsym.rod.codegen.numpy_source` writes into the exported module.

On the reflection interval :math:`t = 2m + \tau`, :math:`0 \le \tau < 2`, all arrived
terms collect into one short sum of Laguerre functions :math:`E_j(x) = e^{-x/2} L_j(x)`,
:math:`x = 2\tau/\alpha`,

.. math::

    N(2m + \tau) = f + \sum_{j=0}^{m} c_{m-j} E_j(x), \qquad
    y(2m + \tau) = y(2m) + y'(2m^+) \tau - \frac{\alpha}{4}
                    \sum_{j=0}^{m} c_{m-j} I_j(x),

with :math:`I_j(x) = \int_0^x \int_0^{x'} E_j` and per-:math:`\alpha` coefficients
:math:`c_d` (:func:`rigid_tables`). Why this form: a point costs :math:`O(m)`
operations; :math:`E_j`, :math:`I_j` come from stable recurrences bounded by their
true size, :math:`y(2m)` and :math:`y'(2m)` are chained interval by interval (no
cancellation of :math:`2m` against a sum of size :math:`m`), and the recurrences run
with a power-of-two scale once :math:`e^{-x/2}` would underflow. The kernel refuses
:math:`t >` :data:`T_LIMIT`, the verified range. Derivation (Laguerre addition theorem)
and verification: See `docs/physics.md#rod-rigid-kernel`.
"""

from __future__ import annotations

import numpy as np

#: Largest normalized time the rigid kernel evaluates (the verified range).
T_LIMIT = 1.0e4

#: Mass ratios the kernel is verified for: above, the Laguerre sums of a heavy striker
#: cancel; below, the certified search runs out of cells (`docs/physics.md#rod-rigid-kernel`).
ALPHA_RANGE = (1.0e-10, 1.0e6)


def check_alpha(alpha: np.ndarray) -> None:
    """Refuse mass ratios outside :data:`ALPHA_RANGE`, naming ``alpha`` and the range.

    >>> check_alpha(np.array([0.5, 2e6]))
    Traceback (most recent call last):
        ...
    ValueError: alpha must lie in [1e-10, 1e+06], where the rod kernel is verified; got 2000000.0
    """
    low, high = ALPHA_RANGE
    outside = alpha[(alpha < low) | (alpha > high)]
    if outside.size:
        raise ValueError(
            f"alpha must lie in [{low:g}, {high:g}], where the rod kernel is verified; "
            f"got {float(outside.flat[0])!r}"
        )


def rescale(E, E_prev, scale, log_scale):
    """Keep a three-term recurrence in range: where ``|E| > 2**500``, divide the last two
    terms by ``2**500`` and carry the factor in ``scale = exp(log_scale)`` (in place)."""
    big = np.abs(E) > 2.0**500
    if big.any():
        E[big] *= 2.0**-500
        E_prev[big] *= 2.0**-500
        log_scale[big] += 500 * np.log(2.0)
        scale[big] = np.exp(log_scale[big])


def next_laguerre(j, x, E, E_prev, spare):
    """One step of :math:`E_j = ((2j - 1 - x) E_{j-1} - (j - 1) E_{j-2}) / j`, in place
    in the three buffers; returns ``(E_j, E_(j-1), spare)``."""
    np.subtract(2 * j - 1, x, out=spare)
    spare *= E
    E_prev *= -(j - 1)
    spare += E_prev
    spare *= 1.0 / j
    return spare, E, E_prev


def next_integrals(E, E_prev, I1, I2, spare, scale=None):
    """One step of the integrals of ``y``: :math:`I1_j = -I1_{j-1} - 2 (E_j - E_{j-1})`,
    :math:`I2_j = -2 (I1_j - I1_{j-1}) - I2_{j-1}` (``E`` times ``scale`` where the
    recurrence is rescaled), in place in the three buffers; returns
    ``(I1_j, I2_j, spare)``."""
    np.subtract(E, E_prev, out=spare)
    if scale is not None:
        spare *= scale
    spare *= -2.0
    spare -= I1  # I1_j
    np.subtract(spare, I1, out=I1)
    I1 *= -2.0
    I1 -= I2  # I2_j, stored in the old I1 buffer
    return spare, I1, I2


def rigid_tables(alpha, n_intervals):
    """Per-alpha coefficient tables of the rigid-contact kernel.

    Returns ``(B, Y0, Y1, V0, V1)``, each of shape ``(len(alpha), n_intervals + 1)``.
    ``B``: column ``d + 1`` holds ``B_d`` (column 0 is ``B_(-1) = 0``); with nodes
    ``y_i = 4 i / alpha``, ``B_d = sum_i A_(d-i)(y_i)``, ``A_p(y) = exp(-y/2)
    L_p^(-1)(y) = E_p(y) - E_(p-1)(y)`` (addition theorem). ``Y0 + f Y1`` and
    ``V0 + f V1``: column ``m`` holds ``y(2m)`` and ``y'(2m)`` (``y'`` is continuous):
    ``y'(2m) = 1 - ((1 + f) G1_(m-1) + (1 - f) G1_m) / 2`` with ``G1_d = sum_i
    I1_(d-i)(y_i)`` (terms of size <= 2, no accumulation), and ``y(2m)`` chained,
    ``y(2m+2) = y(2m) + 2 y'(2m) - (alpha/4) sum_j c_(m-j) I2_j(X)`` at ``X = 4/alpha``
    (no step cancels more than one interval's terms). The Laguerre recurrence runs on
    ``E_n exp(y/2 - s)`` with a power-of-two scale ``s`` per node, so that
    ``exp(-y/2)`` never underflows before ``L_n(y)`` has grown (far out, ``y > 1490``);
    memory is ``O(len(alpha) * n_intervals)``.
    """
    alpha = np.asarray(alpha, dtype=np.float64).reshape(-1)
    K = max(int(n_intervals), 1)
    nodes = 4.0 * np.arange(K + 1)[None, :] / alpha[:, None]
    E_prev, E = np.zeros_like(nodes), np.ones_like(nodes)
    log_scale = -0.5 * nodes
    scale = np.exp(log_scale)
    true_prev = np.zeros_like(nodes)
    B, G1 = np.zeros((alpha.size, K + 1)), np.zeros((alpha.size, K + 1))
    I2X = np.zeros((alpha.size, K))
    X = nodes[:, 1]
    I1 = -2.0 * np.expm1(-0.5 * nodes)  # at every node
    I2 = 2.0 * X + 4.0 * np.expm1(-0.5 * X)  # at node 1 (X) only
    for n in range(K):  # order n at node i feeds index n + i (i < K - n); node 1 is X
        width = max(K - n, 2)
        x, E, E_prev = nodes[:, :width], E[:, :width], E_prev[:, :width]
        scale, log_scale, true_prev = scale[:, :width], log_scale[:, :width], true_prev[:, :width]
        I1 = I1[:, :width]
        if n > 0:
            E_prev, E = E, ((2 * n - 1 - x) * E - (n - 1) * E_prev) / n
            rescale(E, E_prev, scale, log_scale)
        true = E * scale
        B[:, n + 1 :] += (true - true_prev)[:, : K - n]
        if n > 0:  # I1_n = -I1_(n-1) - 2 (E_n - E_(n-1)), I2 likewise from I1
            I1_next = -I1 - 2.0 * (true - true_prev)
            I2 = -I2 - 2.0 * (I1_next[:, 1] - I1[:, 1])
            I1 = I1_next
        G1[:, n + 1 :] += I1[:, : K - n]
        I2X[:, n] = I2
        true_prev = true
    Bs, Bd = B[:, :-1] + B[:, 1:], B[:, :-1] - B[:, 1:]  # c_d = Bs_d + f Bd_d
    # y'(2m) = 1 - ((1 + f) G1_(m-1) + (1 - f) G1_m) / 2 directly (each G1 a sum of
    # terms of size <= 2); y(2m) chained with it
    V0, V1 = np.empty((alpha.size, K + 1)), np.empty((alpha.size, K + 1))
    V0[:, :K] = 1.0 - 0.5 * (G1[:, :K] + G1[:, 1:])
    V1[:, :K] = -0.5 * (G1[:, :K] - G1[:, 1:])
    V0[:, K], V1[:, K] = np.nan, np.nan  # not needed: tables cover m < n_intervals
    quarter = 0.25 * alpha[:, None]
    Y0, Y1 = np.zeros((alpha.size, K + 1)), np.zeros((alpha.size, K + 1))
    for Y, V, coef in ((Y0, V0, Bs), (Y1, V1, Bd)):
        steps = np.array([np.convolve(coef[r], I2X[r])[:K] for r in range(alpha.size)])
        Y[:, 1:] = np.cumsum(2.0 * V[:, :K] - quarter * steps.reshape(alpha.size, K), axis=1)
    return B, Y0, Y1, V0, V1


def rigid_local(which, m, tau, a_idx, alpha, f, tables, derivative=False):
    """Rigid-contact ``y`` (``which="y"``) or ``N`` on reflection interval ``m``.

    Evaluates at ``t = 2 m + tau`` (``0 <= tau <= 2``; ``tau = 2`` gives the left
    limit at ``2 m + 2``) for 1-D arrays ``m`` (int), ``tau`` and ``a_idx`` (row of
    ``tables`` for each point); ``alpha`` and ``f`` are arrays like ``tau`` or
    scalars. Returns the value, or the derivative in ``tau`` if ``derivative``.
    Python loops run over blocks of equal ``(a_idx, m)`` and the Laguerre order
    ``j``, never over points; with many distinct ``alpha`` the blocks are merged
    and the coefficients gathered per point.
    """
    B, Y0, Y1, V0, V1 = tables
    m = np.asarray(m, dtype=np.int64)
    size = m.size
    scalar_f = np.ndim(f) == 0
    # c_(m-j) = (1 + f) B_(m-j-1) + (1 - f) B_(m-j) = Bs + f Bd
    Bs, Bd = B[:, :-1] + B[:, 1:], B[:, :-1] - B[:, 1:]
    if scalar_f:
        Bs, Bd = Bs + f * Bd, np.zeros_like(Bd)
    single = np.all(a_idx == a_idx[0])
    order = np.argsort(-m, kind="stable") if single else np.lexsort((-m, a_idx))
    ms, rows = m[order], a_idx[order]
    starts = np.flatnonzero(np.r_[True, (ms[1:] != ms[:-1]) | (rows[1:] != rows[:-1])])
    if starts.size > max(64, size // 4096):  # many small blocks: one block, gathers
        order = np.argsort(-m, kind="stable")
        ms, rows, starts = m[order], a_idx[order], np.zeros(1, dtype=np.int64)
    ends = np.r_[starts[1:], size]
    al = alpha if np.ndim(alpha) == 0 else alpha[order]
    ff = f if scalar_f else f[order]
    taus = tau[order]
    x_all = (2.0 / al) * taus
    acc1, acc2 = np.zeros(size), np.zeros(size)
    for lo, hi in zip(starts, ends, strict=True):
        mb, rb = ms[lo:hi], rows[lo:hi]
        uniform = mb[0] == mb[-1] and rb[0] == rb[-1]
        mmax = int(mb[0])
        n_active = np.searchsorted(-mb, -np.arange(mmax + 1), side="right")
        x = x_all[lo:hi]
        # far out (x > 1400) exp(-x/2) underflows before L_j(x) has grown: the
        # recurrence then runs on E_j exp(x/2 - s), s a power-of-two scale per point
        scaled = x.size > 0 and x.max() > 1400.0
        if scaled:
            log_scale = -0.5 * x
            scale = np.exp(log_scale)
            E = np.ones(hi - lo)
        else:
            E = np.exp(-0.5 * x)
        E_prev, tmp = np.zeros(hi - lo), np.empty(hi - lo)
        if which == "y":
            I1 = np.expm1(-0.5 * x)
            I2 = 2.0 * x + 4.0 * I1
            I1 *= -2.0
        else:
            S = np.zeros(hi - lo)
        for j in range(mmax + 1):
            n = n_active[j]
            a1, a2 = acc1[lo : lo + n], acc2[lo : lo + n]
            x, E, E_prev, tmp = x[:n], E[:n], E_prev[:n], tmp[:n]
            if j > 0:
                E, E_prev, tmp = next_laguerre(j, x, E, E_prev, tmp)
            if scaled:
                scale, log_scale = scale[:n], log_scale[:n]
                rescale(E, E_prev, scale, log_scale)
                E_true = E * scale
            else:
                E_true = E
            if which == "y":
                I1, I2 = I1[:n], I2[:n]
                if j > 0:
                    I1, I2, tmp = next_integrals(E, E_prev, I1, I2, tmp, scale if scaled else None)
                term = I1 if derivative else I2
            elif derivative:
                S = S[:n]
                term = -(S + 0.5 * E_true)
                S += E_true
            else:
                term = E_true
            if uniform:
                d = mmax - j
                if Bs[rb[0], d] != 0.0:
                    a1 += Bs[rb[0], d] * term
                if not scalar_f:
                    a2 += Bd[rb[0], d] * term
            else:
                d = mb[:n] - j
                a1 += Bs[rb[:n], d] * term
                if not scalar_f:
                    a2 += Bd[rb[:n], d] * term
    acc = acc1 if scalar_f else acc1 + ff * acc2
    if which == "y":
        v0 = V0[rows, ms] + ff * V1[rows, ms]
        if derivative:
            res = v0 - 0.5 * acc
        else:
            y0 = Y0[rows, ms] + ff * Y1[rows, ms]
            res = y0 + v0 * taus - 0.25 * al * acc
    elif derivative:
        res = (2.0 / al) * acc
    else:
        res = ff + acc
    out = np.empty(size)
    out[order] = res
    return out


def rigid_evaluate(which, t, alpha, f):
    """Rigid-contact ``y`` or ``N`` at flat arrays ``t >= 0``, ``alpha``, ``f``.

    Refuses ``t > T_LIMIT``, the verified range (the tables cost ``O((t/2)^2)`` per
    distinct ``alpha``; `docs/physics.md#rod-rigid-kernel`).
    """
    if t.size and not np.max(t) <= T_LIMIT:
        raise ValueError(
            f"t must be <= {T_LIMIT:g} for rigid contact (the range where the kernel is "
            f"verified to 1e-9), got t = {float(np.max(t))!r}"
        )
    m = np.floor(t / 2.0).astype(np.int64)
    ua, a_idx = np.unique(alpha, return_inverse=True)
    tables = rigid_tables(ua, int(m.max()) + 1 if m.size else 1)
    f_arg = f[0] if f.size and np.all(f == f[0]) else f
    a_arg = ua[0] if ua.size == 1 else alpha
    return rigid_local(which, m, t - 2.0 * m, a_idx.ravel(), a_arg, f_arg, tables)
