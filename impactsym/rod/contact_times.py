"""Contact times of the rod impact: certified first sign changes of :math:`y(t)` and :math:`N(t)`.

The public face: :func:`contact_time`, :func:`contact_time_map` and its result
:class:`ContactTimeMap`. The searches live in :mod:`impactsym.rod.rigid_search` (rigid
contact) and :mod:`impactsym.rod.elastic.search` (finite :math:`\\kappa`); see
`docs/physics.md#rod-contact-times`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from impactsym.records import ArrayRecord
from impactsym.rod.elastic.poles import T_LIMIT_ELASTIC
from impactsym.rod.elastic.search import elastic_contact_times
from impactsym.rod.kernel import T_LIMIT, check_alpha
from impactsym.rod.rigid_search import rigid_contact_times
from impactsym.validation import broadcast, check_condition, finish, real_array

__all__ = ["ContactTimeMap", "contact_time", "contact_time_map"]

#: Default search horizons (rigid, finite stiffness).
T_MAX_RIGID, T_MAX_ELASTIC = 100.0, 20.0


def _check_t_max(t_max, rigid):
    if t_max is None:
        return None
    value, scalar = real_array("t_max", t_max, lower=0.0, strict=True)
    if not scalar:
        raise TypeError(f"t_max must be a real number, got {t_max!r}")
    limit = T_LIMIT if rigid else T_LIMIT_ELASTIC
    if value > limit:
        kind = "rigid contact" if rigid else "finite kappa"
        raise ValueError(f"t_max must be <= {limit:g} for {kind}, got {float(value)!r}")
    return float(value)


def contact_time(
    alpha: ArrayLike,
    f: ArrayLike,
    *,
    condition: str,
    kappa: ArrayLike = np.inf,
    t_max: float | None = None,
) -> float | np.ndarray:
    r"""First sign change of the contact force or the displacement after impact.

    The contact time :math:`t_c` is the first :math:`t > 0` where the persistent-contact
    solution :math:`g = N` (``condition="force"``, *Kraftbedingung*) or :math:`g = y`
    (``condition="position"``, *Ortsbedingung*) goes from positive to :math:`\le 0`;
    ``inf``: no sign change in :math:`(0, t_{max}]` (the striker sticks up to the horizon).

    **Certified, not sampled**, so that no end of contact is missed: a rigorous bound on
    :math:`|g''|` proves each cell zero-free or monotone, or it is halved
    (:mod:`impactsym.rod.rigid_search`, :mod:`impactsym.rod.elastic.search`); the first
    sign change is polished to full precision. A tangential touch is no end of contact;
    only a dip shallower than ``1e-12`` (``2e-12`` with a finite :math:`\kappa`) may be
    passed over. With a finite :math:`\kappa` a sign change counts where :math:`g` is
    proven negative (below ``-2e-12``, twice the tables' error bound), and the contact
    ends at the zero just before: a force decaying to zero without crossing it (an
    over-damped light striker) is not ended where a table rounds it below zero. Pairs
    of equal :math:`\alpha` share the proofs (:math:`g` is affine in :math:`f`), so a
    grid is cheaper per pair. See `docs/physics.md#rod-contact-times`.

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
        trips) for finite :math:`\kappa`; at most 1e4 resp. 20 (where the time
        functions are verified).

    Returns
    -------
    float or numpy.ndarray
        Contact times, broadcast over ``alpha``, ``f``, ``kappa``; ``inf`` where no
        sign change occurs up to ``t_max``.

    Raises
    ------
    ValueError
        For bad parameter values, an unknown ``condition`` or ``t_max`` beyond the
        verified range.

    Examples
    --------
    Classical rigid striker, :math:`f = 0`: the force is
    :math:`e^{-t/\alpha} + 2 e^{-(t-2)/\alpha}(1 - (t-2)/\alpha)` on :math:`2 < t < 4`
    and vanishes at :math:`t = 2 + \alpha(1 + e^{-2/\alpha}/2)`:

    >>> import numpy as np
    >>> t_c = contact_time(0.5, 0.0, condition="force")
    >>> bool(abs(t_c - (2 + 0.5 * (1 + np.exp(-4.0) / 2))) < 1e-12)
    True
    >>> contact_time(0.05, 2.0, condition="force")  # a light striker pressed hard sticks
    inf
    """
    condition = check_condition(condition)
    a_arr, a_scalar = real_array("alpha", alpha, lower=0.0, strict=True)
    check_alpha(a_arr)
    f_arr, f_scalar = real_array("f", f, lower=0.0)
    k_arr, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    shape = broadcast(alpha=a_arr, f=f_arr, kappa=k_arr)
    a, ff, k = (np.broadcast_to(v, shape).ravel().copy() for v in (a_arr, f_arr, k_arr))
    rigid = np.isinf(k)
    which = "N" if condition == "force" else "y"
    result = np.full(a.size, np.inf)
    if rigid.any():
        horizon = _check_t_max(t_max, True)
        horizon = T_MAX_RIGID if horizon is None else horizon
        result[rigid] = rigid_contact_times(which, a[rigid], ff[rigid], t_max=horizon)
    if not rigid.all():
        horizon = _check_t_max(t_max, False)
        horizon = T_MAX_ELASTIC if horizon is None else horizon
        result[~rigid] = elastic_contact_times(
            which, a[~rigid], ff[~rigid], kappa=k[~rigid], t_max=horizon
        )
    return finish(result.reshape(shape), a_scalar and f_scalar and k_scalar)


@dataclass(frozen=True, eq=False)
class ContactTimeMap(ArrayRecord):
    """Contact times of both conditions over an ``alpha``-``f`` grid.

    ``==`` compares the values (arrays element by element, see
    :class:`impactsym.records.ArrayRecord`); the hash is that of ``kappa`` and
    ``t_max``.

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

    def interval(self, *, condition: str) -> np.ndarray:
        """Reflection interval on which the first contact ends, :math:`\\lfloor t_c/2
        \\rfloor` (1: between the first and the second return of the reflected wave,
        :math:`2 \\le t_c < 4`); NaN where the striker sticks.

        >>> contact_time_map([0.5], [0.0]).interval(condition="force").tolist()
        [[1.0]]
        """
        times = {"force": self.force, "position": self.position}[check_condition(condition)]
        with np.errstate(invalid="ignore"):
            return np.where(np.isfinite(times), np.floor(times / 2.0), np.nan)

    def rows(self) -> list[tuple[float, ...]]:
        """``(alpha, f, t_force, t_position, ratio)`` per grid point, for tables."""
        A, F = np.meshgrid(self.alpha, self.f)
        columns = (A, F, self.force, self.position, self.ratio)
        return list(zip(*(c.ravel().tolist() for c in columns), strict=True))

    def plot(self, *, axes: Any = None) -> Any:
        """Atlases of both contact times and their ratio (see
        :func:`impactsym.plotting.rod.plot_contact_time_atlases`)."""
        from impactsym.plotting.rod import plot_contact_time_atlases

        return plot_contact_time_atlases(self, axes=axes)


def contact_time_map(
    alpha: ArrayLike, f: ArrayLike, *, kappa: float = np.inf, t_max: float | None = None
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
    k_value, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    if not k_scalar:
        raise TypeError(f"kappa must be a single number for a map, got {kappa!r}")
    kappa = float(k_value)
    A, F = np.meshgrid(a_axis, f_axis)
    horizon = _check_t_max(t_max, bool(np.isinf(kappa)))
    times = {
        c: contact_time(A, F, condition=c, kappa=kappa, t_max=horizon)
        for c in ("force", "position")
    }
    if horizon is None:
        horizon = T_MAX_RIGID if np.isinf(kappa) else T_MAX_ELASTIC
    return ContactTimeMap(a_axis, f_axis, times["force"], times["position"], float(kappa), horizon)
