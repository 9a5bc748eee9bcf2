"""Finite contact stiffness, method 1: the rod time functions as pole sums.

Every term :math:`k` of the delay series of :math:`Y` or :math:`N` (eq. (2) with the
contact spring of eq. (1)) inverts to :math:`\\sum_p e^{p u} \\sum_j c_{pj} u^j`,
:math:`u = t - 2k`, over the poles :math:`p` (the roots of :math:`P = \\alpha s^2 +
\\alpha\\kappa s + \\kappa` and :math:`s = 0`). The coefficients come from the symbolic
series in mpmath (40 digits or more: they are exact data); the sum is evaluated in
complex float64 with a rounding-error bound, and where that bound exceeds ``1e-12`` --
near critical contact damping, :math:`\\alpha\\kappa \\approx 4`, where the per-pole
parts cancel -- again in mpmath at the precision the bound asks for. Pointwise and slow
(a point costs up to milliseconds), but exact data: the reference of the two tables
(:mod:`impactsym.rod.elastic.cells`, :mod:`impactsym.rod.elastic.taylor`) and their
fallback. See docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

#: Absolute error allowed for the float path of the finite-stiffness evaluation.
_TOLERANCE = 1e-12
#: Largest normalized time evaluated with a finite contact stiffness (the time
#: functions are verified to 1e-10 up to there).
T_LIMIT_ELASTIC = 20.0
_EPS = np.finfo(np.float64).eps


def check_which(which: str) -> str:
    """Internal: ``which`` time function, ``"y"`` (displacement) or ``"N"`` (force), or
    ValueError naming it."""
    if which not in ("y", "N"):
        raise ValueError(f"which must be 'y' or 'N', got {which!r}")
    return which


@lru_cache(maxsize=8)
def series_coefficients(which: str, n_terms: int) -> tuple:
    """Internal: the finite-stiffness series of ``which`` (``"y"`` or ``"N"``) as
    numerator-coefficient functions (used by :mod:`impactsym.rod.elastic.cells`).

    Every term of :meth:`impactsym.rod.RodImpact.series` (of ``"Y"`` resp. ``"N"``) is
    ``numerator(s) / (const * s**m0 * P**n)`` with ``P = alpha s**2 + alpha kappa s
    + kappa``; returns ``(delay, m0, n, fn)`` per term, ``fn(alpha, kappa)`` giving
    (mpmath) the numerator coefficients, highest power first, for ``f**0`` and
    ``f**1``, and ``const``.
    """
    import sympy as sp

    from impactsym.rod.derivation import RodImpact, alpha, f, kappa, s

    P = sp.expand(alpha * s**2 + alpha * kappa * s + kappa)
    out = []
    name = "Y" if check_which(which) == "y" else "N"
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
        inv = 1 / d  # binom(-mo, j) = (-1)**j binom(mo + j - 1, j), an exact integer
        factor = [d ** (-mo)]
        for j in range(1, m):
            factor.append(factor[-1] * inv * mp.mpf(-(mo + j - 1)) / j)
        series = [mp.fdot(series[: j + 1], factor[j::-1]) for j in range(m)]
    return [series[m - 1 - p] / (lead * mp.factorial(p)) for p in range(m)]


class PoleModel:
    """Internal: exact pole data of the first ``n_terms`` finite-stiffness terms of
    ``which`` (built by :func:`pole_model`).

    For term ``k`` (delay ``2k``) ``parts[k]`` lists ``(root, c0, c1, pair)``: the
    term is ``sum exp(root u) (c0(u) + f c1(u))`` (``2 Re`` of it if ``pair``), with
    the coefficients computed at ``dps`` digits; ``dparts`` is the same for the
    derivative in ``u``.
    """

    def __init__(self, which: str, alpha: float, kappa: float, n_terms: int, dps: int) -> None:
        import mpmath as mp

        from impactsym.numeric.precision import workdps  # (mpmath: not in exported code)

        self.dps = dps
        self._shift_cache: dict = {}
        self.parts: list[list] = []
        self.dparts: list[list] = []
        self.d2parts: list[list] = []
        with workdps(dps):
            a, k = mp.mpf(alpha), mp.mpf(kappa)
            disc = a * a * k * k - 4 * a * k  # exact: products of doubles fit in dps
            if disc == 0:
                roots = [(-k / 2, 2)]
            else:
                sq = mp.sqrt(disc) if disc > 0 else mp.mpc(0, mp.sqrt(-disc))
                big = (-a * k - sq) / (2 * a)  # no cancellation; the product is k / a
                roots = [(k / (a * big), 1), (big, 1)]
            self.fastest = float(max(abs(r) for r, _ in roots))
            for _, m0, n, fn in series_coefficients(which, n_terms):
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
                self.d2parts.append(
                    [
                        (
                            complex(r).real,
                            np.array([abs(complex(c)) for c in _derivative(q0, r)]),
                            np.array([abs(complex(c)) for c in _derivative(q1, r)]),
                            2.0 if pair else 1.0,
                        )
                        for r, q0, q1, pair in dparts
                    ]
                )

    def evaluate(self, u_terms, f, derivative=False):
        """Float sum of the terms at ``u_terms[k]`` (``u = t - 2k``, NaN if not arrived)
        and a bound on its rounding error (NaN or inf where float64 overflows, e.g.
        for an extreme ``kappa``: those points are re-evaluated with mpmath)."""
        with np.errstate(all="ignore"):
            return self._evaluate(u_terms, f, derivative)

    def _shifted(self, derivative, k, centre):
        """Float coefficients of term ``k`` re-expanded about ``u = centre`` (an odd
        integer): per part ``(root, d0, d1, pair)`` with ``c(centre + e) = sum d_j e^j``.

        The shift is done with mpmath at the model's precision from the exact pole
        data, so the alternating, large coefficients of the later terms do not cancel in
        float64 (docs/physics.md#finite-contact-stiffness-three-methods). Cached per
        ``(derivative, k, centre)``, shared by every ``f``.
        """
        key = (derivative, k, centre)
        cached = self._shift_cache.get(key)
        if cached is not None:
            return cached
        import mpmath as mp

        from impactsym.numeric.precision import workdps  # (mpmath: not in exported code)

        out = []
        with workdps(self.dps):
            c = mp.mpf(centre)
            for r, p0, p1, pair in (self.dparts if derivative else self.parts)[k]:
                shifted = []
                for coeffs in (p0, p1):
                    n = len(coeffs)
                    d = [
                        mp.fsum(mp.binomial(j, i) * coeffs[j] * c ** (j - i) for j in range(i, n))
                        for i in range(n)
                    ]
                    shifted.append(np.array([complex(x) for x in d]))
                out.append((complex(r), shifted[0], shifted[1], pair))
        self._shift_cache[key] = out
        return out

    def _evaluate(self, u_terms, f, derivative):
        value = np.zeros(np.shape(f))
        bound = np.zeros(np.shape(f))
        n_parts = len(self.dparts if derivative else self.parts)
        for k in range(n_parts):
            u = u_terms[k]
            arrived = u >= 0
            if not arrived.any():
                continue
            ua, fa = u[arrived], f[arrived]
            # centre 2j + 1 of the unit-2 cell [2j, 2j + 2] holding u; |e| <= 1
            cell = np.minimum(np.floor(0.5 * ua), T_LIMIT_ELASTIC // 2).astype(np.int64)
            for j in np.unique(cell):
                sel = np.flatnonzero(cell == j)
                centre = 2 * int(j) + 1
                us, fs = ua[sel], fa[sel]
                e_arg = us - centre
                ae = np.abs(e_arg)
                plain = self._shifted(derivative, k, 0)
                for (r, c0, c1, pair), (_, b0, b1, _) in zip(
                    self._shifted(derivative, k, centre), plain, strict=True
                ):
                    # per point the basis (about the centre or about u = 0) with the
                    # smaller rounding bound: the fast pole's part is small in u only
                    poly, size = _horner(c0, c1, e_arg, ae, fs)
                    poly0, size0 = _horner(b0, b1, us, us, fs)
                    use0 = size0 < size
                    poly, size = np.where(use0, poly0, poly), np.where(use0, size0, size)
                    e = np.exp(r * us)
                    weight = 2.0 if pair else 1.0
                    idx = np.flatnonzero(arrived)[sel]
                    value[idx] += weight * (poly * e).real
                    # Horner and coefficient rounding, and the exponential's argument
                    # (relative error about |r u| eps, from r and r * u in float64)
                    factor = len(c0) + 4 + 2.0 * abs(r) * us
                    bound[idx] += weight * size * np.abs(e) * factor
        return value, bound * _EPS

    def second_derivative_bound(self, ta, tb, f):
        """Bound on ``|g''|`` over ``[ta, tb]`` (arrays; ``f`` per cell).

        Every arrived term is ``e^{r u} P(u)``, ``u = t - 2k``, with ``Re r <= 0``:
        its second derivative is ``e^{r u} P2(u)``, bounded on the cell by
        ``e^{Re r u_lo} sum_j |P2_j| u_hi^j``.
        """
        total = np.zeros(np.shape(ta))
        for k, parts in enumerate(self.d2parts):
            u_hi = tb - 2.0 * k
            live = u_hi > 0
            if not live.any():
                continue
            u_lo = np.maximum(ta[live] - 2.0 * k, 0.0)
            uh, fl = u_hi[live], f[live]
            for re, a0, a1, weight in parts:
                size = np.zeros(uh.size)
                for q0, q1 in zip(a0[::-1], a1[::-1], strict=True):
                    size = size * uh + (q0 + fl * q1)
                total[live] += weight * np.exp(re * u_lo) * size
        return total * (1.0 + 1e-12)

    def evaluate_mp(self, t, f, derivative=False):
        """The same sum with mpmath at the model's precision (one point)."""
        import mpmath as mp

        from impactsym.numeric.precision import workdps  # (mpmath: not in exported code)

        with workdps(self.dps):
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


def _horner(c0, c1, x, ax, f):
    """``sum (c0_j + f c1_j) x^j`` and ``sum (|c0_j| + f |c1_j|) |x|^j`` by Horner."""
    poly = np.zeros(x.size, dtype=complex)
    size = np.zeros(x.size)
    for q0, q1 in zip(c0[::-1], c1[::-1], strict=True):
        poly = poly * x + (q0 + f * q1)
        size = size * ax + np.abs(q0) + f * np.abs(q1)
    return poly, size


def _derivative(coeffs: list, r) -> list:
    """Coefficients of d/du [exp(r u) sum_p c_p u**p] in the same form."""
    n = len(coeffs)
    return [r * coeffs[p] + ((p + 1) * coeffs[p + 1] if p + 1 < n else 0) for p in range(n)]


def pole_model(which: str, alpha: float, *, kappa: float, n_terms: int, dps: int = 40) -> PoleModel:
    """Internal: the cached :class:`PoleModel` of ``which`` (``"y"`` or ``"N"``) at ``dps``
    digits (one cache key whether ``dps`` is given or not)."""
    return _cached_model(which, float(alpha), float(kappa), int(n_terms), int(dps))


def clear_cache() -> None:
    """Internal: forget every cached :class:`PoleModel` (to time cold builds)."""
    _cached_model.cache_clear()


@lru_cache(maxsize=64)
def _cached_model(which: str, alpha: float, kappa: float, n_terms: int, dps: int):
    return PoleModel(which, alpha, kappa, n_terms, dps)


def time_function(
    which: str,
    t: np.ndarray,
    alpha: float,
    f: np.ndarray,
    *,
    kappa: float,
    derivative: bool = False,
    n_terms: int = 0,
) -> np.ndarray:
    """Internal: finite-stiffness ``y`` or ``N`` (``which``), or its time derivative, at flat
    times ``0 <= t <= T_LIMIT_ELASTIC`` and forces ``f`` for one ``(alpha, kappa)``;
    float64 where the rounding bound is below ``1e-12``, mpmath elsewhere.

    The pole model has the terms arrived by ``max(t)``, or ``n_terms`` if more: a caller
    evaluating many batches (the contact-time search) passes its own count so that every
    batch shares one cached model and one symbolic series (terms not arrived add
    nothing, so the values are the same)."""
    if t.size and not np.max(t) <= T_LIMIT_ELASTIC:
        raise ValueError(
            f"t must be <= {T_LIMIT_ELASTIC:g} for a finite kappa (the range where the "
            f"finite-stiffness functions are verified), got t = {float(np.max(t))!r}"
        )
    n_terms = max(int(np.max(t) // 2) + 1, n_terms)
    model = pole_model(which, alpha, kappa=kappa, n_terms=n_terms)
    u_terms = [t - 2.0 * k for k in range(n_terms)]
    value, error = model.evaluate(u_terms, f, derivative)
    bad = np.flatnonzero(~(error <= _TOLERANCE))
    if bad.size:  # mpmath where float64 cancels (near critical damping)
        digits = (
            int(np.ceil(np.log10(np.max(error[bad]) / _EPS)))
            if np.isfinite(error[bad]).all()
            else 300
        )
        fine = pole_model(which, alpha, kappa=kappa, n_terms=n_terms, dps=max(40, digits + 25))
        value[bad] = [
            fine.evaluate_mp(ti, fi, derivative) for ti, fi in zip(t[bad], f[bad], strict=True)
        ]
    return value
