r"""The rod impact continued past separation: result objects and the one event loop.

The struck end of the rod (paper section 1, normalized) is driven by the outgoing wave
:math:`g`: rod end velocity :math:`u' = g(t) - g(t - 2)`, rod end force
:math:`g(t) + g(t - 2)`, fixed-end stress :math:`2 g(t - 1)`. In contact :math:`g` obeys a
delay equation, in flight :math:`g(t) = -g(t - 2)` and :math:`\alpha y'' = f`. The event
loop :func:`follow` walks through the pieces of :math:`g` (cut where an incoming piece
:math:`g(t - 2)` arrives and at events), switching between contact and flight; a *step
model* (:class:`StepModel`) solves one piece: rigid contact
(:mod:`impactsym.rod.sequence_rigid`) or a contact spring of stiffness :math:`\kappa`
(:mod:`impactsym.rod.sequence_elastic`). The result is a :class:`RodImpactSequence`
whose time functions and energies are evaluated from the stored pieces.

Equations, representations and why the float64 pieces are trusted (the energy balance
checked in the middle of every piece): docs/physics.md#the-rod-impact-continued-past-separation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from impactsym.records import ArrayRecord
from impactsym.validation import real_array

__all__ = [
    "MAX_PIECES",
    "ElasticRodImpactSequence",
    "ElasticSequenceEnergy",
    "RodImpactSequence",
    "RodSequenceEnergy",
    "SequenceState",
    "StepModel",
    "check_balance",
    "follow",
]

# Largest energy-balance residual, relative to alpha/2 + |f y|, at which the float64
# pieces are still trusted (mid-piece); beyond it the sequence is refused.
_BALANCE_RTOL = 1e-9

#: Most pieces of ``g`` one sequence may hold (about 2.5 kB each for rigid contact): a
#: run that needs more is refused, so that memory follows what happens up to a bound.
MAX_PIECES = 100_000


@dataclass(frozen=True, eq=False)
class RodSequenceEnergy(ArrayRecord):
    r"""Energy split of a continued rod impact, unit :math:`m_{rod} v_0^2`.

    Methods take normalized times (array or float): :meth:`striker` the kinetic energy
    :math:`\alpha y'^2/2`, :meth:`work` the work :math:`f y` done by the pressing force,
    :meth:`rod` the elastic plus kinetic energy of the rod :math:`\int_{t-2}^t g^2`,
    :meth:`balance` the residual :math:`\alpha y'^2/2 + E_{rod} - f y - \alpha/2`
    (zero up to rounding).

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> energy = impact_sequence(1.0, 0.5, t_max=10.0).energy
    >>> bool(np.abs(energy.balance(np.linspace(0.0, 9.9, 100))).max() < 1e-12)
    True
    """

    sequence: RodImpactSequence

    def striker(self, t):
        return 0.5 * self.sequence.alpha * self.sequence.velocity(t) ** 2

    def work(self, t):
        return self.sequence.f * self.sequence.displacement(t)

    def rod(self, t):
        tab, tt = self.sequence._tables, self.sequence._times(t)
        return tab.integral(tt, square=True) - tab.integral(tt - 2.0, square=True)

    def balance(self, t):
        return self.striker(t) + self.rod(t) - self.work(t) - 0.5 * self.sequence.alpha

    def balance_and_work(self, t):
        """:meth:`balance` and :meth:`work` at once (used by :func:`check_balance`): for
        rigid contact the integrals of ``g`` and ``g^2`` at ``t`` and ``t - 2`` are taken
        in one pass (the same numbers as the separate methods)."""
        seq = self.sequence
        tt = seq._times(t)
        if type(seq).velocity is not RodImpactSequence.velocity:  # a subclass's own law
            now, before = seq._tables.integrals(tt), seq._tables.integrals(tt - 2.0)
            rod = now[1] - before[1]
            work = seq.f * seq._striker_position(tt, now[0] - before[0])
            striker = 0.5 * seq.alpha * seq.velocity(tt) ** 2
        else:  # t and t - 2 in one pass of each table function (elementwise the same)
            flat = np.ravel(tt)
            both = np.concatenate([flat, flat - 2.0])
            i1, i2 = seq._tables.integrals(both)
            g = seq._tables.g(both)
            n = flat.size
            rod = (i2[:n] - i2[n:]).reshape(tt.shape)
            u = (i1[:n] - i1[n:]).reshape(tt.shape)
            v = (g[:n] - g[n:]).reshape(tt.shape)
            work = seq.f * seq._striker_position(tt, u, velocity=v)
            striker = 0.5 * seq.alpha * v**2
        if np.ndim(t) == 0:
            striker, rod, work = float(striker), float(rod), float(work)
        return striker + rod - work - 0.5 * seq.alpha, work


@dataclass(frozen=True, eq=False)
class RodImpactSequence(ArrayRecord):
    r"""The rigid-contact rod impact followed through contacts and flights up to ``t_max``.

    Attributes
    ----------
    alpha, f, kappa, t_max
        The parameters (normalized, paper section 1); ``t_end`` is the former name of
        ``t_max``, still readable.
    contacts
        ``(start, end)`` of every contact up to ``t_max`` (``end = t_max`` if the
        striker is still in contact then).
    separation_velocities
        Striker velocity :math:`y'` at each separation (negative: rebounding).
    restitution
        For ``f = 0``: the striker's rebound speed after its last contact over the
        impact speed, :math:`-y'`, when that flight provably never ends (``final``);
        ``nan`` otherwise (``f > 0``: the striker always returns; or the sequence is not
        over at ``t_max``).
    final
        Whether the striker has left for good (``f = 0``, receding and beyond any
        reach of the rod end, :math:`|u| \le \sqrt{2 E_{rod}}`).
    max_fixed_end_stress
        Largest compressive stress :math:`\sigma(1, t)` for :math:`t \le t_{max}`
        (unit :math:`E v_0 / c`).
    """

    alpha: float
    f: float
    kappa: float
    t_max: float
    contacts: list
    separation_velocities: list
    restitution: float
    final: bool
    max_fixed_end_stress: float
    _tables: Any = field(repr=False)  # the pieces of g (g, integral(s), start)
    _flights: tuple = field(repr=False)  # (t0, y0, v0) per flight

    @property
    def t_end(self) -> float:
        """Former name of :attr:`t_max`."""
        return self.t_max

    @property
    def separation_speeds(self) -> list:
        """Former name of :attr:`separation_velocities` (signed: they are velocities)."""
        return self.separation_velocities

    def _times(self, t) -> np.ndarray:
        """``t`` as a float array, refused beyond ``t_max``; at ``t_max`` itself the left
        limit (one ulp earlier), so that ``g(t)`` and ``g(t - 2)`` are one-sided alike."""
        tt, _ = real_array("t", t)
        if np.any(tt > self.t_max):
            raise ValueError(f"t must be <= t_max = {self.t_max}, got {float(tt.max())!r}")
        return np.where(tt == self.t_max, np.nextafter(self.t_max, -np.inf), tt)

    @property
    def energy(self) -> RodSequenceEnergy:
        """Striker and rod energies as functions of time (:class:`RodSequenceEnergy`)."""
        return RodSequenceEnergy(self)

    def fixed_end_stress(self, t):
        r""":math:`\sigma(1, t) = 2 g(t - 1)`, compression positive (vectorized)."""
        tt = self._times(t)
        out = 2.0 * self._tables.g(tt - 1.0)
        return float(out) if np.ndim(t) == 0 else out

    def rod_end_displacement(self, t):
        """:math:`u(t) = w(0, t)`."""
        tt = self._times(t)
        out = self._tables.integral(tt) - self._tables.integral(tt - 2.0)
        return float(out) if np.ndim(t) == 0 else out

    def _flight_index(self, tt):
        starts = np.array([fl[0] for fl in self._flights] + [np.inf])
        k = np.searchsorted(starts, tt, side="right") - 1
        ends = np.array([c[0] for c in self.contacts[1:]] + [np.inf])
        in_flight = (k >= 0) & (tt < ends[np.maximum(k, 0)] if ends.size else False)
        return k, in_flight

    def displacement(self, t):
        """Striker displacement :math:`y(t)`."""
        tt = self._times(t)
        y = self._striker_position(tt, np.asarray(self.rod_end_displacement(tt), dtype=float))
        return float(y) if np.ndim(t) == 0 else y

    def _striker_position(self, tt, u, velocity=None):
        """:math:`y` at the times ``tt`` (checked) given the rod end position ``u`` there;
        given the rod end velocity as well, that of the striker is set in it (in place,
        as :meth:`velocity` does)."""
        y = u
        if self._flights:
            k, fl = self._flight_index(tt)
            data = np.array(self._flights)
            t0, y0, v0 = data[np.maximum(k, 0)].T
            d = tt - t0
            y = np.where(fl, y0 + v0 * d + 0.5 * self.f / self.alpha * d * d, y)
            if velocity is not None:
                velocity[...] = np.where(fl, v0 + self.f / self.alpha * d, velocity)
        return y

    def velocity(self, t):
        """Striker velocity :math:`y'(t)`."""
        tt = self._times(t)
        v = self._tables.g(tt) - self._tables.g(tt - 2.0)
        if self._flights:
            k, fl = self._flight_index(tt)
            data = np.array(self._flights)
            t0, _, v0 = data[np.maximum(k, 0)].T
            v = np.where(fl, v0 + self.f / self.alpha * (tt - t0), v)
        return float(v) if np.ndim(t) == 0 else v

    def contact_force(self, t):
        """:math:`N(t)`: :math:`g(t) + g(t-2)` in contact, zero in flight."""
        tt = self._times(t)
        n = self._tables.g(tt) + self._tables.g(tt - 2.0)
        if self._flights:
            n = np.where(self._flight_index(tt)[1], 0.0, n)
        return float(n) if np.ndim(t) == 0 else n

    def plot(self, *, ax=None):
        """Contact/flight sequence with the energy split (see
        :func:`impactsym.plotting.rod_sequence.plot_sequence`)."""
        from impactsym.plotting.rod_sequence import plot_sequence

        return plot_sequence(self, ax=ax)


@dataclass(frozen=True, eq=False)
class ElasticSequenceEnergy(RodSequenceEnergy):
    r"""Energy split with a contact spring, unit :math:`m_{rod} v_0^2`.

    As :class:`RodSequenceEnergy`, plus :meth:`spring`, the energy :math:`N^2/(2\kappa)`
    stored in the contact spring; :meth:`balance` is
    :math:`\alpha y'^2/2 + N^2/(2\kappa) + E_{rod} - f y - \alpha/2`.

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> energy = impact_sequence(1.0, 0.5, kappa=20.0, t_max=10.0).energy
    >>> bool(np.abs(energy.balance(np.linspace(0.0, 9.9, 100))).max() < 1e-12)
    True
    """

    def spring(self, t):
        return self.sequence.contact_force(t) ** 2 / (2.0 * self.sequence.kappa)

    def balance(self, t):
        return super().balance(t) + self.spring(t)

    def balance_and_work(self, t):
        """:meth:`balance` and :meth:`work`."""
        return self.balance(t), self.work(t)


@dataclass(frozen=True, eq=False)
class ElasticRodImpactSequence(RodImpactSequence):
    r"""The rod impact with a finite contact stiffness followed up to ``t_max``.

    The attributes of :class:`RodImpactSequence`: ``contacts`` (spring compressed,
    :math:`z = y - u > 0`), ``separation_velocities``, ``restitution``, ``final``,
    ``max_fixed_end_stress``; in contact the striker is :math:`N/\kappa` ahead of the rod
    end, and :attr:`energy` includes the spring.

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> seq = impact_sequence(0.5, 0.0, kappa=1e3)
    >>> len(seq.contacts), seq.final
    (1, True)
    >>> rigid = impact_sequence(0.5, 0.0)
    >>> bool(abs(seq.restitution - rigid.restitution) < 1e-2)
    True
    """

    @property
    def energy(self) -> ElasticSequenceEnergy:
        """Striker, spring and rod energies as functions of time."""
        return ElasticSequenceEnergy(self)

    def displacement(self, t):
        """Striker displacement :math:`y = u + N/\\kappa` (in contact) or of the flight."""
        out = np.asarray(super().displacement(t)) + np.asarray(self.contact_force(t)) / self.kappa
        return float(out) if np.ndim(t) == 0 else out

    def velocity(self, t):
        """Striker velocity :math:`y' = u' + N'/\\kappa` (in contact) or of the flight."""
        tt = self._times(t)
        dn = (self._tables.dg(tt) + self._tables.dg(tt - 2.0)) / self.kappa
        if self._flights:
            dn = np.where(self._flight_index(tt)[1], 0.0, dn)
        out = np.asarray(super().velocity(tt)) + dn
        return float(out) if np.ndim(t) == 0 else out


@dataclass(slots=True)
class SequenceState:
    """Where the event loop stands: time ``t``, striker velocity ``v`` and position ``y``,
    rod end position ``u`` (internal: advanced by the step models)."""

    t: float = 0.0
    v: float = 1.0
    y: float = 0.0
    u: float = 0.0


class StepModel(Protocol):
    """What :func:`follow` needs from a contact law (internal protocol).

    ``starts`` is the growing list of the starts of the pieces of :math:`g` (the model
    appends to it as it solves them). Each step method advances ``state`` over one piece
    that ends no later than ``t_next`` (the arrival of the next incoming piece, or
    ``t_max``) and returns whether an event ends it; the piece may be shorter (the model's
    own cap on piece lengths) or empty (rigid contact: a tensile front ends the contact
    at once).
    """

    alpha: float
    f: float
    kappa: float
    starts: list
    errstate: dict  # np.errstate arguments for the whole run
    where: str  # "impact_sequence(alpha=..., ...)", the prefix of every refusal

    def incoming(self, j: int, delta: float) -> Any:
        """Incoming piece ``j`` (:math:`g(t - 2)`), shifted by ``delta`` past its start."""

    def free(self, state: SequenceState, incoming: Any, t_next: float) -> None:
        """The striker has left for good: the rod end reflects the incoming wave."""

    def contact(self, state: SequenceState, incoming: Any, t_next: float) -> bool:
        """A contact piece; ``True`` at a separation (``state.y`` then is ``state.u``)."""

    def flight(self, state: SequenceState, incoming: Any, t_next: float, opening: bool) -> bool:
        """A flight piece (``opening``: it starts at a separation); ``True`` at a
        re-contact (``state.y`` then is ``state.u``)."""

    result: type[RodImpactSequence]  # the result class of this contact law

    def tables(self, t_reached: float) -> Any:
        """The pieces of :math:`g` up to ``t_reached``, as the result object reads them."""

    def g_max(self, tables: Any, s_end: float) -> float:
        """The largest :math:`g` on ``[0, s_end]`` (half the largest fixed-end stress)."""

    def check(self, tables: Any, stress: float, velocities: list) -> None:
        """Refuse a result the model cannot vouch for (before the energy balance)."""

    def balance_note(self) -> str:
        """Appended to a failed balance check's message."""


def follow(
    model: StepModel, *, t_max: float, max_contacts: int, max_pieces: int = MAX_PIECES
) -> RodImpactSequence:
    """Follow the impact through contacts and flights to ``t_max`` with ``model``.

    The contact/flight state machine: pieces end where an incoming piece arrives, at
    ``t_max`` or at an event (separation, re-contact); more than ``max_contacts`` contacts
    raise ``RuntimeError`` (chatter), more than ``max_pieces`` pieces of :math:`g` a
    ``ValueError`` (memory grows with the pieces that occur, up to this bound); for
    ``f = 0`` the striker has left for good (``final``) once it recedes beyond any reach
    of the rod end (energy balance: the rod end stays within :math:`\\sqrt{2 E_{rod}}`),
    and the rod then vibrates freely. The result's energy balance is checked
    (:func:`check_balance`). Internal: called by :func:`impactsym.rod.impact_sequence`
    (arguments validated there).
    """
    where = model.where
    with np.errstate(**model.errstate):
        seq = _run(model, t_max, max_contacts, max_pieces, where)
        check_balance(seq, model.balance_note())
    return seq


def _run(
    model: StepModel, t_max: float, max_contacts: int, max_pieces: int, where: str
) -> RodImpactSequence:
    alpha, f, starts = model.alpha, model.f, model.starts
    state = SequenceState()
    contacts, velocities, flights = [], [], []
    in_contact, contact_start, final = True, 0.0, False
    j = 0  # incoming piece: the one holding t - 2
    incoming_piece, contact, flight = model.incoming, model.contact, model.flight
    try:
        while state.t < t_max:
            t = state.t
            if len(starts) > max_pieces:
                raise ValueError(
                    f"{where}: more than {max_pieces} pieces of g before t = {t:.6g} < "
                    f"t_max = {t_max} (memory); lower t_max"
                )
            # piece boundaries are compared in the time of arrival (start + 2) so that
            # aligned pieces meet exactly
            while j + 1 < len(starts) and starts[j + 1] + 2.0 <= t:
                j += 1
            incoming = incoming_piece(j, max(t - (starts[j] + 2.0), 0.0))
            t_next = min((starts[j + 1] if j + 1 < len(starts) else t) + 2.0, t_max)
            if final:  # free vibration: copy the reflected wave, no events
                model.free(state, incoming, t_next)
            elif in_contact:
                if contact(state, incoming, t_next):
                    contacts.append((contact_start, state.t))
                    velocities.append(state.v)
                    flights.append((state.t, state.y, state.v))
                    in_contact = False
            else:
                opening = bool(flights) and flights[-1][0] == t
                if flight(state, incoming, t_next, opening):
                    if len(contacts) >= max_contacts:
                        raise RuntimeError(
                            f"{where}: more than max_contacts={max_contacts} contacts "
                            f"before t = {state.t:.6g} < t_max = {t_max} (chatter); raise "
                            "max_contacts or lower t_max"
                        )
                    in_contact, contact_start = True, state.t
                elif f == 0.0 and state.v < 0.0:  # left for good?
                    e_rod = 0.5 * alpha * (1.0 - state.v * state.v)  # energy balance
                    final = state.y < -math.sqrt(2.0 * max(e_rod, 0.0)) - 1e-12
    except ValueError as exc:  # e.g. a piece degree beyond what float64 handles
        if str(exc).startswith(where):
            raise
        raise ValueError(
            f"{where}: the float64 pieces fail at t = {state.t:.6g}: {exc}; lower t_max"
        ) from exc
    if in_contact:
        contacts.append((contact_start, t_max))
    tables = model.tables(state.t)
    stress = 2.0 * model.g_max(tables, t_max - 1.0) if t_max > 1.0 else 0.0
    velocities = [float(v) for v in velocities]
    model.check(tables, stress, velocities)
    return model.result(
        alpha,
        f,
        model.kappa,
        t_max,
        [(float(a), float(b)) for a, b in contacts],
        velocities,
        -velocities[-1] if (final and f == 0.0) else math.nan,
        final,
        stress,
        tables,
        tuple(flights),
    )


def check_balance(seq: RodImpactSequence, note: str = "") -> None:
    r"""Refuse a sequence whose energy balance fails by more than ``1e-9`` of
    :math:`\alpha/2 + |f y|` in the middle of a piece (``note`` is appended to the
    message). The float64 pieces grow about one degree per round trip and their
    coefficients cancel, so past some time the result is no longer exact
    (docs/physics.md#the-rod-impact-continued-past-separation). Internal: used by
    :func:`follow`."""
    ends = np.append(seq._tables.start, seq.t_max)
    ts = 0.5 * (ends[:-1] + ends[1:])  # mid-piece: no event (jump) is evaluated
    ts = ts[(ts > 0.0) & (ts < seq.t_max)]
    residual, work = seq.energy.balance_and_work(ts)
    residual = np.abs(residual)
    scale = 0.5 * seq.alpha + np.abs(work)
    bad = np.flatnonzero(~(residual <= _BALANCE_RTOL * scale))  # NaN fails as well
    if bad.size:
        k = bad[0]
        good = float(ts[k - 1]) if k else 0.0
        kappa = "" if math.isinf(seq.kappa) else f", kappa={seq.kappa!r}"
        raise ValueError(
            f"impact_sequence(alpha={seq.alpha!r}, f={seq.f!r}{kappa}, t_max={seq.t_max!r}): "
            f"the float64 pieces are no longer exact at t = {ts[k]:.8g} (energy balance "
            f"residual {residual[k]:.2g} > {_BALANCE_RTOL:g} x (alpha/2 + |f y|)); they are "
            f"trusted up to t = {good:.8g}, lower t_max{note}"
        )
