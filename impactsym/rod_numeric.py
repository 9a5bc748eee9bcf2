"""Float time functions of the rod impact: :math:`y(t)`, :math:`N(t)` and contact times.

Everything here evaluates *exactly the inverted series terms whose delay has arrived*
(:meth:`impactsym.rod.RodImpact.time_terms`), arranged so that float64 does not cancel
catastrophically far out.

**Rigid contact** (:math:`\\kappa \\to \\infty`). With :math:`x = 2u/\\alpha` and the
Laguerre functions :math:`E_n(x) = e^{-x/2} L_n(x)`, the inverted terms of the series
of ``N`` and ``Y`` (``PHYSICS.md``, eq. (2)) are

.. math::

    N(t) = f + \\sum_{k \\ge 0} \\bigl[(1+f) E_{k-1}(x_k) + (1-f) E_k(x_k)\\bigr], \\qquad
    y(t) = t - \\frac{\\alpha}{4} \\sum_{k \\ge 0}
           \\bigl[(1+f) I_{k-1}(x_k) + (1-f) I_k(x_k)\\bigr],

summed over :math:`2k \\le t`, with :math:`x_k = 2(t - 2k)/\\alpha`,
:math:`E_{-1} = I_{-1} = 0` and :math:`I_n(x) = \\int_0^x \\int_0^{x'} E_n`. On the
reflection interval :math:`t = 2m + \\tau`, :math:`0 \\le \\tau < 2`, the Laguerre
addition theorem :math:`L_n(x + y) = \\sum_{j \\le n} L_{n-j}^{(-1)}(y) L_j(x)`
collects all arrived terms into one short sum in :math:`x = 2\\tau/\\alpha`,

.. math::

    N(2m + \\tau) = f + \\sum_{j=0}^{m} c_{m-j} E_j(x), \\qquad
    y(2m + \\tau) = y(2m) + y'(2m^+) \\tau - \\frac{\\alpha}{4}
                    \\sum_{j=0}^{m} c_{m-j} I_j(x),

:math:`c_d = (1+f) B_{d-1} + (1-f) B_d`, :math:`B_d = \\sum_{i=0}^{d} e^{-y_i/2}
L^{(-1)}_{d-i}(y_i)`, :math:`y_i = 4i/\\alpha`. :math:`E_j`, :math:`I_j` come from
stable recurrences (three-term for :math:`E_j`, and
:math:`I'_j + I'_{j-1} = -2(E_j - E_{j-1})` integrated), all bounded by their
true size; a point costs :math:`O(m)` operations. This kernel is plain NumPy
(:func:`numpy_source` emits it).

**Finite contact stiffness.** Every term is
:math:`\\sum_p e^{p u} \\sum_j c_{pj} u^j` over the poles :math:`p` (the roots of
:math:`P = \\alpha s^2 + \\alpha\\kappa s + \\kappa` and :math:`s = 0`); the Laurent
coefficients are computed from the symbolic series with mpmath at 40 or more digits
and the sum is evaluated in complex float64 together with a rounding-error bound.
Near critical contact damping, :math:`\\alpha\\kappa \\approx 4`, the two roots merge and
the per-pole parts cancel; points whose bound exceeds ``1e-12`` are re-evaluated
with mpmath at the precision the bound asks for.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from impactsym.numeric import bracketed_newton
from impactsym.validation import check_condition, finish, real_array

__all__ = [
    "ContactTimeMap",
    "contact_force",
    "contact_time",
    "contact_time_map",
    "displacement",
    "numpy_source",
]

#: Absolute error allowed for the float path of the finite-stiffness evaluation.
_TOLERANCE = 1e-12
_EPS = np.finfo(np.float64).eps


# ------------------------------------------------------------ rigid-contact kernel
# These two functions use nothing but NumPy: numpy_source() emits their source.


def _rigid_tables(alpha, n_intervals):
    """Per-alpha coefficient tables of the rigid-contact kernel.

    Returns ``(B, G1, G2)``, each of shape ``(len(alpha), n_intervals + 1)``; column
    ``d + 1`` holds index ``d`` (column 0 is index -1, zero). With nodes
    ``y_i = 4 i / alpha``: ``B_d = sum_i A_(d-i)(y_i)`` with
    ``A_p(y) = exp(-y/2) L_p^(-1)(y) = E_p(y) - E_(p-1)(y)`` (addition theorem),
    ``G1_d = sum_i I1_(d-i)(y_i)`` and ``G2_d = sum_i I2_(d-i)(y_i)`` (single and
    double integrals of ``E_n``), used for ``y(2m)`` and ``y'(2m+)``.
    """
    alpha = np.asarray(alpha, dtype=np.float64).reshape(-1)
    K = max(int(n_intervals), 1)
    nodes = 4.0 * np.arange(K)[None, :] / alpha[:, None]
    em1 = np.expm1(-0.5 * nodes)
    E_prev, E = np.zeros_like(nodes), np.exp(-0.5 * nodes)
    I1, I2 = -2.0 * em1, 2.0 * nodes + 4.0 * em1
    tabs = np.empty((3, K, *nodes.shape))
    for n in range(K):
        if n > 0:
            E_prev, E = E, ((2 * n - 1 - nodes) * E - (n - 1) * E_prev) / n
            I1_next = -I1 - 2.0 * (E - E_prev)
            I2 = -I2 - 2.0 * (I1_next - I1)
            I1 = I1_next
        tabs[0, n], tabs[1, n], tabs[2, n] = E - E_prev, I1, I2
    out = np.zeros((3, alpha.size, K + 1))
    for i in range(K):  # anti-diagonal sums: order n at node i feeds index n + i
        out[:, :, i + 1 :] += np.swapaxes(tabs[:, : K - i, :, i], 1, 2)
    return out[0], out[1], out[2]


def _rigid_local(which, m, tau, a_idx, alpha, f, tables, derivative=False):
    """Rigid-contact ``y`` (``which="y"``) or ``N`` on reflection interval ``m``.

    Evaluates at ``t = 2 m + tau`` (``0 <= tau <= 2``; ``tau = 2`` gives the left
    limit at ``2 m + 2``) for 1-D arrays ``m`` (int), ``tau`` and ``a_idx`` (row of
    ``tables`` for each point); ``alpha`` and ``f`` are arrays like ``tau`` or
    scalars. Returns the value, or the derivative in ``tau`` if ``derivative``.
    Python loops run over blocks of equal ``(a_idx, m)`` and the Laguerre order
    ``j``, never over points; with many distinct ``alpha`` the blocks are merged
    and the coefficients gathered per point.
    """
    B, G1, G2 = tables
    m = np.asarray(m, dtype=np.int64)
    size = m.size
    scalar_f = np.ndim(f) == 0
    # c_(m-j) = (1 + f) B_(m-j-1) + (1 - f) B_(m-j) = Bs + f Bd, likewise for G1, G2
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
        E_prev, E, tmp = np.zeros(hi - lo), np.exp(-0.5 * x), np.empty(hi - lo)
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
            if j > 0:  # E_j = ((2j - 1 - x) E_(j-1) - (j - 1) E_(j-2)) / j
                np.subtract(2 * j - 1, x, out=tmp)
                tmp *= E
                E_prev *= -(j - 1)
                tmp += E_prev
                tmp *= 1.0 / j
                E_prev, E, tmp = E, tmp, E_prev
            if which == "y":
                I1, I2 = I1[:n], I2[:n]
                if j > 0:  # I1_j = -I1_(j-1) - 2 (E_j - E_(j-1)); I2 likewise from I1
                    np.subtract(E, E_prev, out=tmp)
                    tmp *= -2.0
                    tmp -= I1  # I1_j
                    np.subtract(tmp, I1, out=I1)
                    I1 *= -2.0
                    I1 -= I2  # I2_j, stored in the old I1 buffer
                    I1, I2, tmp = tmp, I1, I2
                term = I1 if derivative else I2
            elif derivative:
                S = S[:n]
                term = -(S + 0.5 * E)
                S += E
            else:
                term = E
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
        g1 = G1[rows, ms] + G1[rows, ms + 1] + ff * (G1[rows, ms] - G1[rows, ms + 1])
        if derivative:
            res = 1.0 - 0.5 * g1 - 0.5 * acc
        else:
            g2 = G2[rows, ms] + G2[rows, ms + 1] + ff * (G2[rows, ms] - G2[rows, ms + 1])
            res = 2.0 * ms + (1.0 - 0.5 * g1) * taus - 0.25 * al * (g2 + acc)
    elif derivative:
        res = (2.0 / al) * acc
    else:
        res = ff + acc
    out = np.empty(size)
    out[order] = res
    return out


def _rigid_evaluate(which, t, alpha, f):
    """Rigid-contact ``y`` or ``N`` at flat arrays ``t >= 0``, ``alpha``, ``f``."""
    m = np.floor(t / 2.0).astype(np.int64)
    ua, a_idx = np.unique(alpha, return_inverse=True)
    tables = _rigid_tables(ua, int(m.max()) + 1 if m.size else 1)
    f_arg = f[0] if f.size and np.all(f == f[0]) else f
    a_arg = ua[0] if ua.size == 1 else alpha
    return _rigid_local(which, m, t - 2.0 * m, a_idx.ravel(), a_arg, f_arg, tables)


# --------------------------------------------------------- finite-stiffness kernel


@lru_cache(maxsize=8)
def _elastic_series(name: str, n_terms: int) -> tuple:
    """The finite-stiffness series of ``name`` as numerator-coefficient functions.

    Every term of :meth:`impactsym.rod.RodImpact.series` is
    ``numerator(s) / (const * s**m0 * P**n)`` with ``P = alpha s**2 + alpha kappa s
    + kappa``; returns ``(delay, m0, n, fn)`` per term, ``fn(alpha, kappa)`` giving
    (mpmath) the numerator coefficients, highest power first, for ``f**0`` and
    ``f**1``, and ``const``.
    """
    import sympy as sp

    from impactsym.rod import RodImpact, alpha, f, kappa, s

    P = sp.expand(alpha * s**2 + alpha * kappa * s + kappa)
    out = []
    for delay, coeff in RodImpact(kappa).series(name, n_terms):
        numer, denom = sp.fraction(coeff)
        const, m0, n = sp.Integer(1), 0, 0
        for factor in sp.Mul.make_args(denom):
            base, power = factor.as_base_exp()
            if base == s:
                m0 = int(power)
            elif sp.expand(base - P) == 0:
                n = int(power)
            elif not base.has(s):
                const *= factor
            else:  # pragma: no cover - structure of eq. (1)
                raise RuntimeError(f"unexpected denominator factor {factor}")
        coeffs = sp.Poly(numer, s).all_coeffs()
        c0 = [sp.expand(c).subs(f, 0) for c in coeffs]
        c1 = [sp.expand(c).coeff(f, 1) for c in coeffs]
        if any(sp.expand(c - a - f * b) != 0 for c, a, b in zip(coeffs, c0, c1, strict=True)):
            raise RuntimeError("numerator not linear in f")  # pragma: no cover
        fn = sp.lambdify((alpha, kappa), [c0, c1, const], modules="mpmath")
        out.append((int(delay), m0, n, fn))
    return tuple(out)


def _principal_parts(num: list, lead, poles: list, index: int) -> list:
    """Coefficients ``c_p`` of ``exp(r u) sum_p c_p u**p``, the inverse transform of the
    principal part of ``num(s) / (lead * prod (s - r_i)**m_i)`` at ``r = poles[index]``
    (mpmath numbers; ``num`` highest power first)."""
    import mpmath as mp

    r, m = poles[index]
    series = [mp.mpf(0)] * m  # num(r + e) modulo e**m, by Horner
    series[0] = num[0]
    for c in num[1:]:
        nxt = [series[0] * r + c] + [series[i] * r + series[i - 1] for i in range(1, m)]
        series = nxt
    for k, (o, mo) in enumerate(poles):
        if k == index:
            continue
        d = r - o  # (d + e)**(-mo) = sum_j binom(-mo, j) d**(-mo-j) e**j
        factor = [mp.binomial(-mo, j) * d ** (-mo - j) for j in range(m)]
        series = [mp.fsum(series[i] * factor[j - i] for i in range(j + 1)) for j in range(m)]
    return [series[m - 1 - p] / (lead * mp.factorial(p)) for p in range(m)]


class _ElasticModel:
    """Exact pole data of the first ``n_terms`` finite-stiffness terms of ``name``.

    For term ``k`` (delay ``2k``) ``parts[k]`` lists ``(root, c0, c1, pair)``: the
    term is ``sum exp(root u) (c0(u) + f c1(u))`` (``2 Re`` of it if ``pair``), with
    the coefficients computed at ``dps`` digits; ``dparts`` is the same for the
    derivative in ``u``.
    """

    def __init__(self, name: str, alpha: float, kappa: float, n_terms: int, dps: int) -> None:
        import mpmath as mp

        self.dps = dps
        self.parts: list[list] = []
        self.dparts: list[list] = []
        with mp.workdps(dps):
            a, k = mp.mpf(alpha), mp.mpf(kappa)
            disc = a * a * k * k - 4 * a * k  # exact: products of doubles fit in dps
            if disc == 0:
                roots = [(-k / 2, 2)]
            else:
                sq = mp.sqrt(disc) if disc > 0 else mp.mpc(0, mp.sqrt(-disc))
                roots = [((-a * k + sq) / (2 * a), 1), ((-a * k - sq) / (2 * a), 1)]
            self.fastest = float(max(abs(r) for r, _ in roots))
            for _, m0, n, fn in _elastic_series(name, n_terms):
                c0, c1, const = fn(a, k)
                poles = [(r, mult * n) for r, mult in roots]
                if m0:
                    poles.append((mp.mpf(0), m0))
                lead = const * a**n
                parts, dparts = [], []
                for index, (r, _) in enumerate(poles):
                    if isinstance(r, mp.mpc) and r.imag < 0:
                        continue  # the conjugate of the root before
                    pair = isinstance(r, mp.mpc)
                    p0 = _principal_parts(c0, lead, poles, index)
                    p1 = _principal_parts(c1, lead, poles, index)
                    parts.append((r, p0, p1, pair))
                    dparts.append((r, _derivative(p0, r), _derivative(p1, r), pair))
                self.parts.append(parts)
                self.dparts.append(dparts)

    def evaluate(self, u_terms, f, derivative=False):
        """Float sum of the terms at ``u_terms[k]`` (``u = t - 2k``, NaN if not arrived)
        and a bound on its rounding error."""
        value = np.zeros(np.shape(f))
        bound = np.zeros(np.shape(f))
        for k, parts in enumerate(self.dparts if derivative else self.parts):
            u = u_terms[k]
            arrived = u >= 0
            if not arrived.any():
                continue
            ua, fa = u[arrived], f[arrived]
            for r, p0, p1, pair in parts:
                c0 = np.array([complex(c) for c in p0])
                c1 = np.array([complex(c) for c in p1])
                poly = np.zeros(ua.size, dtype=complex)
                size = np.zeros(ua.size)
                for q0, q1 in zip(c0[::-1], c1[::-1], strict=True):
                    poly = poly * ua + (q0 + fa * q1)
                    size = size * ua + np.abs(q0) + fa * np.abs(q1)
                e = np.exp(complex(r) * ua)
                weight = 2.0 if pair else 1.0
                value[arrived] += weight * (poly * e).real
                bound[arrived] += weight * size * np.abs(e) * (len(c0) + 4)
        return value, bound * _EPS

    def evaluate_mp(self, t, f, derivative=False):
        """The same sum with mpmath at the model's precision (one point)."""
        import mpmath as mp

        with mp.workdps(self.dps):
            total = mp.mpf(0)
            for k, parts in enumerate(self.dparts if derivative else self.parts):
                u = mp.mpf(t) - 2 * k
                if u < 0:
                    break
                for r, p0, p1, pair in parts:
                    poly = mp.polyval([a + f * b for a, b in zip(p0, p1, strict=True)][::-1], u)
                    term = poly * mp.exp(r * u)
                    total += 2 * mp.re(term) if pair else mp.re(term)
            return float(total)


def _derivative(coeffs: list, r) -> list:
    """Coefficients of d/du [exp(r u) sum_p c_p u**p] in the same form."""
    n = len(coeffs)
    return [r * coeffs[p] + ((p + 1) * coeffs[p + 1] if p + 1 < n else 0) for p in range(n)]


@lru_cache(maxsize=64)
def _elastic_model(name: str, alpha: float, kappa: float, n_terms: int, dps: int = 40):
    return _ElasticModel(name, alpha, kappa, n_terms, dps)


def _elastic(name: str, t: np.ndarray, alpha: float, kappa: float, f: np.ndarray, derivative=False):
    """Finite-stiffness ``y`` or ``N`` at times ``t >= 0`` for one ``(alpha, kappa)``."""
    n_terms = int(np.max(t) // 2) + 1
    model = _elastic_model(name, alpha, kappa, n_terms)
    u_terms = [t - 2.0 * k for k in range(n_terms)]
    value, error = model.evaluate(u_terms, f, derivative)
    bad = np.flatnonzero(~(error <= _TOLERANCE))
    if bad.size:  # mpmath where float64 cancels (near critical damping)
        digits = (
            int(np.ceil(np.log10(np.max(error[bad]) / _EPS)))
            if np.isfinite(error[bad]).all()
            else 300
        )
        fine = _elastic_model(name, alpha, kappa, n_terms, max(40, digits + 25))
        value[bad] = [
            fine.evaluate_mp(ti, fi, derivative) for ti, fi in zip(t[bad], f[bad], strict=True)
        ]
    return value


# ------------------------------------------------------------------ public API


def _prepare(t, alpha, f, kappa):
    t_arr, t_scalar = real_array("t", t)
    a_arr, a_scalar = real_array("alpha", alpha, lower=0.0, strict=True)
    f_arr, f_scalar = real_array("f", f, lower=0.0)
    k_arr, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    shape = np.broadcast_shapes(t_arr.shape, a_arr.shape, f_arr.shape, k_arr.shape)
    flat = [np.broadcast_to(v, shape).ravel() for v in (t_arr, a_arr, f_arr, k_arr)]
    return flat, shape, t_scalar and a_scalar and f_scalar and k_scalar


def _evaluate(which: str, t, alpha, f, kappa):
    (t, a, ff, k), shape, scalar = _prepare(t, alpha, f, kappa)
    out = np.zeros(t.size)
    rigid = (t >= 0) & np.isinf(k)
    if rigid.any():
        out[rigid] = _rigid_evaluate(which, t[rigid], a[rigid], ff[rigid])
    elastic = (t >= 0) & ~np.isinf(k)
    if elastic.any():
        idx = np.flatnonzero(elastic)
        keys = np.stack([a[idx], k[idx]], axis=1)
        uk, inverse = np.unique(keys, axis=0, return_inverse=True)
        name = "Y" if which == "y" else "N"
        for g, (ag, kg) in enumerate(uk):
            sel = idx[inverse.ravel() == g]
            out[sel] = _elastic(name, t[sel], float(ag), float(kg), ff[sel])
    return finish(out.reshape(shape), scalar)


def displacement(
    t: ArrayLike, alpha: ArrayLike, f: ArrayLike, kappa: ArrayLike = np.inf
) -> float | np.ndarray:
    r"""Striker displacement :math:`y(t)` of the persistent-contact solution.

    The sum of the inverted terms of the delay series of :math:`Y(s)` (eq. (2) for
    rigid contact) whose delay :math:`2k \le t` has arrived,

    .. math::

        y(t) = \sum_{k=0}^{\lfloor t/2 \rfloor} y_k(t - 2k), \qquad
        y_k = \mathcal{L}^{-1}\{Y_k\},

    evaluated stably (see the module notes); :math:`y = 0` for :math:`t < 0`. Units:
    :math:`v_0 L / c` for :math:`y`, :math:`L / c` for :math:`t`.

    Parameters
    ----------
    t : float or array_like
        Normalized time (one wave transit = 1).
    alpha : float or array_like
        Mass ratio :math:`M / m_{rod} > 0`.
    f : float or array_like
        Normalized pressing force :math:`F c / (EA v_0) \ge 0`.
    kappa : float or array_like, optional
        Contact stiffness :math:`k_c L / (EA) > 0`; ``inf`` (default) is rigid.

    Returns
    -------
    float or numpy.ndarray
        :math:`y(t)`, broadcast over the arguments (a float if all are scalars).

    Raises
    ------
    ValueError
        For ``alpha <= 0``, ``f < 0``, ``kappa <= 0`` or non-finite values.

    Examples
    --------
    Before the first reflection returns (:math:`t < 2`) a rigid striker with
    :math:`f = 0` moves as :math:`y = \alpha (1 - e^{-t/\alpha})`:

    >>> import numpy as np
    >>> bool(abs(displacement(1.0, 0.5, 0.0) - 0.5 * (1 - np.exp(-2.0))) < 1e-15)
    True
    >>> displacement([-1.0, 0.0], 1.0, 0.0).tolist()
    [0.0, 0.0]
    """
    return _evaluate("y", t, alpha, f, kappa)


def contact_force(
    t: ArrayLike, alpha: ArrayLike, f: ArrayLike, kappa: ArrayLike = np.inf
) -> float | np.ndarray:
    r"""Contact force :math:`N(t)` of the persistent-contact solution.

    The sum of the inverted terms of the delay series of
    :math:`N(s) = -\partial_\xi W(0, s)` whose delay has arrived; for rigid contact

    .. math::

        N(s) = \frac{\alpha s + f}{s(\alpha s + 1)}
             + \sum_{n \ge 2} \frac{2\alpha(\alpha s + f)(\alpha s - 1)^{n-2}}
               {(\alpha s + 1)^n} e^{-2(n-1)s},

    which jumps by 2 whenever a reflection returns (:math:`t = 2, 4, \dots`; the
    value there is the right limit). :math:`N = 0` for :math:`t < 0`. Unit:
    :math:`EA v_0 / c`, compression positive.

    Parameters
    ----------
    t, alpha, f, kappa
        As for :func:`displacement`.

    Returns
    -------
    float or numpy.ndarray
        :math:`N(t)`.

    Examples
    --------
    Classical rigid striker (:math:`f = 0`): :math:`N = e^{-t/\alpha}` until the
    reflection returns at :math:`t = 2`:

    >>> import numpy as np
    >>> bool(abs(contact_force(1.5, 2.0, 0.0) - np.exp(-0.75)) < 1e-15)
    True
    >>> contact_force(0.0, 2.0, 0.0)
    1.0
    """
    return _evaluate("N", t, alpha, f, kappa)


def _check_t_max(t_max):
    if t_max is None:
        return None
    value, scalar = real_array("t_max", t_max, lower=0.0, strict=True)
    if not scalar:
        raise TypeError(f"t_max must be a real number, got {t_max!r}")
    return float(value)


class _Pairs:
    """``y`` or ``N`` (and the derivative) on reflection interval ``m`` for many
    parameter pairs: ``g(tau, m, p)`` with ``p`` the pair index of every point."""

    def __init__(self, which: str, alpha, f, kappa, n_intervals: int) -> None:
        self.which, self.alpha, self.f, self.kappa = which, alpha, f, kappa
        self.rigid = np.isinf(kappa)
        ua, a_idx = np.unique(np.where(self.rigid, alpha, 1.0), return_inverse=True)
        self.a_idx = a_idx.ravel()
        self.tables = _rigid_tables(ua, n_intervals + 1)
        keys = np.stack([alpha, np.where(self.rigid, 0.0, kappa)], axis=1)
        self.groups, inverse = np.unique(keys, axis=0, return_inverse=True)
        self.group = inverse.ravel()

    def __call__(self, tau, m, p, derivative=False):
        m, p = m.astype(np.int64), p.astype(np.int64)
        out = np.empty(tau.size)
        rigid = self.rigid[p]
        if rigid.any():
            pr = p[rigid]
            out[rigid] = _rigid_local(
                self.which,
                m[rigid],
                tau[rigid],
                self.a_idx[pr],
                self.alpha[pr],
                self.f[pr],
                self.tables,
                derivative,
            )
        if not rigid.all():
            name = "Y" if self.which == "y" else "N"
            for g in np.unique(self.group[p[~rigid]]):
                sel = np.flatnonzero(~rigid & (self.group[p] == g))
                a, k = self.groups[g]
                out[sel] = _elastic(
                    name, 2.0 * m[sel] + tau[sel], float(a), float(k), self.f[p[sel]], derivative
                )
        return out

    def derivative(self, tau, m, p):
        return self(tau, m, p, derivative=True)


def contact_time(
    alpha: ArrayLike,
    f: ArrayLike,
    condition: str = "force",
    kappa: ArrayLike = np.inf,
    *,
    t_max: float | None = None,
) -> float | np.ndarray:
    r"""First zero crossing of the contact force or the displacement after impact.

    The contact time :math:`t_c` is the first :math:`t > 0` where the
    persistent-contact solution reaches the non-contact side: :math:`N(t) \le 0`
    (``condition="force"``, the paper's *Kraftbedingung*) or :math:`y(t) \le 0`
    (``condition="position"``, *Ortsbedingung*). Without such a crossing up to
    ``t_max`` the striker sticks and :math:`t_c = \infty`.

    Each reflection interval :math:`[2m, 2m+2]` is sampled on a grid uniform in
    :math:`\sqrt{\tau}`, fine enough for the Laguerre functions of order :math:`m`,
    whose phase grows like :math:`2\sqrt{m x}`, :math:`x = 2\tau/\alpha`: right after
    many reflections the force oscillates on a time scale :math:`\alpha/m` (about 16
    samples per oscillation; the pole time scale stands in for :math:`\alpha` with
    finite :math:`\kappa`). The first sign change is bracketed and polished with
    :func:`impactsym.numeric.bracketed_newton`. Sign changes closer together than
    the sampling step can be missed.

    Parameters
    ----------
    alpha : float or array_like
        Mass ratio, > 0.
    f : float or array_like
        Pressing force, >= 0.
    condition : {"force", "position"}
        Contact condition.
    kappa : float or array_like, optional
        Contact stiffness, > 0; ``inf`` (default) is rigid.
    t_max : float, optional
        Search horizon; default 100 (50 round trips) for rigid and 20 (10 round
        trips) for finite :math:`\kappa`, the ranges where the time functions are
        verified to 1e-10.

    Returns
    -------
    float or numpy.ndarray
        Contact times, broadcast over ``alpha``, ``f``, ``kappa``; ``inf`` where the
        striker sticks.

    Raises
    ------
    ValueError
        For bad parameter values or an unknown ``condition``.

    Examples
    --------
    Classical rigid striker, :math:`f = 0`: the force is
    :math:`e^{-t/\alpha} + 2 e^{-(t-2)/\alpha}(1 - (t-2)/\alpha)` on :math:`2 < t < 4`
    and vanishes at :math:`t = 2 + \alpha(1 + e^{-2/\alpha}/2)`:

    >>> import numpy as np
    >>> t_c = contact_time(0.5, 0.0)
    >>> bool(abs(t_c - (2 + 0.5 * (1 + np.exp(-4.0) / 2))) < 1e-12)
    True
    """
    condition = check_condition(condition)
    a_arr, a_scalar = real_array("alpha", alpha, lower=0.0, strict=True)
    f_arr, f_scalar = real_array("f", f, lower=0.0)
    k_arr, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    horizon = _check_t_max(t_max)
    shape = np.broadcast_shapes(a_arr.shape, f_arr.shape, k_arr.shape)
    a, ff, k = (np.broadcast_to(v, shape).ravel().copy() for v in (a_arr, f_arr, k_arr))
    rigid = np.isinf(k)
    limit = np.where(rigid, 100.0, 20.0) if horizon is None else np.full(a.size, horizon)
    n_intervals = int(np.ceil(limit.max() / 2.0)) if a.size else 0
    fn = _Pairs("N" if condition == "force" else "y", a, ff, k, n_intervals)
    # sampling grid uniform in sqrt(tau): on interval m the Laguerre functions of
    # order <= m oscillate with phase ~ 2 sqrt(m x), x = 2 tau / alpha (and the
    # pole time scale 1/|p| plays the part of alpha for finite kappa)
    scale = a / 2.0
    if not rigid.all():
        for g, (ag, kg) in enumerate(fn.groups):
            if kg > 0:
                model = _elastic_model("N", float(ag), float(kg), 1)
                sel = fn.group == g
                scale[sel] = np.minimum(scale[sel], 0.5 / model.fastest)
    root_step = np.sqrt(scale) * np.pi / 16.0
    result = np.full(a.size, np.inf)
    active = np.arange(a.size)
    for m in range(n_intervals):
        active = active[limit[active] > 2.0 * m]
        if active.size == 0:
            break
        length = np.minimum(2.0, limit[active] - 2.0 * m)
        du = root_step[active] / np.sqrt(m + 1.0)
        n_steps = np.clip(np.ceil(np.sqrt(length) / du), 16, 8192).astype(np.int64)
        counts = n_steps + 1
        p = np.repeat(active, counts)
        first = np.cumsum(counts) - counts
        k_idx = np.arange(p.size) - np.repeat(first, counts)
        tau = np.repeat(length, counts) * (k_idx / np.repeat(n_steps, counts)) ** 2
        values = fn(tau, np.full(p.size, m), p)
        hit = (values <= 0) & (k_idx >= (1 if m == 0 else 0))
        position = np.where(hit, np.arange(p.size), p.size)
        first_hit = np.minimum.reduceat(position, first)
        found = first_hit < p.size
        if not found.any():
            continue
        idx = first_hit[found]
        pairs = active[found]
        at_start = k_idx[idx] == 0
        result[pairs[at_start]] = 2.0 * m
        inner = ~at_start
        if inner.any():
            lo, hi = tau[idx[inner] - 1], tau[idx[inner]]
            pp = pairs[inner]
            root = bracketed_newton(
                fn, fn.derivative, lo, hi, [np.full(pp.size, float(m)), pp.astype(np.float64)]
            )
            result[pp] = 2.0 * m + root
        active = active[~found]
    return finish(result.reshape(shape), a_scalar and f_scalar and k_scalar)


@dataclass(frozen=True)
class ContactTimeMap:
    """Contact times of both conditions over an ``alpha``-``f`` grid.

    Attributes
    ----------
    alpha, f : numpy.ndarray
        The grid axes (1-D).
    force, position : numpy.ndarray
        Contact times, shape ``(len(f), len(alpha))``; ``inf`` where the striker sticks.
    kappa, t_max : float
        Contact stiffness and search horizon used.

    Examples
    --------
    >>> study = contact_time_map([0.1, 30.0], [0.0, 2.0])
    >>> study.force.shape, bool(np.isinf(study.force[1, 0]))  # alpha=0.1, f=2 sticks
    ((2, 2), True)
    >>> study.rows()[1][:2]
    (30.0, 0.0)
    """

    alpha: np.ndarray
    f: np.ndarray
    force: np.ndarray
    position: np.ndarray
    kappa: float
    t_max: float

    @property
    def ratio(self) -> np.ndarray:
        """``position / force`` where both release, NaN where either sticks."""
        both = np.isfinite(self.force) & np.isfinite(self.position)
        out = np.full(self.force.shape, np.nan)
        out[both] = self.position[both] / self.force[both]
        return out

    def rows(self) -> list[tuple[float, ...]]:
        """``(alpha, f, t_force, t_position, ratio)`` per grid point, for tables."""
        A, F = np.meshgrid(self.alpha, self.f)
        columns = (A, F, self.force, self.position, self.ratio)
        return list(zip(*(c.ravel().tolist() for c in columns), strict=True))

    def plot(self, axes: Any = None) -> Any:
        """Maps of both contact times and their ratio (see
        :func:`impactsym.plotting.rod.plot_contact_time_maps`)."""
        from impactsym.plotting.rod import plot_contact_time_maps

        return plot_contact_time_maps(self, axes)


def contact_time_map(
    alpha: ArrayLike, f: ArrayLike, kappa: float = np.inf, *, t_max: float | None = None
) -> ContactTimeMap:
    """Contact times under the force and the position condition on an ``alpha``-``f`` grid.

    The paper's parameter study: :func:`contact_time` for both conditions at every
    pair of the 1-D axes ``alpha`` and ``f`` (rows: ``f``, columns: ``alpha``).

    Examples
    --------
    >>> study = contact_time_map([0.5, 50.0], [0.0])
    >>> study.force.shape
    (1, 2)
    >>> bool(abs(study.ratio[0, 1] - 1) < 0.05)  # heavy striker: the conditions agree
    True
    """
    a_axis, _ = real_array("alpha", alpha, lower=0.0, strict=True)
    f_axis, _ = real_array("f", f, lower=0.0)
    a_axis, f_axis = np.atleast_1d(a_axis), np.atleast_1d(f_axis)
    if a_axis.ndim != 1 or f_axis.ndim != 1:
        raise ValueError("alpha and f must be 1-D axes of the grid")
    A, F = np.meshgrid(a_axis, f_axis)
    horizon = _check_t_max(t_max)
    times = {c: contact_time(A, F, c, kappa, t_max=horizon) for c in ("force", "position")}
    if horizon is None:
        horizon = 100.0 if np.isinf(kappa) else 20.0
    return ContactTimeMap(a_axis, f_axis, times["force"], times["position"], float(kappa), horizon)


# ------------------------------------------------------------ generated module

_HEADER = '''"""Rod impact time functions, rigid contact (generated by impactsym; needs NumPy only).

Persistent-contact solution of a mass (ratio ``alpha``) with pressing force ``f``
striking an elastic rod fixed at its far end (Waltersberger, Keppler, Wauer, PAMM
2004, section 1): the inverse Laplace transforms of the delay series of eq. (2),
summed over the reflections that have arrived, evaluated with Laguerre functions.
Normalization: t in units of L/c, y in v0 L/c, N in EA v0/c.
"""

import numpy as np
'''

_WRAPPERS = '''

def _check(t, alpha, f):
    t, alpha, f = (np.asarray(v, dtype=np.float64) for v in (t, alpha, f))
    for name, v in (("t", t), ("alpha", alpha), ("f", f)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be finite")
    if np.any(alpha <= 0):
        raise ValueError("alpha must be > 0")
    if np.any(f < 0):
        raise ValueError("f must be >= 0")
    shape = np.broadcast_shapes(t.shape, alpha.shape, f.shape)
    return [np.broadcast_to(v, shape).ravel() for v in (t, alpha, f)], shape


def _rod(which, t, alpha, f):
    (t, alpha, f), shape = _check(t, alpha, f)
    out = np.zeros(t.size)
    arrived = t >= 0
    if arrived.any():
        out[arrived] = _rigid_evaluate(which, t[arrived], alpha[arrived], f[arrived])
    out = out.reshape(shape)
    return float(out) if out.ndim == 0 else out


def rod_displacement(t, alpha, f):
    """Striker displacement y(t), rigid contact (inverse of eq. (2), the series of Y(s)).

    Parameters: t -- normalized time (array_like); alpha -- mass ratio M/m_rod > 0;
    f -- normalized pressing force F c/(EA v0) >= 0. Returns y(t); 0 for t < 0.
    """
    return _rod("y", t, alpha, f)


def rod_contact_force(t, alpha, f):
    """Contact force N(t) = -dw/dxi(0, t), rigid contact (series of N(s) of eq. (1)).

    Parameters: t -- normalized time (array_like); alpha -- mass ratio M/m_rod > 0;
    f -- normalized pressing force F c/(EA v0) >= 0. Returns N(t) (compression
    positive, right-continuous at the reflection times t = 2, 4, ...); 0 for t < 0.
    """
    return _rod("N", t, alpha, f)
'''


def numpy_source() -> str:
    """Self-contained NumPy-only Python source of the rigid-contact time functions.

    Defines ``rod_displacement(t, alpha, f)`` and ``rod_contact_force(t, alpha, f)``
    (the same kernel as :func:`displacement` and :func:`contact_force` with
    ``kappa=inf``). The finite-stiffness functions need mpmath for their pole data
    and are not part of it.

    Examples
    --------
    >>> namespace = {}
    >>> exec(numpy_source(), namespace)
    >>> namespace["rod_contact_force"](1.0, 1.0, 0.0) == contact_force(1.0, 1.0, 0.0)
    True
    """
    kernel = "\n\n".join(
        inspect.getsource(fn) for fn in (_rigid_tables, _rigid_local, _rigid_evaluate)
    )
    return _HEADER + "\n\n" + kernel + _WRAPPERS
