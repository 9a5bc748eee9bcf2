r"""The bounce sequence of the spring-damper contact until the body rests.

**What.** Normalized on the *first* impact (:math:`\tau = \omega_0 t`,
:math:`z = x\omega_0/v_0`, :math:`f = F/(d v_0)`): a body released from the contact flies
under the pressing force alone, with acceleration :math:`2Df` towards the contact, hits
again, and so on until a contact no longer ends (the body sticks). `docs/physics.md,
section 2 <../physics.html#bounce-sequences-until-rest>`_ derives the recursions and why
the sequence ends.

**Which equations.** Position condition: every contact starts undeformed, so contact
``n`` at speed :math:`v_n` is the first impact with :math:`f_n = f/v_n`,

.. math::

    v_{n+1} = e(D, f_n)\, v_n,\qquad
    \tau_{n+1}^\mathrm{start} = \tau_n^\mathrm{start} + \tau_c(D, f_n)
        + \frac{2 v_{n+1}}{2 D f}.

Force condition: the contact ends with the massless element still deflected by
:math:`2Du`; it relaxes as :math:`z_e' = -z_e/(2D)` while the body flies, and the next
contact starts from the state :math:`(z^*, v^*)` where the body meets it (the re-contact
root of :math:`\psi(x) = 2D^2 f/u`, :mod:`~impactsym.contact.flight`), with the restart
forms of :class:`~impactsym.contact.derivation.SpringDamperRestart`. ``arrival_velocity``
is signed (negative: the element catches the body from behind), ``arrival_speed`` its
magnitude.

**Why this numerics.** One loop over contacts, vectorized over all points
(:mod:`~impactsym.contact.loop`, shared by :func:`bounce_sequence` and
:func:`bounce_map`): each contact is one call of the section-2 kernel
(:func:`impactsym.contact.kernel.first_release`, ridge-bracketed Newton), each
re-contact one bracketed Newton solve of the flight equation; points that rest drop
out. A release at the fold to rounding (:math:`1/2 - r < 10^{-13}`) counts as sticking;
``max_contacts`` bounds the loop (under the force condition finiteness is not proven)
but sizes nothing: memory follows the contacts that occur.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from impactsym.contact.kernel import check_derived, flat_inputs, kernels
from impactsym.contact.lawbounce import law_sequence, law_sequences
from impactsym.contact.lawnumbers import exponent_in_use
from impactsym.contact.laws import check_law
from impactsym.contact.loop import check_max_contacts, check_resolution, run_sequences
from impactsym.contact.nonlinear import check_law_condition
from impactsym.records import ArrayRecord
from impactsym.validation import check_condition, finish, real_array

ArrayLike = float | np.ndarray


@cache
def _restart_z() -> Any:
    """z(tau; D, f, z0, v0) of a contact started from (z0, v0) (its position function)."""
    return kernels(condition="position", restart=True).g


@dataclass(frozen=True, eq=False)
class BounceSequence(ArrayRecord):
    r"""The contacts of one body until it rests (normalized on the first impact).

    Attributes
    ----------
    D, f, condition
        The model and the contact condition.
    start, end
        Start and end :math:`\tau` of every contact (``end`` is ``inf`` for the contact in
        which the body sticks).
    arrival_speed, departure_speed
        Speed at the start and at the end of every contact, over the first impact speed
        (``departure_speed`` is 0 for the sticking contact).
    arrival_velocity
        Body velocity at the start of every contact, positive into the contact (force
        condition: negative when the relaxing element catches the body from behind).
    element_deflection
        Element deflection :math:`z(0)` at the start of every contact (0 under the
        position condition).
    n_contacts
        Number of contacts, the sticking contact included.
    time_to_rest
        Start of the sticking contact (``inf`` when the body does not stick).
    sticks
        False only when ``max_contacts`` ran out or the body is not pushed back (``f = 0``
        or ``D = 0``).
    law, exponent
        The contact law (``D`` is its damping number, ``f`` its pressing number, times are
        in units of the first impact's :math:`T`) and the exponent in use.
    """

    D: float
    f: float
    condition: str
    start: np.ndarray
    end: np.ndarray
    arrival_speed: np.ndarray
    departure_speed: np.ndarray
    arrival_velocity: np.ndarray
    element_deflection: np.ndarray
    n_contacts: int
    time_to_rest: float
    sticks: bool
    law: str = "linear"
    exponent: float = 1.0

    def trajectory(self, tau: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        r"""Body penetration :math:`z(\tau)` and element deflection :math:`z_e(\tau)`.

        In contact both are the solution of the contact from its initial state
        (:class:`~impactsym.contact.derivation.SpringDamperRestart`); in flight the body
        follows :math:`z_c - u s + D f s^2` and the element relaxes as
        :math:`z_c e^{-s/(2D)}` (:math:`z_c = 0` under the position condition), ``s``
        the time since the release.

        >>> seq = bounce_sequence(0.0, 0.0, condition="force")
        >>> z, z_e = seq.trajectory([np.pi / 2, 4.0])
        >>> np.round(z, 12).tolist(), z_e.tolist()  # sin(tau), then flying off at speed 1
        ([1.0, -0.85840734641], [1.0, 0.0])

        Only for ``law="linear"`` under the position or force condition (the closed
        forms): another law or the clipped condition (whose contacts coast) raises
        ``ValueError``.
        """
        if self.law != "linear" or self.condition == "clipped":
            what = f"{self.law!r} law" if self.law != "linear" else "clipped condition"
            raise ValueError(
                f"trajectory is available for the linear law only, position or force "
                f"(this sequence is on the {what}; its contacts are in start, end and the "
                f"speeds)"
            )
        t = real_array("tau", tau, lower=0.0)[0].ravel()
        i = np.maximum(np.searchsorted(self.start, t, side="right") - 1, 0)
        contact = t < self.end[i]
        z, element = np.empty(t.shape), np.empty(t.shape)
        if contact.any():
            k = i[contact]
            z[contact] = _restart_z()(
                t[contact] - self.start[k],
                np.full(k.shape, self.D),
                np.full(k.shape, self.f),
                self.element_deflection[k],
                self.arrival_velocity[k],
            )
            element[contact] = z[contact]
        flying = ~contact
        if flying.any():
            k = i[flying]
            s, u = t[flying] - self.end[k], self.departure_speed[k]
            released = 2.0 * self.D * u if self.condition == "force" else 0.0 * u
            z[flying] = released - u * s + self.D * self.f * s**2
            with np.errstate(divide="ignore", over="ignore"):
                relax = np.exp(-s / (2.0 * self.D)) if self.D > 0 else 0.0 * s
            element[flying] = released * relax
        return z, element

    def plot(self, *, ax: Any = None) -> Any:
        """Penetration and element deflection over time (see
        :func:`impactsym.plotting.bounce.plot_bounce_sequence`)."""
        from impactsym.plotting.bounce import plot_bounce_sequence

        return plot_bounce_sequence(self, ax=ax)


def bounce_sequence(
    D: float,
    f: float,
    *,
    condition: str,
    max_contacts: int = 100,
    law: str = "linear",
    exponent: float = 1.5,
) -> BounceSequence:
    r"""The sequence of contacts and free flights of the spring-damper contact until rest.

    Contact ``n`` follows :math:`z'' + 2Dz' + z = 2Df` from its initial state until its
    contact function changes sign (``docs/physics.md``, section 2); in between, the body flies
    with acceleration :math:`2Df` towards the contact. Under the position condition

    .. math::  v_{n+1} = e(D, f/v_n)\, v_n, \qquad
               \Delta\tau_\mathrm{flight} = \frac{2 v_{n+1}}{2 D f};

    under the force condition the next contact starts from the still deflected element
    (the module docstring; physics.md, section 2, *Bounce sequences until rest*).

    With ``law`` another contact law of :mod:`impactsym.contact.laws`: each contact is the
    exact impact of that law at its arrival speed, whose damping and pressing numbers
    follow from those of the first impact by powers of the speed
    (:mod:`~impactsym.contact.lawbounce`); under the force condition each contact starts
    from the element relaxing with zero force where the body meets it (in the first
    impact's units).

    Parameters
    ----------
    D : float
        Lehr's damping ratio, ``>= 0`` (another law: its damping number ``D``, ``s``,
        ``alpha`` or ``beta`` at the first impact).
    f : float
        Pressing force over the damper force at the first impact, ``>= 0`` (another law:
        its pressing number :math:`F_0 T/(m v_0)` at the first impact).
    condition : {"position", "force", "clipped"}
        How each contact ends. ``"clipped"`` (any law, the linear one included): the
        engines' force :math:`\max(0, F)` on the geometric overlap; each contact ends at
        zero overlap with nothing left deflected, so the next starts undeformed at its
        arrival speed (:mod:`~impactsym.contact.lawbounce`; for the linear law, LAMMPS's
        continuous ``limit_damping`` contact).
    max_contacts : int
        At most this many contacts are computed (``1 <= max_contacts <= 10**7``).
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
        The contact law (default the linear spring-damper of the paper).
    exponent : float
        ``p >= 1`` of the laws that have one (ignored by ``"linear"``, ``"viscoelastic"``).

    Returns
    -------
    BounceSequence

    Raises
    ------
    ValueError
        Where a contact starts so late that double precision resolves its end only to
        more than :math:`10^{-6}` of its duration (long flights, :math:`Df \lesssim
        10^{-10}`): the message names the contact; :func:`bounce_map` still counts the
        contacts and gives the time to rest.

    Examples
    --------
    The first contact is the section-2 contact:

    >>> from impactsym.contact import contact_time, restitution
    >>> seq = bounce_sequence(0.1, 0.2, condition="position")
    >>> bool(seq.end[0] == contact_time(0.1, 0.2, condition="position"))
    True
    >>> bool(seq.departure_speed[0] == restitution(0.1, 0.2, condition="position"))
    True
    >>> seq.n_contacts, seq.sticks, round(seq.time_to_rest, 6)
    (8, True, 131.428158)
    >>> float(seq.end[-1]), float(seq.departure_speed[-1])
    (inf, 0.0)

    On a Hunt–Crossley contact, whose damping number :math:`s = \lambda v` falls with
    the arrival speed:

    >>> hc = bounce_sequence(0.3, 0.2, condition="position", law="hunt-crossley")
    >>> hc.n_contacts, hc.sticks, np.round(hc.departure_speed[:3], 6).tolist()
    (6, True, [0.72487, 0.533231, 0.38585])
    """
    check_law_condition(condition)
    check_law(law)
    max_contacts = check_max_contacts(max_contacts)
    values = []
    for name, value in (("D", D), ("f", f)):
        array, scalar = real_array(name, value, lower=0.0)
        if not scalar:
            raise TypeError(f"{name} must be a scalar (use bounce_map for arrays), got {value!r}")
        values.append(array.reshape(1))
    damping, force = float(values[0][0]), float(values[1][0])
    if law != "linear" or condition == "clipped":
        return _law_bounce(law, damping, force, exponent, condition, max_contacts)
    what = f"bounce_sequence(D={damping!r}, f={force!r})"
    result = run_sequences(values[0], values[1], max_contacts, condition=condition, resolved=what)
    table = result.table(0)
    return BounceSequence(
        D=damping,
        f=force,
        condition=condition,
        start=table["start"],
        end=table["start"] + table["duration"],
        arrival_speed=np.abs(table["arrival"]),
        departure_speed=table["departure"],
        arrival_velocity=table["arrival"],
        element_deflection=table["deflection"],
        n_contacts=int(result.n_contacts[0]),
        time_to_rest=float(result.time_to_rest[0]),
        sticks=bool(result.sticks[0]),
    )


def _law_bounce(
    law: str, damping: float, force: float, exponent: object, condition: str, max_contacts: int
) -> BounceSequence:
    """The sequence of a nonlinear law (:mod:`~impactsym.contact.lawbounce`)."""
    array, scalar = real_array("exponent", exponent, lower=1.0)
    if not scalar:
        raise TypeError(f"exponent must be a scalar, got {exponent!r}")
    q = float(exponent_in_use(law, array))
    what = f"bounce_sequence(D={damping!r}, f={force!r}, law={law!r})"

    def check(start: np.ndarray, duration: np.ndarray, contact: int) -> None:
        check_resolution(start, duration, what, contact=contact)

    try:
        if condition == "force":  # from the relaxing element (lawbounce.law_sequences)
            seq = law_sequences(
                law, *(np.array([v]) for v in (damping, force, q)), condition=condition,
                max_contacts=max_contacts, record=True, check=check,
            ).sequence(0)  # fmt: skip
        else:  # position or clipped: every contact starts undeformed
            seq = law_sequence(
                law, damping, force, q, max_contacts=max_contacts, check=check,
                condition=condition,
            )  # fmt: skip
    except ValueError as exc:
        if str(exc).startswith(what):
            raise
        raise ValueError(f"{what}: {exc}") from None
    return BounceSequence(
        D=damping,
        f=force,
        condition=condition,
        start=seq.start,
        end=seq.start + seq.duration,
        arrival_speed=seq.arrival,
        departure_speed=seq.departure,
        arrival_velocity=seq.arrival.copy()
        if seq.arrival_velocity is None
        else seq.arrival_velocity,
        element_deflection=np.zeros(seq.n_contacts) if seq.deflection is None else seq.deflection,
        n_contacts=seq.n_contacts,
        time_to_rest=seq.time_to_rest,
        sticks=seq.sticks,
        law=law,
        exponent=q,
    )


@dataclass(frozen=True, eq=False)
class BounceMap(ArrayRecord):
    """Number of contacts and time to rest over arrays of ``(D, f)``.

    Attributes
    ----------
    D, f
        The broadcast inputs.
    n_contacts
        Number of contacts, the sticking one included (int array).
    time_to_rest
        Start of the sticking contact; ``inf`` where the body does not stick.
    sticks
        Whether the body came to rest within ``max_contacts``.
    condition
        The contact condition.
    law, exponent
        The contact law and its exponent (the one in use: 1 for the laws without one).
    """

    D: np.ndarray
    f: np.ndarray
    n_contacts: np.ndarray
    time_to_rest: np.ndarray
    sticks: np.ndarray
    condition: str
    law: str = "linear"
    exponent: float = 1.0

    def plot(self, *, quantity: str = "n_contacts", ax: Any = None) -> Any:
        """Map of ``quantity`` with the first contact's stick boundary (see
        :func:`impactsym.plotting.bounce.plot_bounce_map`)."""
        from impactsym.contact.api import stick_boundary
        from impactsym.contact.lawstick import law_stick_boundary
        from impactsym.plotting.bounce import plot_bounce_map

        if self.law == "linear" and self.condition != "clipped":
            f_line = np.geomspace(float(np.max(self.f)) * 1e-4, float(np.max(self.f)), 400)
            line = stick_boundary(f_line, condition=self.condition), f_line
        else:  # the law's boundary f*(D), D its damping number at the first impact
            d_line = np.linspace(float(np.min(self.D)), float(np.max(self.D)), 200)
            f_star = law_stick_boundary(
                self.law, d_line, exponent=self.exponent, condition=self.condition
            )
            line = d_line, f_star
        return plot_bounce_map(self, quantity=quantity, boundary=line, ax=ax)


def bounce_map(
    D: ArrayLike,
    f: ArrayLike,
    *,
    condition: str,
    max_contacts: int = 100,
    law: str = "linear",
    exponent: float = 1.5,
) -> BounceMap:
    """Number of contacts and time to rest, vectorized over ``D`` and ``f``.

    The same computation as :func:`bounce_sequence`, one contact after another for all
    points at once (points that rest drop out); with ``law`` another contact law
    (``D``, ``f`` its damping and pressing numbers at the first impact,
    :func:`~impactsym.contact.lawbounce.law_sequences`; ``exponent`` a scalar);
    ``condition="clipped"`` on any law, the linear one included.

    Examples
    --------
    >>> m = bounce_map([0.05, 0.1, 2.0], 0.2, condition="force")
    >>> m.n_contacts.tolist(), m.sticks.tolist()
    ([21, 9, 1], [True, True, True])
    >>> m.time_to_rest.round(3).tolist()  # D = 2 sticks at the first contact
    [608.025, 143.756, 0.0]
    """
    max_contacts = check_max_contacts(max_contacts)
    check_law(law)
    check_law_condition(condition)
    basic = "position" if condition == "clipped" else condition  # checked: clipped too
    (damping, force), shape, _ = flat_inputs(condition=basic, D=D, f=f)
    q_used = 1.0
    if law == "linear" and condition != "clipped":
        result = run_sequences(damping, force, max_contacts, condition=condition, record=False)
    else:
        array, scalar = real_array("exponent", exponent, lower=1.0)
        if not scalar:
            raise TypeError(f"exponent must be a scalar, got {exponent!r}")
        q_used = float(exponent_in_use(law, array))
        q = np.full(damping.shape, q_used)
        result = law_sequences(
            law, damping, force, q, condition=condition, max_contacts=max_contacts
        )
    return BounceMap(
        D=damping.reshape(shape),
        f=force.reshape(shape),
        n_contacts=result.n_contacts.reshape(shape),
        time_to_rest=result.time_to_rest.reshape(shape),
        sticks=result.sticks.reshape(shape),
        condition=condition,
        law=law,
        exponent=q_used,
    )


@dataclass(frozen=True, eq=False)
class PhysicalBounce(ArrayRecord):
    r"""A bounce sequence in physical units (seconds, metres, metres per second).

    Attributes
    ----------
    omega0, D, f
        Natural frequency :math:`\sqrt{k/m}` (rad/s), Lehr's damping, normalized pressing
        force (``inf`` for :math:`d = 0 < F`).
    start, end
        Contact start and end times in seconds.
    arrival_speed, departure_speed
        Speeds in metres per second.
    element_deflection
        Element deflection at each contact start, metres.
    time_to_rest
        Seconds until the sticking contact starts (``inf`` if the body does not stick).
    n_contacts, sticks, condition
        As in :class:`BounceSequence`.
    """

    omega0: float
    D: float
    f: float
    start: np.ndarray
    end: np.ndarray
    arrival_speed: np.ndarray
    departure_speed: np.ndarray
    element_deflection: np.ndarray
    time_to_rest: float
    n_contacts: int
    sticks: bool
    condition: str


def physical_bounce(
    m: float,
    k: float,
    d: float,
    v0: float,
    F: float = 0.0,
    *,
    condition: str,
    max_contacts: int = 100,
) -> PhysicalBounce:
    r"""Bounce sequence of a body of mass ``m`` dropped at speed ``v0`` on a spring ``k``
    and damper ``d`` under a pressing force ``F`` (e.g. its weight :math:`mg`), in SI units.

    .. math::  \omega_0 = \sqrt{k/m},\quad D = \frac{d}{2\sqrt{km}},\quad
               f = \frac{F}{d v_0},\quad t = \tau/\omega_0,\quad x = z\, v_0/\omega_0 .

    An undamped contact under a load (:math:`d = 0 < F`, :math:`f = \infty`) bounces for
    ever: every contact starts undeformed at speed :math:`v_0`, lasts
    :math:`\tau_c = 2\pi - 2\arctan(1/b)` with :math:`b = F/(\sqrt{km}\, v_0)` and
    returns it with :math:`e = 1` after a flight of :math:`2/b`.

    Examples
    --------
    A 10 g part dropped at 0.5 m/s on a 1 kN/m pad damped with 2 N s/m, under its weight:

    >>> b = physical_bounce(0.01, 1e3, 2.0, 0.5, 0.01 * 9.81, condition="force")
    >>> b.n_contacts, b.sticks, round(b.time_to_rest * 1e3, 3)  # milliseconds
    (3, True, 70.403)
    """
    check_condition(condition)
    max_contacts = check_max_contacts(max_contacts)
    vals = {}
    for name, value, strict in (("m", m, True), ("k", k, True), ("d", d, False)):
        vals[name] = _scalar(name, value, strict)
    vals["v0"] = _scalar("v0", v0, True)
    vals["F"] = _scalar("F", F, False)
    mass, stiffness, damping, speed, load = vals.values()
    with np.errstate(all="ignore"):  # what leaves double precision is refused below
        root_k, root_m = np.sqrt(stiffness), np.sqrt(mass)  # no overflow in k m or k/m
        omega0 = np.float64(root_k / root_m)
        D_ = np.float64(damping / 2.0 / (root_k * root_m))
        length = np.float64(speed / omega0)  # metres per unit of z
        b = np.float64(load / (root_k * root_m) / speed)  # static penetration 2 D f
    check_derived("omega0 = sqrt(k/m)", "m, k", omega0, lambda w: (w > 0) & np.isfinite(w))
    check_derived("D = d/(2 sqrt(k m))", "d, k, m", D_, np.isfinite)
    check_derived("v0/omega0", "m, k, v0", length, lambda x: (x > 0) & np.isfinite(x))
    if damping == 0 and load > 0:
        check_derived("b = F/(sqrt(k m) v0)", "F, k, m, v0", b, lambda x: (x > 0) & np.isfinite(x))
        tau_c = 2.0 * np.pi - 2.0 * np.arctan2(1.0, b)
        with np.errstate(over="ignore"):
            start = np.arange(max_contacts) * (tau_c + 2.0 / b)
        what = f"physical_bounce (undamped, b = F/(sqrt(k m) v0) = {float(b):g})"
        check_resolution(start, np.full(max_contacts, tau_c), what)
        ones = np.ones(max_contacts)
        seq = {
            "f": np.inf, "start": start, "end": start + tau_c, "arrival": ones,
            "departure": ones, "deflection": 0.0 * ones, "time_to_rest": np.inf,
            "n": max_contacts, "sticks": False,
        }  # fmt: skip
    else:
        with np.errstate(all="ignore"):
            f_ = np.float64(load / damping / speed) if load > 0 else np.float64(0.0)
        check_derived("f = F/(d v0)", "F, d, v0", f_, np.isfinite)
        try:
            s = bounce_sequence(D_, f_, condition=condition, max_contacts=max_contacts)
        except ValueError as exc:
            raise ValueError(f"physical_bounce: the inputs m, k, d, v0, F give {exc}") from None
        seq = {
            "f": f_, "start": s.start, "end": s.end, "arrival": s.arrival_speed,
            "departure": s.departure_speed, "deflection": s.element_deflection,
            "time_to_rest": s.time_to_rest, "n": s.n_contacts, "sticks": s.sticks,
        }  # fmt: skip
    with np.errstate(over="ignore", under="ignore"):
        start, end = seq["start"] / omega0, seq["end"] / omega0
        deflection = seq["deflection"] * length
    tau = np.concatenate([seq["start"], seq["end"]])
    check_derived(
        "the contact times tau/omega0",
        "m, k",
        np.concatenate([start, end]),
        lambda t: np.isinf(tau) | ((t > 0) | (tau == 0)) & np.isfinite(t),
    )
    check_derived("the element deflection", "m, k, v0", deflection, np.isfinite)
    return PhysicalBounce(
        omega0=float(omega0),
        D=float(D_),
        f=float(seq["f"]),
        start=start,
        end=end,
        arrival_speed=seq["arrival"] * speed,
        departure_speed=seq["departure"] * speed,
        element_deflection=deflection,
        time_to_rest=float(seq["time_to_rest"]) / float(omega0),
        n_contacts=int(seq["n"]),
        sticks=bool(seq["sticks"]),
        condition=condition,
    )


def _scalar(name: str, value: object, strict: bool) -> float:
    array, scalar = real_array(name, value, lower=0.0, strict=strict)
    if not scalar:
        raise TypeError(f"{name} must be a scalar, got {value!r}")
    return float(finish(array, True))
