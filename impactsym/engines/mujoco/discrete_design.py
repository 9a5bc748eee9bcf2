r"""``solref`` for a wanted restitution (and contact time) at the user's timestep.

:func:`~impactsym.engines.mujoco.design.solref_for` with a ``timestep`` lands here. The
target is the **phase mean** of :func:`~impactsym.engines.mujoco.prediction.predict` at
that timestep and integrator (``phase=None``), used as a vectorized black box
``E(timeconst, dampratio)``: whatever the discrete model inside, the design inverts it.

* Restitution alone (timeconst fixed at ``max(0.02, 2 timestep)``): the phase mean falls
  with the dampratio in the large, but not monotonically near the step map's stability
  limit, so it is evaluated on a geometric dampratio grid from that limit to 100 and the
  **largest-dampratio crossing** (the softest design: the most engine steps per contact,
  the farthest from instability) is refined by the Illinois method in ``log dampratio``.
  The mean is continuous in the ``solref`` even where the end step jumps at some phase
  (the jump moves through the phases), so the bracket holds a root unless the body
  starts to stick at some phase inside it (then refused). Where the continuous design
  at that timeconst brackets the crossing within a factor ``_LOCAL`` and that bracket
  lies clear of the stability limit (``_local_crossing``), the grid is skipped and the
  crossing nearest the continuous design is taken: the same crossing wherever the mean
  falls monotonically, for a fraction of the evaluations. Many targets of one contact
  (speed, gravity, weight) share one phase mean: it is tabulated and inverted first
  (:mod:`~impactsym.engines.mujoco.table_design`; hits the target to ``1e-9``; where
  the summary is the costly general one, most designs and their summaries are read off
  a table of it).
* With a contact time: a Newton iteration on ``(log timeconst, log dampratio)`` with a
  forward-difference Jacobian (:func:`impactsym.numeric.roots.newton_system`), started
  at the continuous design (close: the discrete mean differs by the step's error).
  Many targets of one contact and one contact time lie on one curve of designs
  ``u(e)``: Newton solves up to ``_CURVE`` of them, the others start at its cubic
  interpolation and keep it where both residuals are below the Newton tolerance
  already (``_curve_newton``; 99 % of 1e5 evenly spread targets), Newton from there
  elsewhere.
* A target the timestep cannot deliver (MuJoCo's refsafe floor ``timeconst >= 2
  timestep``, the stability limit of the step map, sticking at some phase) raises
  ``ValueError`` with the reason and a timestep that does deliver it: found by halving
  the timestep until the design succeeds, then bisection (in log) between the last
  failure and that success; the returned value is one at which the design was
  completed (the reachability need not be monotone in the timestep).

The stability limit: inside the contact the Euler step (and ``implicitfast``, the same
map here) is the affine map of matrix ``[[1 - k, 1 - b], [-k, 1 - b]]`` with
``k = d' d kbar dt^2``, ``b = d' b dt``, stable iff ``b < 2`` and ``k + 2 b < 4`` (Jury);
RK4 is stable iff ``|R(z)| < 1`` for both roots ``z`` of ``z^2 + b z + k = 0``,
``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``. Both are taken at ``d = d_max`` (the largest
``k`` and ``b`` of a varying impedance). `docs/physics.md#touch-phase`.
All quantities are SI: seconds, m/s, m/s^2, kilograms.
"""

from __future__ import annotations

from dataclasses import fields
from types import SimpleNamespace
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import bounds_without_search, phase_mean
from impactsym.engines.mujoco.model import (
    DEFAULT_TIMECONST,
    coefficients,
    d_max,
    effective_impedance,
    refsafe,
    weight_ratio,
)
from impactsym.engines.mujoco.table_design import table_crossings
from impactsym.numeric.poly import cubic_lagrange
from impactsym.numeric.roots import bracketed_illinois, newton_system

__all__ = ["DiscreteTarget", "design_discrete", "stable"]

#: dampratio grid of the restitution design: points, upper end
_GRID = 33
_DR_TOP = 1e2
#: factor on either side of the continuous design for the local bracket
_LOCAL = 1.25
#: ... used where it lies above this multiple of the stability limit's dampratio
_CLEAR = 2.2
#: targets from which the tabulated mean is tried (per contact it needs 128)
_TABLE_FROM = 128
#: a design is accepted when its phase mean is this close (absolute in e, relative in t_c)
_DESIGN_TOL = 1e-5
#: forward-difference step of the Newton Jacobian (in log timeconst, log dampratio)
_EPS = 1e-6
#: the Newton iteration's tolerance on both residuals
_NEWTON_TOL = 1e-9
#: designs solved by Newton on the curve of many contact-time designs of one contact
_CURVE = 1024
#: halvings of the timestep tried when looking for one that reaches a refused target
_HALVINGS = 8
_BISECTIONS = 3


def stable(*, kappa: Any, beta: Any, integrator: str) -> np.ndarray:
    """Whether the in-contact step map with ``k = kappa``, ``b = beta`` is stable (docstring)."""
    kappa, beta = np.asarray(kappa, float), np.asarray(beta, float)
    if integrator != "rk4":
        return (beta < 2.0) & (kappa + 2.0 * beta < 4.0)
    root = np.sqrt((beta * beta - 4.0 * kappa).astype(complex))
    ok = np.ones(np.broadcast(kappa, beta).shape, bool)
    for z in (0.5 * (-beta + root), 0.5 * (-beta - root)):
        ok &= np.abs(1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)))) < 1.0
    return ok


class DiscreteTarget:
    """The targets of one discrete design and the black box ``E(timeconst, dampratio)``.

    Flat 1-D arrays: ``restitution``, ``speed``, ``gravity``, ``contact_time`` (or
    ``None``), ``weight`` (``inverse_weight`` or ``None``), ``rho``, ``start`` (the
    continuous design ``(timeconst, dampratio)``, or ``None``); scalars ``solimp``,
    ``mass``, ``timestep``, ``integrator``.
    """

    def __init__(self, e, v, g, t_c, solimp, mass, weight, rho, timestep, integrator, start):
        self.e, self.v, self.g, self.t_c = e, v, g, t_c
        self.solimp, self.mass, self.weight, self.rho = solimp, mass, weight, rho
        self.timestep, self.integrator, self.start = timestep, integrator, start
        self._last = None  # the last phase mean of each element (record)
        self._parent = None  # (targets, indices there) of a part made by take()
        #: the continuous design of elements ``i`` (raises where it refuses them); set
        #: by the caller, used to skip the timestep search where no timestep can help
        self.continuous = None
        #: the continuous dampratio of elements ``i`` at the restitution design's
        #: timeconst (raises where refused); set by the caller, a start for the design
        self.guess = None

    def take(self, i: np.ndarray) -> DiscreteTarget:
        """The targets of the elements ``i``."""

        def part(a):
            return None if a is None else np.broadcast_to(a, self.e.shape)[i]

        out = DiscreteTarget(
            self.e[i], self.v[i], self.g[i], part(self.t_c), self.solimp, self.mass,
            part(self.weight), part(self.rho), self.timestep, self.integrator,
            None if self.start is None else tuple(part(a) for a in self.start),
        )  # fmt: skip
        out._parent = (self, np.arange(self.e.size)[i])  # its means are recorded here too
        return out

    def at(self, timestep: float) -> DiscreteTarget:
        """The same targets at another timestep."""
        out = self.take(np.arange(self.e.size))
        out.timestep = timestep
        out._parent = None  # its means are of another timestep
        return out

    def summary(self, tc, dr, idx) -> np.ndarray:
        """The phase summary at ``solref = (tc, dr)`` of elements ``idx`` with exact
        bounds, ``(7, size)`` (the fields of
        :class:`~impactsym.engines.mujoco.discrete.PhaseSummary`; sticking at some phase:
        an infinite contact time, the rest ``nan``): a table of designs reads its
        designs' summaries off it (:mod:`~impactsym.engines.mujoco.table_design`)."""
        return _stacked(self._phase_mean(tc, dr, idx, bounds=True))

    def mean(self, tc, dr, idx, *, bounds=False):
        """Phase mean at ``solref = (tc, dr)`` of elements ``idx``: ``restitution``,
        ``contact_time`` and ``sticks`` (at some phase), as ``predict(phase=None)``.

        ``bounds=True`` where the design may end at ``(tc, dr)``: the general summary then
        also searches the extremes inside its pieces, so that the bounds are exact and the
        design's prediction reuses the whole summary (:meth:`known_at`). At flat impedance
        (Euler, ``implicitfast``) they are exact without the search and always kept.
        """
        exact = bounds_without_search(self.integrator, self.solimp)
        p = self._phase_mean(tc, dr, idx, bounds=bounds and not exact)
        if bounds or exact:  # its bounds are exact
            self.record(tc, dr, idx, _stacked(p))
        return SimpleNamespace(
            restitution=p.restitution, contact_time=p.contact_time, sticks=np.isinf(p.contact_time)
        )

    def _phase_mean(self, tc, dr, idx, *, bounds):
        weight = None if self.weight is None else np.broadcast_to(self.weight, self.e.shape)[idx]
        rho = weight_ratio(self.mass, weight)
        h = self.timestep
        return phase_mean(
            coefficients((tc, dr), self.solimp, h),
            self.solimp,
            rho,
            self.g[idx],
            self.v[idx],
            h,
            integrator=self.integrator,
            bounds=bounds,
            resolve_sticking=False,
        )

    def record(self, tc: Any, dr: Any, idx: np.ndarray, summary: np.ndarray) -> None:
        """Keep the last phase summary ``(7, size)`` of elements ``idx`` (the fields of
        :class:`~impactsym.engines.mujoco.discrete.PhaseSummary`), with its ``solref``
        (and in the targets this one was taken from)."""
        if self._last is None:
            self._last = np.full((9, self.e.size), np.nan)
        self._last[0, idx], self._last[1, idx] = tc, dr
        self._last[2:, idx] = summary
        if self._parent is not None:
            parent, where = self._parent
            parent.record(tc, dr, where[idx], summary)

    def known_at(self, tc: np.ndarray, dr: np.ndarray) -> np.ndarray:
        """The phase means evaluated at exactly ``solref = (tc, dr)`` (one per element)
        by :meth:`mean` with exact bounds: ``(7, size)``, ``nan`` columns where none was
        (the ``known`` of :func:`~impactsym.engines.mujoco.discrete.phase_summary`)."""
        if self._last is None:
            return np.full((7, self.e.size), np.nan)
        same = (self._last[0] == tc) & (self._last[1] == dr) & ~np.isnan(self._last[2])
        return np.where(same[None, :], self._last[2:], np.nan)

    def stability_dampratio(self, tc: np.ndarray) -> np.ndarray:
        """Smallest stable dampratio at timeconst ``tc`` (bisection in log; ``inf``: none).

        Computed once per distinct ``(timeconst, weight ratio)``: many targets share one.
        Euler and ``implicitfast`` in closed form: with ``tc`` after refsafe,
        ``beta = 2 d' h / (d_max tc)`` and ``kappa = d' h^2 / (d_max tc^2 dr^2)``, the map
        is stable iff ``beta < 2`` and ``dr^2 > d' h^2 / (d_max tc^2 (4 - 2 beta))``.
        """
        if self.integrator != "rk4":
            dm = d_max(self.solimp)
            dp = effective_impedance(dm, np.broadcast_to(self.rho, self.e.shape))
            h = self.timestep
            tc = refsafe(np.broadcast_to(tc, self.e.shape), h)
            beta = 2.0 * dp * h / (dm * tc)
            with np.errstate(divide="ignore", invalid="ignore"):
                dr = np.sqrt(dp * h * h / (dm * tc * tc * (4.0 - 2.0 * beta)))
            dr = np.where(beta < 2.0, dr, np.inf)
            return np.where(dr < 1e-6, 0.0, np.where(dr < _DR_TOP, dr, np.inf))
        shape = self.e.shape
        pairs = np.stack([np.broadcast_to(tc, shape), np.broadcast_to(self.rho, shape)])
        (tc, rho), back = np.unique(pairs, axis=1, return_inverse=True)
        dm = d_max(self.solimp)
        dp = effective_impedance(dm, rho)
        h = self.timestep

        def ok(dr):
            c = coefficients((tc, dr), self.solimp, h)
            return stable(
                kappa=dp * dm * c.stiffness * h * h,
                beta=dp * c.damping * h,
                integrator=self.integrator,
            )

        lo, hi = np.full(tc.shape, 1e-6), np.full(tc.shape, _DR_TOP)
        top = ok(hi)
        every = ok(lo)
        for _ in range(60):
            mid = np.sqrt(lo * hi)
            good = ok(mid)
            lo, hi = np.where(good, lo, mid), np.where(good, mid, hi)
        return np.where(every, 0.0, np.where(top, hi, np.inf))[back.ravel()]


def _stacked(p: Any) -> np.ndarray:
    """A phase summary's fields as one ``(7, size)`` array."""
    return np.stack([np.ravel(getattr(p, f.name)) for f in fields(p)])


def _refuse(tg: DiscreteTarget, i: int, why: str, solve) -> None:
    """Raise for element ``i``: ``why``, and a timestep that reaches it (``solve`` on one)."""
    one = tg.take(np.array([i]))
    wanted = f"restitution = {float(tg.e[i])!r}" + (
        "" if tg.t_c is None else f" with contact_time = {float(tg.t_c[i])!r} s"
    )
    try:
        if tg.continuous is not None:
            tg.continuous(np.array([i]))
    except ValueError as exc:  # the limit timestep -> 0 refuses it too: no search
        where = f"no timestep reaches it (the continuous design refuses it too: {exc})"
    else:
        h = reaching_timestep(one, solve)
        where = (
            f"timestep = {h!r} s reaches it"
            if h is not None
            else f"no timestep down to {tg.timestep / 2**_HALVINGS:.3g} s reaches it"
        )
    raise ValueError(
        f"{wanted} (element {i}) cannot be reached at timestep = {tg.timestep!r} s with "
        f"integrator {tg.integrator!r} (phase mean): {why}; {where}"
    )


def reaching_timestep(one: DiscreteTarget, solve) -> float | None:
    """A timestep below ``one.timestep`` at which ``solve`` designs the single target.

    Halves the timestep until the design succeeds, then bisects (in log) between the last
    failure and the success; returns a timestep at which it succeeded (``None`` if none
    down to ``timestep / 2**8``).
    """

    def works(h):
        try:
            solve(one.at(h), refuse=False)
        except ValueError:
            return False
        return True

    bad = one.timestep
    good = None
    for _ in range(_HALVINGS):
        h = bad / 2.0
        if works(h):
            good = h
            break
        bad = h
    if good is None:
        return None
    for _ in range(_BISECTIONS):
        mid = np.sqrt(good * bad)
        if works(mid):
            good = mid
        else:
            bad = mid
    # the value the message prints (3 digits, rounded down) if it works too
    scale = 10.0 ** (np.floor(np.log10(good)) - 2)
    short = float(np.floor(good / scale) * scale)
    return short if works(short) else float(good)


def _restitution_design(tg: DiscreteTarget, tc: np.ndarray, refuse: bool = True) -> np.ndarray:
    """Dampratio at timeconst ``tc`` whose phase-mean restitution is ``tg.e`` (module doc)."""
    n = tg.e.size
    dr_min = tg.stability_dampratio(tc)
    if not np.all(np.isfinite(dr_min)):
        i = int(np.flatnonzero(~np.isfinite(dr_min))[0])
        _raise(tg, i, "the step map is unstable for every dampratio up to 100", refuse)

    def gap(dr, i, final=False):  # target minus phase mean; sticking counts as restitution 0
        p = tg.mean(tc[i], dr, i, bounds=final)
        return tg.e[i] - np.where(np.asarray(p.sticks), 0.0, np.asarray(p.restitution))

    dr = np.full(n, np.nan)
    rows = np.arange(n)
    low = np.maximum(dr_min * (1.0 + 1e-3), 1e-3)  # the bottom of the scan
    checked = np.zeros(n, bool)  # hit to 1e-9: the table's guess evaluated, or read off
    if n >= _TABLE_FROM:  # many targets of one contact: the tabulated mean
        same = np.stack([tg.g, tg.v, np.broadcast_to(tg.rho, (n,))])
        if np.all(same == same[:, :1]):  # one contact (the common case): no sort
            contact = np.zeros(n, int)
        else:
            contact = np.unique(same, axis=1, return_inverse=True)[1]
        # the general summary is costly: designs are read off a table of it where smooth
        costly = not bounds_without_search(tg.integrator, tg.solimp)
        dr[:], rows, checked, known = table_crossings(
            gap, contact.ravel(), tg.e, low, _DR_TOP,
            (lambda d, i: tg.summary(tc[i], d, i)) if costly else None,
        )  # fmt: skip
        read = np.flatnonzero(np.isfinite(known[0]))  # designs read off the table
        if read.size:
            tg.record(tc[read], dr[read], read, known[:, read])
    if tg.guess is not None and rows.size:  # a local bracket around the continuous design
        try:
            guess = np.full(n, np.nan)
            guess[rows] = tg.guess(rows)
        except ValueError:  # the continuous design refuses some: the scan decides
            pass
        else:
            dr[rows], rows = _local_crossing(gap, guess, dr_min, rows)
    if rows.size:
        dr[rows] = _grid_crossing(tg, gap, tc, dr_min, rows, refuse)
    rows = np.flatnonzero(~checked)
    p = tg.mean(tc[rows], dr[rows], rows, bounds=True)
    e = np.asarray(p.restitution)
    miss = np.asarray(p.sticks) | ~(np.abs(e - tg.e[rows]) <= _DESIGN_TOL)
    if miss.any():
        i = int(rows[np.flatnonzero(miss)[0]])
        more = tg.mean(tc[i : i + 1], dr[i : i + 1] * (1 + 1e-6), np.array([i]))
        why = (
            f"the body starts to stick at some touch phase at dampratio = {dr[i]:.6g}, "
            f"where the phase-mean restitution is still above it"
            if bool(np.any(p.sticks)) or bool(np.any(more.sticks))
            else f"the phase-mean restitution jumps at dampratio = {dr[i]:.6g}"
        )
        _raise(tg, i, why, refuse)
    return dr


def _local_crossing(gap, guess: np.ndarray, dr_min: np.ndarray, rows: np.ndarray) -> tuple:
    """Crossings bracketed by ``guess / _LOCAL`` and ``guess * _LOCAL`` (log Illinois).

    ``guess`` is the continuous design, within the step's error of the discrete one.
    Used only where the bracket lies above ``_CLEAR`` times the stability limit's
    dampratio: nearer the limit the phase mean rises with the dampratio over a band
    (measured: from about 1.42 to 2.03 times the limit at speeds of 0.3 m/s and more,
    dt = 0.0002 to 0.004 s). Above it the mean falls with the dampratio but for small
    bumps at slow approaches (``g dt / v`` large), where a target may be crossed more
    than once: the design is then the crossing nearest the continuous one, the grid's
    largest crossing elsewhere. Returns the dampratios (``nan`` where not found) and the
    elements left to the grid.
    """
    dr = np.full(rows.size, np.nan)
    lo, hi = guess[rows] / _LOCAL, guess[rows] * _LOCAL
    ok = np.flatnonzero(np.isfinite(lo) & (lo > _CLEAR * dr_min[rows]))
    cand = rows[ok]
    lo, hi = lo[ok], hi[ok]
    if cand.size:
        f_lo, f_hi = gap(lo, cand), gap(hi, cand)
        good = (f_lo < 0) & (f_hi >= 0)
        c = cand[good]
        if c.size:
            dr[ok[good]] = bracketed_illinois(
                lambda x, j: gap(x, c[j]),
                lo[good],
                hi[good],
                log=True,
                rtol=1e-12,
                f_lo=f_lo[good],
                f_hi=f_hi[good],
            )
    return dr, rows[np.isnan(dr)]


def _grid_crossing(tg, gap, tc, dr_min, rows, refuse) -> np.ndarray:
    """The largest-dampratio crossing of elements ``rows`` on a geometric grid (module doc)."""
    n = rows.size
    low = np.maximum(dr_min[rows] * (1.0 + 1e-3), 1e-3)
    grid = np.exp(np.linspace(np.log(low), np.log(_DR_TOP), _GRID).T)  # (n, K)
    f = gap(grid.ravel(), np.repeat(rows, _GRID)).reshape(n, _GRID)
    below = f < 0  # too bouncy at this dampratio
    if np.any(below[:, -1]):
        i = int(rows[np.flatnonzero(below[:, -1])[0]])
        _raise(tg, i, f"even dampratio = {_DR_TOP:g} rebounds faster", refuse)
    if not np.all(below.any(axis=1)):
        j = int(np.flatnonzero(~below.any(axis=1))[0])
        i = int(rows[j])
        _raise(
            tg,
            i,
            f"the phase-mean restitution stays below it for every stable dampratio (at "
            f"most {tg.e[i] - f[j].min():.4g}, the step map being unstable below dampratio "
            f"= {dr_min[i]:.4g} at timeconst = {tc[i]:.4g} s), or the body sticks at some "
            f"phase",
            refuse,
        )
    last = _GRID - 1 - np.argmax(below[:, ::-1], axis=1)  # the largest-dampratio crossing
    k = np.arange(n)
    return bracketed_illinois(
        lambda x, j: gap(x, rows[j]),
        grid[k, last],
        grid[k, last + 1],
        log=True,
        rtol=1e-12,
        f_lo=f[k, last],
        f_hi=f[k, last + 1],
    )


def _both_design(tg: DiscreteTarget, refuse: bool = True) -> tuple:
    """``(timeconst, dampratio)`` for the phase-mean restitution and contact time."""
    h = tg.timestep
    floor = 2.0 * h
    n = tg.e.size
    tc0, dr0 = (np.asarray(a, float) for a in tg.start)
    if np.any(tc0 < floor):
        i = int(np.flatnonzero(tc0 < floor)[0])
        _raise(
            tg,
            i,
            f"it needs timeconst = {tc0[i]:.4g} s < 2 * timestep (MuJoCo's refsafe "
            f"floor raises it to {floor:g} s)",
            refuse,
        )

    u0 = np.stack([np.log(tc0), np.log(dr0)])
    u, r = _curve_newton(tg, u0) if n >= _TABLE_FROM else _newton(tg, u0)
    tc, dr = np.exp(u[0]), np.exp(u[1])
    miss = ~((np.abs(r[0]) <= _DESIGN_TOL) & (np.abs(r[1]) <= _DESIGN_TOL)) | (tc < floor)
    if miss.any():
        i = int(np.flatnonzero(miss)[0])
        if tc[i] <= floor * (1.0 + 1e-6):
            why = (
                f"it needs timeconst = {tc[i]:.4g} s < 2 * timestep (MuJoCo's refsafe "
                f"floor raises it to {floor:g} s)"
            )
        elif not np.isfinite(r[0, i]):
            why = (
                "the Newton system is singular from the continuous design on (the body "
                "sticks at some touch phase, or the phase mean does not change there)"
            )
        elif r[1, i] > 1.0:
            why = "the body sticks at some touch phase near the design"
        else:
            why = (
                f"the Newton iteration from the continuous design stops at solref = "
                f"({tc[i]:.6g}, {dr[i]:.6g}), missing it by {r[0, i]:.3g} in the "
                f"restitution (the step map is near its stability limit, or the target "
                f"is out of the phase mean's range)"
            )
        _raise(tg, i, why, refuse)
    return tc, dr


def _residual(tg: DiscreteTarget):
    """The Newton residual of the contact-time design of ``tg`` in ``u = (log tc, log dr)``."""
    h = tg.timestep
    floor = 2.0 * h
    rows = np.arange(tg.e.size)

    def resid(u):
        # below the refsafe floor MuJoCo runs timeconst 2 timestep: the contact time is
        # continued there by log(timeconst / floor) so that the Newton system stays
        # regular and a solution below the floor shows as such (refused below)
        tc = refsafe(np.exp(u[0]), h)
        dr = np.maximum(np.exp(u[1]), tg.stability_dampratio(tc) * (1.0 + 1e-3))
        p = tg.mean(tc, dr, rows)
        sticks = np.asarray(p.sticks)
        e = np.where(sticks, 0.0, np.asarray(p.restitution))
        t = np.where(sticks, 1e3 * tg.t_c, np.asarray(p.contact_time))
        return np.stack([e - tg.e, np.log(t / tg.t_c) + np.minimum(u[0] - np.log(floor), 0.0)])

    return resid


def _newton(tg: DiscreteTarget, u0: np.ndarray) -> tuple:
    """``(u, r)`` of the Newton iteration from ``u0`` (``r = inf`` where it breaks down)."""
    try:
        return newton_system(
            _residual(tg), u0, eps=_EPS, max_step=0.5, tol=_NEWTON_TOL, max_iter=20
        )
    except np.linalg.LinAlgError:  # a residual flat in an unknown: refsafe floor or stick
        return u0, np.full(u0.shape, np.inf)


def _curve_newton(tg: DiscreteTarget, u0: np.ndarray) -> tuple:
    """:func:`_newton` for many targets; those of one contact and one contact time share
    a curve ``u(e)`` of designs: solved at ``_CURVE`` of them (nodes spread over the
    sorted restitutions), interpolated (cubic Lagrange through the four nearest nodes)
    for the others, kept where the interpolated design's residual is below the Newton
    tolerance already, iterated from there elsewhere."""
    n = tg.e.size
    same = np.stack([tg.g, tg.v, np.broadcast_to(tg.rho, (n,)), tg.t_c])
    if not np.all(same == same[:, :1]):
        return _newton(tg, u0)
    order = np.argsort(tg.e, kind="stable")
    pick = order[np.round(np.linspace(0, n - 1, min(_CURVE, n // 8))).astype(int)]
    nodes = pick[np.concatenate([[True], np.diff(tg.e[pick]) > 0])]  # distinct targets
    u_n, r_n = _newton(tg.take(nodes), u0[:, nodes])
    if nodes.size < 4 or not np.all(np.abs(r_n) < _NEWTON_TOL):
        return _newton(tg, u0)  # some node is refused: the plain way says why
    u, r = np.empty_like(u0), np.empty_like(u0)
    u[:, nodes], r[:, nodes] = u_n, r_n
    rest = np.setdiff1d(np.arange(n), nodes)
    u[:, rest] = cubic_lagrange(tg.e[nodes], u_n, tg.e[rest])[0]
    r[:, rest] = _residual(tg.take(rest))(u[:, rest])
    again = rest[~np.all(np.abs(r[:, rest]) < _NEWTON_TOL, axis=0)]
    if again.size:
        u[:, again], r[:, again] = _newton(tg.take(again), u[:, again])
    return u, r


def _raise(tg: DiscreteTarget, i: int, why: str, refuse: bool) -> None:
    if not refuse:  # probing another timestep: no nested timestep search
        raise ValueError(why)
    _refuse(tg, i, why, _solve)


def _solve(tg: DiscreteTarget, refuse: bool = True) -> tuple:
    """The discrete design of ``tg``."""
    if tg.t_c is None:
        tc = np.full(tg.e.shape, max(DEFAULT_TIMECONST, 2.0 * tg.timestep))
        return tc, _restitution_design(tg, tc, refuse)
    return _both_design(tg, refuse)


def design_discrete(tg: DiscreteTarget) -> tuple[np.ndarray, np.ndarray]:
    """``(timeconst, dampratio)`` arrays whose phase-mean prediction hits ``tg`` (module doc).

    ``tg.start`` is the continuous design (needed with a contact time). Raises
    ``ValueError`` with the reason and a timestep that reaches a refused target.
    """
    return _solve(tg, True)
