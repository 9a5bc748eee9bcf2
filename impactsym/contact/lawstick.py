r"""The stick/release boundary of every contact law: the paper's Fig. 1b for each law.

**What.** For a damping number :math:`\delta` of a law of :mod:`impactsym.contact.laws`
(``D``, ``s``, ``alpha`` or ``beta``), :func:`law_stick_boundary` returns the pressing
number :math:`f^*(\delta)` at which the body starts to stick: it releases for
:math:`f < f^*` and sticks at :math:`f^*` and a little above (``docs/physics.md``,
"Nonlinear contact laws", *Stick boundary and bounce sequence*). For ``"linear"`` this is
the inverse of :func:`~impactsym.contact.api.stick_boundary`, :math:`D^*(f^*(D)) = D`.

**Which equation.** Sticking is the verdict of one exact impact
(:func:`~impactsym.contact.lawnumbers.law_impact`): :math:`z'' = b - \varphi(z, z')`,
:math:`z(0) = 0`, :math:`z'(0) = 1` never ends under the contact condition. No closed
boundary equation is known for the nonlinear laws, so the boundary is the root of that
verdict in ``f``.

**Why this numerics.** The verdict is a step function of ``f``: multisection in
:math:`\ln f` (:func:`~impactsym.contact.lawonset.stick_onset`), never below
:data:`F_MIN`.
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.lawnumbers import law_impact, law_inputs
from impactsym.contact.lawonset import stick_onset
from impactsym.validation import finish

ArrayLike = float | np.ndarray

#: The lowest f tried (the scan of :func:`~impactsym.contact.lawonset.stick_onset` goes
#: down to it while the body sticks).
F_MIN = 1e-12
#: The lowest f tried for the linear law (its closed forms; D* = f^(-1/4)/2 there).
F_MIN_LINEAR = 1e-200


def law_stick_boundary(
    law: str,
    damping_number: ArrayLike,
    *,
    exponent: ArrayLike = 1.5,
    condition: str,
    rtol: float = 1e-10,
) -> ArrayLike:
    r"""Pressing number :math:`f^*(\delta)` at which the body starts to stick.

    Parameters
    ----------
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
        The contact law (:mod:`impactsym.contact.laws`).
    damping_number : float or array_like
        The law's damping number :math:`\delta \ge 0`: ``D`` (linear, hertz-linear),
        ``s = lambda v0`` (Hunt–Crossley), ``alpha`` (Tsuji), ``beta = 3A/(2T)``
        (viscoelastic).
    exponent : float or array_like
        ``p >= 1`` of the laws that have one; broadcasts with ``damping_number``.
    condition : {"position", "force", "clipped"}
        How the contact ends (``"clipped"``: the engines' force :math:`\max(0, F)` on the
        overlap, :func:`~impactsym.contact.nonlinear.impact`); for ``"linear"`` clipped,
        the body sticks where the force-condition release speed is below :math:`8D^2 f`.
    rtol : float
        Relative width of the final bracket, in ``[1e-14, 1e-2]``.

    Returns
    -------
    float or ndarray
        :math:`f^*` (the law's pressing number: :math:`F_0/(c v_0)` for ``"linear"``,
        :math:`F_0 T/(m v_0)` otherwise); ``0`` where the body sticks already without
        pressing force, ``inf`` where :math:`\delta = 0` (no dissipation: it never
        sticks). The upper end of a bracket of relative width ``rtol`` around the change
        of the verdict.

    Notes
    -----
    The accuracy is that of the sticking verdict: under every condition it agrees with
    an independent integration to :math:`10^{-4}` (the tests' resolution; near the force
    condition's boundary the force dips below zero inside one step, which the kernel
    finds by locating the force minimum in the step, ``docs/physics.md``).

    Raises
    ------
    ValueError
        Where the body still releases at ``f = 1e12`` (a damping number so small that
        the boundary lies beyond the scan), or sticks at ``F_MIN`` but not at 0 with a
        boundary below it.

    Examples
    --------
    The linear law inverts the paper's boundary :math:`D^*(f)`:

    >>> from impactsym.contact import stick_boundary
    >>> f_star = law_stick_boundary("linear", 0.5, condition="position")
    >>> round(stick_boundary(f_star, condition="position"), 8)
    0.5
    >>> law_stick_boundary("tsuji", [0.0, 2.5], condition="position")  # zeta >= 1 at f = 0
    array([inf,  0.])
    """
    (delta,), q, shape, scalar = law_inputs(
        law, condition=condition, exponent=exponent, damping_number=damping_number
    )
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 1e-14 <= rtol <= 1e-2:
        raise ValueError(f"rtol must be a float in [1e-14, 1e-2], got {rtol!r}")
    result = np.full(delta.shape, np.inf)
    todo = np.flatnonzero(delta > 0)
    if todo.size:
        floor = F_MIN_LINEAR if law == "linear" else F_MIN

        def sticks(d: np.ndarray, f: np.ndarray, qq: np.ndarray) -> np.ndarray:
            return np.isinf(law_impact(law, d, f, qq, condition=condition)[0])

        label = f"law_stick_boundary({law!r}), {condition} condition"
        result[todo] = stick_onset(
            sticks, delta[todo], q[todo], floor=floor, rtol=rtol, label=label
        )
    return finish(result.reshape(shape), scalar)
