"""Contact times of the rod impact: first sign changes of :math:`y(t)` and :math:`N(t)`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from impactsym.numeric.roots import bracketed_newton
from impactsym.rod.elastic import _elastic, _elastic_model
from impactsym.rod.kernel import _rigid_local, _rigid_tables
from impactsym.validation import check_condition, finish, real_array

__all__ = ["ContactTimeMap", "contact_time", "contact_time_map"]


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
