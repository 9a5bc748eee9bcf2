"""Public rod time functions :math:`y(t)` and :math:`N(t)` of the persistent-contact solution.

Dispatch on ``kappa``: rigid contact is evaluated by the NumPy kernel
:mod:`impactsym.rod.kernel`, a finite contact stiffness by the pole sums of
:mod:`impactsym.rod.elastic.poles`; both sum exactly the inverted series terms whose
delay has arrived (docs/physics.md#1-rod-impact-paper-1).
"""

from __future__ import annotations

import numbers

import numpy as np
from numpy.typing import ArrayLike

from impactsym.rod.elastic.poles import time_function
from impactsym.rod.kernel import check_alpha, rigid_evaluate
from impactsym.validation import broadcast, finish, real_array, renamed

__all__ = ["contact_force", "displacement"]

#: Largest ``max_contacts`` :func:`impact_sequence` accepts: a contact costs about a
#: millisecond, so a larger cap would let a chattering striker run for hours.
MAX_CONTACTS = 1_000_000
_F_MAX = 1e150  # largest pressing force of a sequence: energies of order f^2 stay finite
# Piece budget of a contact spring: a piece costs 1 to 8 ms (rigid: 0.1 ms, budget
# MAX_PIECES), the sequences that succeed need fewer than 2000 to t = 40, and a light
# striker on a soft spring (alpha = 1e-6, kappa = 10) asks for 60000.


def _prepare(t, alpha, f, kappa):
    t_arr, t_scalar = real_array("t", t)
    a_arr, a_scalar = real_array("alpha", alpha, lower=0.0, strict=True)
    check_alpha(a_arr)
    f_arr, f_scalar = real_array("f", f, lower=0.0)
    k_arr, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    shape = broadcast(t=t_arr, alpha=a_arr, f=f_arr, kappa=k_arr)
    flat = [np.broadcast_to(v, shape).ravel() for v in (t_arr, a_arr, f_arr, k_arr)]
    return flat, shape, t_scalar and a_scalar and f_scalar and k_scalar


def _evaluate(which: str, t, alpha, f, kappa):
    (t, a, ff, k), shape, scalar = _prepare(t, alpha, f, kappa)
    out = np.zeros(t.size)
    rigid = (t >= 0) & np.isinf(k)
    if rigid.any():
        out[rigid] = rigid_evaluate(which, t[rigid], a[rigid], ff[rigid])
    elastic = (t >= 0) & ~np.isinf(k)
    if elastic.any():
        idx = np.flatnonzero(elastic)
        keys = np.stack([a[idx], k[idx]], axis=1)
        uk, inverse = np.unique(keys, axis=0, return_inverse=True)
        for g, (ag, kg) in enumerate(uk):
            sel = idx[inverse.ravel() == g]
            out[sel] = time_function(which, t[sel], float(ag), ff[sel], kappa=float(kg))
    return finish(out.reshape(shape), scalar)


def displacement(
    t: ArrayLike, alpha: ArrayLike, f: ArrayLike, *, kappa: ArrayLike = np.inf
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
    t: ArrayLike, alpha: ArrayLike, f: ArrayLike, *, kappa: ArrayLike = np.inf
) -> float | np.ndarray:
    r"""Contact force :math:`N(t)` of the persistent-contact solution (paper section 1).

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


def impact_sequence(
    alpha: float,
    f: float,
    *,
    kappa: float = np.inf,
    t_max: float | None = None,
    max_contacts: int = 2000,
    t_end: float | None = None,
):
    r"""Follow the rod impact through separations, flights and re-contacts to ``t_max``.

    In contact the outgoing wave obeys the delay equation of paper section 1 (rigid:
    :math:`\alpha g' + g = f + \alpha g'(t-2) - g(t-2)`; with a contact spring
    :math:`N = \kappa (y - u)`), in flight :math:`g(t) = -g(t-2)` and
    :math:`\alpha y'' = f`. One event loop (:func:`impactsym.rod.sequence.follow`) runs
    the rigid step model (:mod:`impactsym.rod.sequence_rigid`) or, for a finite
    ``kappa``, the contact-spring one (:mod:`impactsym.rod.sequence_elastic`); events are
    certified roots. See docs/physics.md#the-rod-impact-continued-past-separation.

    Parameters
    ----------
    alpha : float
        Mass ratio :math:`M / m_{rod}`, in the verified range
        :data:`impactsym.rod.kernel.ALPHA_RANGE` (as for :func:`contact_time`).
    f : float
        Pressing force :math:`F c / (EA v_0) \ge 0`, at most ``1e150`` (the energies,
        of order :math:`f^2`, stay finite in float64).
    kappa : float, optional
        Contact stiffness :math:`k_c L / (EA) > 0`; ``inf`` (default) is rigid contact.
        A finite spring is refused, as by :func:`contact_time`, where its fastest time
        scale is below ``1e-8`` (its limit is rigid contact).
    t_max : float, optional
        End of the simulated time (unit :math:`L / c`, at most ``1e4``); default 40.
    max_contacts : int, optional
        Limit on the number of contacts before ``t_max``: a light striker pressed by
        ``f > 0`` chatters on the vibrating rod end with ever shorter flights. Any
        integer type (NumPy's too), from 1 to :data:`MAX_CONTACTS`; memory grows with
        the contacts that occur, not with the cap.
    t_end : float, optional
        Former name of ``t_max`` (give one of the two).

    Returns
    -------
    RodImpactSequence or ElasticRodImpactSequence
        (:mod:`impactsym.rod.sequence`), the latter for a finite ``kappa``.

    Raises
    ------
    ValueError, TypeError
        Before any work, naming the argument: for ``alpha`` outside its range, ``f`` outside
        ``[0, 1e150]``,
        ``kappa <= 0`` or too stiff, ``t_max <= 0``, non-finite or non-scalar input, both
        ``t_max`` and ``t_end``, a ``max_contacts`` that is no integer (``TypeError``) or
        outside ``[1, MAX_CONTACTS]``. During the run: when the float64 pieces stop being
        exact before ``t_max`` (energy balance residual above ``1e-9`` of
        :math:`\alpha/2 + |f y|` in the middle of a piece), or when the pieces of
        :math:`g` would exceed :data:`impactsym.rod.sequence.MAX_PIECES` (20000 for a
        finite ``kappa``, whose pieces cost ten times more): the message names the
        arguments and the time reached.
    RuntimeError
        When more than ``max_contacts`` contacts occur before ``t_max``.

    Examples
    --------
    A light striker (:math:`\alpha < 1.7`, :math:`f = 0`) leaves at
    :math:`t = 2 + \alpha(1 + e^{-2/\alpha}/2)`, after the first reflection returned:

    >>> seq = impact_sequence(0.5, 0.0)
    >>> start, end = seq.contacts[0]
    >>> bool(abs(end - (2 + 0.5 * (1 + np.exp(-4.0) / 2))) < 1e-13)
    True
    >>> bool(abs(seq.restitution - 2 * np.exp(-1 - np.exp(-4.0) / 2)) < 1e-13)
    True
    """
    from impactsym.rod.sequence import MAX_PIECES, follow
    from impactsym.rod.sequence_elastic import follow_spring
    from impactsym.rod.sequence_rigid import RigidStep

    t_max = renamed("t_max", t_max, "t_end", t_end, 40.0)
    a_arr, _ = real_array("alpha", alpha, lower=0.0, strict=True)
    f_arr, _ = real_array("f", f, lower=0.0)
    k_arr, _ = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    t_arr, _ = real_array("t_max", t_max, lower=0.0, strict=True)
    for name, arr in (("alpha", a_arr), ("f", f_arr), ("kappa", k_arr), ("t_max", t_arr)):
        if arr.ndim:
            raise TypeError(f"{name} must be a scalar, got an array of shape {arr.shape}")
    check_alpha(a_arr)
    alpha, f, kappa, t_max = float(a_arr), float(f_arr), float(k_arr), float(t_arr)
    if t_max > 1e4:
        raise ValueError(f"t_max must be <= 1e4, got {t_max}")
    if f > _F_MAX:
        raise ValueError(
            f"f must be <= {_F_MAX:g} (the rod energy, of order f^2, must stay within "
            f"float64), got {f!r}"
        )
    max_contacts = _check_count("max_contacts", max_contacts, MAX_CONTACTS)
    if np.isinf(kappa):
        model = RigidStep(alpha, f, t_max=t_max)
        return follow(model, t_max=t_max, max_contacts=max_contacts, max_pieces=MAX_PIECES)
    from impactsym.rod.elastic.search import check_stiffness

    try:  # the rule of contact_time: too stiff for float64 pieces as well
        check_stiffness(alpha, kappa=kappa)
    except ValueError as exc:
        raise ValueError(f"impact_sequence: {exc}") from None
    return follow_spring(alpha, f, kappa=kappa, t_max=t_max, max_contacts=max_contacts)


def _check_count(name: str, value: object, limit: int) -> int:
    """``value`` as an ``int`` in ``[1, limit]``: any integral type (Python's or NumPy's),
    not ``bool``, refused by ``name`` with ``TypeError`` (no integer) or ``ValueError``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r} of type {type(value).__name__}")
    count = int(value)
    if not 1 <= count <= limit:
        shown = repr(count) if abs(count) < 10**18 else f"an integer of {count.bit_length()} bits"
        raise ValueError(f"{name} must be an integer in [1, {limit}], got {shown}")
    return count


__all__ += ["MAX_CONTACTS", "impact_sequence"]
