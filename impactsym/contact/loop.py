r"""The bounce event loop: contact after contact, vectorized over all points.

Internal machinery of :mod:`impactsym.contact.bounce` (the recursions are in its module
docstring and in `docs/physics.md, section 2 <../physics.html#bounce-sequences-until-rest>`_).

**What.** :func:`run_sequences` runs the sequences of many ``(D, f)`` at once: each
contact is one call of the section-2 kernel (:func:`impactsym.contact.kernel.first_release`,
ridge-bracketed Newton) from the state the body arrives in, each force-condition
re-contact one bracketed Newton solve of the flight equation (:func:`recontact`); points
that rest drop out.

**Why this numerics.** A contact from the undeformed state :math:`(0, v)` is the first
impact with :math:`f/v` scaled by ``v``, so it goes through the same closed forms
(:math:`f = 0`), kernel and limits as :func:`~impactsym.contact.api.contact_time`. The
departure speed is capped by the energy balance, so rounding cannot create energy where
the dissipation is below it. The per-contact rows grow with the contacts that occur (a
doubling buffer), never with ``max_contacts``; maps do not record them at all. Measured
figures and the refusals: physics.md, section 2, *Numerics of the sequences*.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from impactsym.contact import flight as _flight
from impactsym.contact.kernel import first_impact, first_release, z_dot
from impactsym.numeric.codegen import lambdify
from impactsym.numeric.roots import bracketed_newton


@cache
def chi_functions() -> tuple[Any, Any]:
    """chi(x) = x psi(x) and chi'(x) of the re-contact equation, as NumPy functions."""
    model = _flight.free_flight()
    return (
        lambdify([_flight.x], model.chi_numeric, name="chi"),
        lambdify([_flight.x], model.chi_dot_numeric, name="chi_dot"),
    )


#: a release with 1/2 - r below this is at the fold to rounding: the body stays on
TANGENT = 1e-13


def recontact(ratio: np.ndarray) -> np.ndarray:
    r"""Root :math:`x^*` of :math:`\psi(x) = r` for :math:`0 < r < 1/2 - 10^{-13}`.

    Solved as :math:`\chi(x) - r x = x(\psi(x) - r) = 0` in the bracket
    :math:`[3/2 - 3r,\ 2/r]`: :math:`\psi(x) \ge 1/2 - x/6` puts :math:`\psi` at least
    :math:`(1/2 - r)/2` above ``r`` at the left end, :math:`\psi(x) < 1/x` puts it
    below :math:`r/2` at the right end, and :math:`\psi` is strictly decreasing.
    """
    chi, chi_dot = chi_functions()
    return bracketed_newton(
        lambda y, q: chi(y) - q * y,
        lambda y, q: chi_dot(y) - q,
        1.5 - 3.0 * ratio,
        2.0 / ratio,
        [ratio],
        rtol=1e-15,
    )


#: Largest ``max_contacts`` accepted: 10^7 contacts are 400 MB of per-contact rows and,
#: at 0.1-10 ms per contact, hours of work; a larger cap is no longer a bound.
MAX_CONTACTS = 10**7
#: A contact whose duration the absolute time at its start resolves only to more than this
#: relative error is refused by :func:`~impactsym.contact.bounce.bounce_sequence`:
#: ``end - start`` would keep fewer than six digits of it (none once ``end == start``).
RESOLUTION = 1e-6
#: Per-contact columns recorded by :func:`run_sequences`, in this order.
COLUMNS = ("start", "duration", "arrival", "departure", "deflection")


class _Rows:
    """Per-contact rows ``(point, start, duration, arrival, departure, deflection)`` in a
    buffer that doubles when full: memory follows the contacts that occur, not a cap."""

    def __init__(self) -> None:
        self.point = np.empty(0, dtype=np.intp)
        self.values = np.empty((0, len(COLUMNS)))
        self.size = 0

    def append(self, point: np.ndarray, *columns: np.ndarray) -> None:
        need = self.size + point.size
        if need > self.point.size:
            capacity = max(2 * self.point.size, need, 64)
            try:
                grown_point = np.empty(capacity, dtype=np.intp)
                grown = np.empty((capacity, len(COLUMNS)))
            except MemoryError:
                raise MemoryError(
                    f"the sequences hold {self.size} contacts and the next "
                    f"{point.size} do not fit in memory; lower max_contacts"
                ) from None
            grown_point[: self.size] = self.point[: self.size]
            grown[: self.size] = self.values[: self.size]
            self.point, self.values = grown_point, grown
        self.point[self.size : need] = point
        self.values[self.size : need] = np.column_stack(columns)
        self.size = need

    def by_point(self) -> np.ndarray:
        """The rows point by point, each point's contacts in order (a stable sort)."""
        order = np.argsort(self.point[: self.size], kind="stable")
        return self.values[: self.size][order]


@dataclass(frozen=True, eq=False)
class Sequences:
    """Bounce sequences of many points; ``rows`` (if recorded) holds every contact,
    point by point (``n_contacts`` rows each), in the columns ``COLUMNS``."""

    n_contacts: np.ndarray
    sticks: np.ndarray
    time_to_rest: np.ndarray
    rows: np.ndarray | None

    def table(self, index: int) -> dict[str, np.ndarray]:
        """The per-contact columns of point ``index``."""
        offset = int(self.n_contacts[:index].sum())
        block = self.rows[offset : offset + int(self.n_contacts[index])]
        return {name: block[:, i].copy() for i, name in enumerate(COLUMNS)}


def _released_speed(
    condition: str,
    damping: np.ndarray,
    force: np.ndarray,
    deflection: np.ndarray,
    arrival: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Contact time and departure speed of one contact from each state, ``inf`` and 0
    where the body sticks.

    A contact from the undeformed state :math:`(0, v)` is the first impact with
    :math:`f/v`, scaled by ``v`` (as :func:`~impactsym.contact.api.contact_time`: the
    closed forms of :mod:`impactsym.contact.unpressed` where :math:`f = 0`, else the
    section-2 kernel with its limits); one from a deflected element uses the
    restart forms. The departure speed is capped by the energy balance
    :math:`E = v^2/2 + z^2/2 - 2Df z` (non-increasing in contact): :math:`u \le v` under
    the position condition, :math:`(1/2 + 2D^2)u^2 - 4D^2 f u \le E` under the force
    condition (the release state is :math:`(2Du, -u)`), so that rounding cannot create
    energy where the dissipation is below it (:math:`D \lesssim 10^{-16}`).
    """
    tau_c, speed = np.full(damping.shape, np.inf), np.zeros(damping.shape)
    fresh = (deflection == 0) & (arrival > 0)
    if fresh.any():  # the first impact at f/v, in units of v
        d, v = damping[fresh], arrival[fresh]
        f_v = force[fresh] / v
        # as contact_time and restitution: without pressing force the closed forms, else
        # the kernel, with the limits deciding where its closed forms fail
        tau, e = first_impact(d, f_v, condition=condition)
        tau_c[fresh], speed[fresh] = tau, e * v
    if not fresh.all():  # the relaxing element met the body: a restart from (z0, v0)
        rest = ~fresh
        d, fr = damping[rest], force[rest]
        state = (deflection[rest], arrival[rest])
        tau = first_release(d, fr, state=state, condition=condition)
        out = np.isfinite(tau)
        u = np.zeros(tau.shape)
        args = (tau[out], d[out], fr[out], state[0][out], state[1][out])
        u[out] = -z_dot(restart=True)(*args)
        tau_c[rest], speed[rest] = tau, u
    with np.errstate(over="ignore", invalid="ignore"):
        if condition == "position":
            bound = np.abs(arrival)
        else:
            energy = 0.5 * arrival**2 + deflection * (0.5 * deflection - 2.0 * damping * force)
            pull, mass = 4.0 * damping**2 * force, 1.0 + 4.0 * damping**2
            bound = (pull + np.sqrt(pull**2 + 2.0 * mass * energy)) / mass
    capped = np.isfinite(tau_c) & np.isfinite(bound) & (speed > bound)
    speed[capped] = bound[capped]
    return tau_c, speed


def run_sequences(
    damping: np.ndarray,
    force: np.ndarray,
    max_contacts: int,
    *,
    condition: str,
    record: bool = True,
    resolved: str | None = None,
) -> Sequences:
    """Bounce sequences on flat arrays: a loop over contacts, vectorized over points.

    Memory follows the contacts that occur: the per-contact rows (``record``) grow with
    them, and nothing is sized by ``max_contacts``. With ``resolved`` (the caller and its
    inputs, for the message) a contact whose end the absolute time cannot represent is
    refused as soon as it is computed (:func:`check_resolution`).
    """
    n = damping.size
    t, z, v = np.zeros(n), np.zeros(n), np.ones(n)
    n_contacts = np.zeros(n, dtype=int)
    sticks = np.zeros(n, dtype=bool)
    time_to_rest = np.full(n, np.inf)
    rows = _Rows() if record else None
    active = np.arange(n)
    for k in range(max_contacts):
        if active.size == 0:
            break
        d, fr, za, va, ta = damping[active], force[active], z[active], v[active], t[active]
        n_contacts[active] = k + 1
        try:
            tau_c, speed = _released_speed(condition, d, fr, za, va)
        except ValueError as exc:
            raise ValueError(
                f"contact {k + 1} of the bounce sequence (normalized on its arrival "
                f"speed, f/v): {exc}"
            ) from None
        if resolved is not None:
            check_resolution(ta, tau_c, resolved, contact=k + 1)
        out = np.isfinite(tau_c)
        accel = 2.0 * d * fr
        pressed = fr > 0  # without pressing force there is no fold: every release is real
        ratio = np.zeros(active.size)
        if condition == "force":  # r = 2 D^2 f / u < 1/2 unless rounding at the fold
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio[out] = d[out] * accel[out] / speed[out]
            tangent = out & pressed & ((speed <= 0) | (ratio >= 0.5 - TANGENT))
        else:
            tangent = out & pressed & (speed <= 0)
        out &= ~tangent  # a release at the fold (to rounding) does not leave the element
        tau_c[~out], speed[~out] = np.inf, 0.0
        sticks[active[~out]] = True
        time_to_rest[active[~out]] = ta[~out]
        if rows is not None:
            rows.append(active, ta, tau_c, va, speed, za)
        # released and pushed back: there is a next contact, unless the flight is longer
        # than floats reach (D f below ~1e-300): that body counts as never coming back
        with np.errstate(all="ignore"):
            reach = 2.0 * speed / accel if condition == "position" else 2.0 / ratio
            back = out & (accel > 0) & np.isfinite(reach) & np.isfinite(ta + reach)
        idx, d, u, a = active[back], d[back], speed[back], accel[back]
        t_release = ta[back] + tau_c[back]
        if condition == "position":
            t[idx], v[idx] = t_release + 2.0 * u / a, u
        else:
            ratio = ratio[back]
            x = recontact(ratio)
            t[idx] = t_release + 2.0 * d * x
            v[idx] = u * (2.0 * ratio * x - 1.0)
            z[idx] = 2.0 * d * u * np.exp(-x)
        active = idx
    return Sequences(
        n_contacts=n_contacts,
        sticks=sticks,
        time_to_rest=time_to_rest,
        rows=None if rows is None else rows.by_point(),
    )


def check_max_contacts(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"max_contacts must be an integer, got {value!r}")
    if value < 1:
        raise ValueError(f"max_contacts must be >= 1, got {value!r}")
    if value > MAX_CONTACTS:
        raise ValueError(
            f"max_contacts must be <= {MAX_CONTACTS:.0e} (a bound on work and memory, "
            f"of order hours and 400 MB there), got {value!r}"
        )
    return int(value)


def check_resolution(
    start: np.ndarray, duration: np.ndarray, what: str, *, contact: int | None = None
) -> None:
    """Refuse contacts whose end the absolute time at their start cannot represent.

    ``start`` and ``duration`` are the contacts of one sequence in order (``contact``
    ``None``), or contact number ``contact`` of several sequences; ``what`` opens the
    message (the call and its inputs).
    """
    finite = np.isfinite(duration)
    with np.errstate(invalid="ignore"):
        coarse = finite & ~(np.spacing(np.abs(start)) <= RESOLUTION * duration)
    if coarse.any():
        k = int(np.argmax(coarse))
        number = k + 1 if contact is None else contact
        raise ValueError(
            f"{what}: contact {number} starts at tau = {start[k]:.6g}, where double precision "
            f"resolves times only to {np.spacing(abs(start[k])):.2g}, more than "
            f"{RESOLUTION:g} of its duration {duration[k]:.6g}: the end of that contact "
            f"cannot be represented (max_contacts={max(number - 1, 1)} gives the contacts "
            "before it, bounce_map the number of contacts and the time to rest)"
        )
