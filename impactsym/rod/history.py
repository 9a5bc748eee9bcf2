"""Sampled time histories of the rod impact, ready to draw (paper section 1).

:func:`time_history` evaluates the persistent-contact solution :math:`y(t)`,
:math:`N(t)` (:func:`impactsym.rod.displacement`, :func:`impactsym.rod.contact_force`)
on a time grid that also holds the left limits at the reflections :math:`t = 2, 4,
\\dots` (where :math:`N` jumps for a rigid contact), together with the contact times
of both conditions (:func:`impactsym.rod.contact_time`), so that
:mod:`impactsym.plotting.rod` only draws. See docs/physics.md#1-rod-impact-paper-1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.records import ArrayRecord
from impactsym.rod.api import contact_force, displacement
from impactsym.rod.contact_times import contact_time
from impactsym.validation import real_array

__all__ = ["MAX_POINTS", "TimeHistory", "time_history"]

#: Most samples :func:`time_history` takes (a figure needs far fewer; each costs a
#: few float64 numbers per array).
MAX_POINTS = 1_000_000


@dataclass(frozen=True, eq=False)
class TimeHistory(ArrayRecord):
    """:math:`y(t)` and :math:`N(t)` of one :math:`(\\alpha, f, \\kappa)` on ``t``.

    ``==`` compares the values (arrays element by element, see
    :class:`impactsym.records.ArrayRecord`); the hash is that of the parameters.

    Attributes
    ----------
    alpha, f, kappa
        Mass ratio, pressing force, contact stiffness (``inf``: rigid).
    t_max
        End of the time axis (the samples cover ``[0, t_max)``).
    t
        Sample times, with the left limits just before ``t = 2, 4, ...``.
    displacement, contact_force
        :math:`y(t)` and :math:`N(t)` on ``t``.
    contact_time_position, contact_time_force
        First sign change of :math:`y` resp. :math:`N` up to ``t_max`` (``inf``: none).
    """

    alpha: float
    f: float
    kappa: float
    t_max: float
    t: np.ndarray
    displacement: np.ndarray
    contact_force: np.ndarray
    contact_time_position: float
    contact_time_force: float

    def plot(self, quantity: str = "N", *, ax: Any = None) -> Any:
        """``y`` or ``N`` over time (see :func:`impactsym.plotting.rod.plot_time_history`)."""
        from impactsym.plotting.rod import plot_time_history

        return plot_time_history([self], quantity, ax=ax)


def _sample_times(t_max: float, n_points: int) -> np.ndarray:
    """``n_points`` samples on ``[0, t_max)`` plus the left limits just before the
    reflections ``t = 2, 4, ...`` (sharp jumps of a rigid contact).

    >>> _sample_times(4.0, 4).tolist()
    [0.0, 1.0, 1.999999999999, 2.0, 3.0, 3.999999999999]
    """
    t = np.linspace(0.0, t_max, n_points, endpoint=False)
    return np.union1d(t, np.arange(2.0, t_max + 1e-9, 2.0) - 1e-12)


def time_history(
    alpha: float,
    f: float,
    *,
    kappa: float = np.inf,
    t_max: float = 12.0,
    n_points: int = 6001,
) -> TimeHistory:
    """Sample :math:`y`, :math:`N` and the contact times of one rod impact.

    Parameters
    ----------
    alpha, f
        Mass ratio :math:`M / m_{rod}` and pressing force (normalized).
    kappa
        Contact stiffness (``inf``: rigid).
    t_max
        End of the time axis (also the horizon of the contact-time search).
    n_points
        Time samples on ``[0, t_max)`` (the left limits at the reflections are added),
        an integer in ``[2, MAX_POINTS]``.

    Raises
    ------
    ValueError, TypeError
        Before any sampling, naming the argument: as :func:`contact_time` for ``alpha``,
        ``f``, ``kappa`` and ``t_max`` (its range for rigid or finite ``kappa``), and
        (``ValueError``) for an ``n_points`` that is no integer or outside
        ``[2, MAX_POINTS]``.

    Examples
    --------
    >>> h = time_history(1.0, 0.0, t_max=4.0, n_points=50)
    >>> h.t[0], h.t_max, bool(h.contact_force[0] == 1.0)
    (np.float64(0.0), 4.0, True)
    """
    for name, value in (("alpha", alpha), ("f", f), ("kappa", kappa), ("t_max", t_max)):
        if np.ndim(real_array(name, value, allow_inf=name == "kappa")[0]) != 0:
            raise TypeError(f"{name} must be a single number, got {value!r}")
    if (
        isinstance(n_points, (bool, np.bool_))
        or not isinstance(n_points, (int, np.integer))
        or not 2 <= n_points <= MAX_POINTS
    ):
        big = isinstance(n_points, int) and abs(n_points) >= 10**18
        shown = "an integer of over 18 digits" if big else repr(n_points)
        raise ValueError(f"n_points must be an integer >= 2 and <= {MAX_POINTS}, got {shown}")
    real_array("t_max", t_max, lower=0.0, strict=True)
    # the contact times first: they validate alpha, f, kappa and t_max (its range for
    # rigid or finite kappa) before any sample is taken
    times = {
        c: float(contact_time(alpha, f, condition=c, kappa=kappa, t_max=t_max))
        for c in ("position", "force")
    }
    t = _sample_times(float(t_max), int(n_points))
    return TimeHistory(
        alpha=float(alpha),
        f=float(f),
        kappa=float(kappa),
        t_max=float(t_max),
        t=t,
        displacement=np.asarray(displacement(t, alpha, f, kappa=kappa)),
        contact_force=np.asarray(contact_force(t, alpha, f, kappa=kappa)),
        contact_time_position=times["position"],
        contact_time_force=times["force"],
    )
