r"""Designing a PyBullet contact: ``contactStiffness``, ``contactDamping`` for a wanted bounce.

:func:`contact_for` inverts :func:`~impactsym.engines.pybullet.prediction.predict` at the
user's timestep: the pair's ``(k, c)`` whose phase-mean restitution and contact time are
the targets, found by Newton's method in ``(ln k, ln zeta)`` (``zeta = c / (2 sqrt(k
m))``) on whole arrays of designs, started from the continuous textbook design; then the
body's own values by the pair rules (:func:`~impactsym.engines.pybullet.pair.split_pair`:
the other body's default ``contactDamping`` ``0.1`` is taken off). The phase mean is
continuous and piecewise smooth in ``(k, c)`` (the jumps of the per-phase result move
continuously), so Newton converges where a design exists. Under gravity the phases stick
above a damping that falls as the contact lengthens, and the textbook start often lies
there: a point that sticks is not a failure but a step back (the last step halved, or at
the start zeta halved), since below the stick boundary the restitution falls with the
damping and meets the target once (scanned in the tests). Where no design exists (too
short a contact for the step, a restitution the map cannot give, phases that stick) a
``ValueError`` names the reason and a smaller timestep, or under gravity a shorter
contact time, that reaches the target (each checked by designing with it). SI units.

Many targets: where a call holds at least :data:`TABLE_GROUP` targets of one contact
(equal speed, mass and gravity; the timestep and settings are one per call), Newton starts
them instead from the inverse of a table of the phase means
(:func:`~impactsym.engines.pybullet.design_table.table_designs`) and steps on the exact
phase means with the table's Jacobian, one evaluation per step (2-3 per design against
about 14): the designs meet the same test, both targets to ``1e-9``, and agree with the
textbook start's to a few ``1e-9``. Where every target of the call is designed from a
table, the prediction returned (means, ranges, stick fraction) is the summary of the
exact evaluation that accepted each design, not a second one: :func:`predict` of the
returned values gives it again to ~1e-15 (the pair rules' round trip moves ``k`` and
``c`` by an ulp; tested). The rule depends on the call alone; a smaller call
gives the same numbers as before, element by element. A target Newton from the textbook
start does not reach under gravity, with a contact of at most 50 steps, is tried from a
table of its own contact before it is refused: the textbook start can lie past the stick
boundary while a design with a lower damping exists (e.g. ``e = 0.4431`` at 10 steps of
1/240 s, ``m = 0.1`` kg, ``v = 1`` m/s), and the retreats do not always get there (longer
contacts are left out: their tables would reach into sticking points that run to the step
budget, minutes for a refusal).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import PhaseSummary
from impactsym.engines.pybullet.design_table import table_designs
from impactsym.engines.pybullet.pair import combine_pair, split_pair
from impactsym.engines.pybullet.phases import phase_summary
from impactsym.engines.pybullet.prediction import (
    PyBulletContact,
    check_budget,
    check_settings,
    predict,
    summary_contact,
)
from impactsym.engines.pybullet.stepping import DEFAULT_RESTITUTION_THRESHOLD, DEFAULT_SLOP
from impactsym.validation import broadcast, real_array

__all__ = ["DEFAULT_CONTACT_STEPS", "TABLE_GROUP", "contact_for"]

#: without ``contact_time`` the design lasts this many timesteps (phase spread of a few %)
DEFAULT_CONTACT_STEPS = 10
#: a call with at least this many targets of one contact (speed, mass, gravity) designs
#: them from a table of the phase means (:mod:`~impactsym.engines.pybullet.design_table`)
TABLE_GROUP = 256
_RESCUE_STEPS = 50  # targets the textbook path misses get a table up to this many steps
_ITERATIONS = 40  # Newton converges in 6-9 where a design exists, more after retreats
_PROBE = 12  # Newton steps per smaller timestep probed for the message
_RETREATS = 12  # steps back out of sticking points before a design is given up
_RTOL = 1e-9  # Newton's tolerance on both targets (relative)
_CHECK = 1e-6  # a design whose prediction misses a target by more is refused
_FD = 1e-7  # finite-difference step in ln k and ln zeta


def contact_for(
    *,
    restitution: Any,
    speed: Any,
    mass: Any,
    gravity: Any = 0.0,
    contact_time: Any = None,
    timestep: float = 1 / 240,
    substeps: int = 1,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    other_stiffness: Any = np.inf,
    other_damping: Any = 0.1,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> PyBulletContact:
    """``contactStiffness``/``contactDamping`` that give ``restitution`` (phase mean) in PyBullet.

    Parameters
    ----------
    restitution
        Target phase-mean restitution, in ``(0, 1)``.
    speed, mass, gravity
        Approach speed (m/s), the contact's effective mass (kg), gravity (m/s^2).
    contact_time
        Target phase-mean contact time (s); ``None``: ``DEFAULT_CONTACT_STEPS``
        timesteps.
    timestep, substeps, slop, processing_threshold, other_stiffness, other_damping,
    velocity_restitution, restitution_threshold
        As in :func:`~impactsym.engines.pybullet.prediction.predict`.

    Returns
    -------
    PyBulletContact
        ``.stiffness``/``.damping`` to pass to ``changeDynamics`` of the body, the pair's
        values and the prediction (phase mean and range) at ``timestep``.

    Raises
    ------
    ValueError
        Where no design exists at this step: the reason and a timestep that reaches it.

    Notes
    -----
    From :data:`TABLE_GROUP` (256) targets of one contact (equal speed, mass and gravity)
    in the call, Newton starts from a table of the phase means (module docstring): the
    same acceptance (both targets to ``1e-9``), 4-7 times fewer exact evaluations per
    design. Smaller
    calls give the same numbers as before, element by element. Under gravity, a target
    Newton misses from the textbook start gets a table of its own before it is refused
    (contacts of at most 50 steps; longer ones would cost minutes per refusal), so a
    target designed alone is designed in any call; a big call may also design a target
    of a longer contact that a call of its own refuses (its table then finds it).

    >>> d = contact_for(restitution=0.5, speed=1.0, mass=0.1, contact_time=0.05)
    >>> round(d.restitution, 9), round(d.contact_time, 9)
    (0.5, 0.05)
    """
    e, s1 = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {restitution!r}")
    v, s2 = real_array("speed", speed, lower=0.0, strict=True)
    m, s3 = real_array("mass", mass, lower=0.0, strict=True)
    g, s4 = real_array("gravity", gravity, lower=0.0)
    h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not h_scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    h = float(h)
    if contact_time is None:
        t, s5 = np.asarray(DEFAULT_CONTACT_STEPS * h), True
    else:
        t, s5 = real_array("contact_time", contact_time, lower=0.0, strict=True)
    settings = check_settings(
        slop, processing_threshold, substeps, velocity_restitution, restitution_threshold
    )
    shape = broadcast(restitution=e, speed=v, mass=m, gravity=g, contact_time=t)
    e, v, m, g, t = (np.broadcast_to(a, shape).ravel() for a in (e, v, m, g, t))
    check_budget(m * (np.pi / t) ** 2, 0.0, m, h)  # the stiffness of an undamped contact of t
    k, c, summary = _designs(e, t, v, m, g, h, settings)
    bad = ~(np.isfinite(k) & np.isfinite(c))
    if bad.any():
        _refuse(e, t, v, m, g, h, settings, int(np.flatnonzero(bad)[0]))
    k_body, c_body = split_pair(
        stiffness=k, damping=c, other_stiffness=other_stiffness, other_damping=other_damping
    )
    scalar = s1 and s2 and s3 and s4 and s5
    shaped = [np.reshape(a, shape) for a in (k_body, c_body, m, v, g)]
    if scalar:
        shaped = [float(a) for a in shaped]
    k_b, c_b, m_, v_, g_ = shaped
    single = np.ndim(other_stiffness) == 0 and np.ndim(other_damping) == 0
    if single and np.all(np.isfinite(summary)):
        # every design from a table: the summary of its accepting exact evaluation (at the
        # pair's (k, c) as designed; the pair rules' round trip moves them by an ulp) is
        # the prediction, with the ranges: no second evaluation
        k_pair, c_pair = combine_pair(
            stiffness=k_body, damping=c_body, other_stiffness=other_stiffness,
            other_damping=other_damping,
        )  # fmt: skip
        check_budget(k_pair, c_pair, m, h)
        pair = [np.reshape(a, shape) for a in (k_body, c_body, k_pair, c_pair)]
        found = PhaseSummary(*(np.reshape(row, shape) for row in summary))
        return summary_contact(
            found, *pair, scalar=scalar, timestep=h, substeps=settings["substeps"]
        )
    return predict(
        stiffness=k_b,
        damping=c_b,
        mass=m_,
        speed=v_,
        gravity=g_,
        timestep=h,
        other_stiffness=other_stiffness,
        other_damping=other_damping,
        **settings,
    )


def _means(k, c, m, v, g, h, settings):
    """The phase means ``(restitution, contact_time)`` of
    :func:`~impactsym.engines.pybullet.phases.phase_summary` (with PyBullet's defaults
    the break points in closed form and the pieces integrated exactly,
    :func:`~impactsym.engines.pybullet.phase_means.root_summary`)."""
    r = phase_summary(k, c, m, v, g, h, **settings)
    return r.restitution, r.contact_time


def _designs(e, t, v, m, g, h, settings):
    """The pair's ``(k, c)`` of every target (``nan`` where none is found; module
    docstring): the targets of a contact (speed, mass, gravity) that holds at least
    ``TABLE_GROUP`` of them by Newton from a table
    (:func:`~impactsym.engines.pybullet.design_table.table_designs`), the others by
    :func:`_solve` from the textbook start, and those that misses under gravity with
    contacts of at most ``_RESCUE_STEPS`` steps from a table of their own contact (Newton
    from the textbook start can miss a design that exists), and those a shared table
    missed from a table of their own target, so that a target designed alone is designed
    in any call."""
    label, counts = _contacts(v, m, g)
    big = counts[label] >= TABLE_GROUP
    k, c = np.full(e.size, np.nan), np.full(e.size, np.nan)
    summary = np.full((len(dataclasses.fields(PhaseSummary)), e.size), np.nan)
    _from_tables(e, t, v, m, g, h, settings, k, c, summary, big)
    left = np.isnan(k)
    if left.all():  # no table: the textbook path alone, as for any call below TABLE_GROUP
        k, c = _solve(e, t, v, m, g, h, settings)
    elif left.any():
        k[left], c[left] = _solve(*(a[left] for a in (e, t, v, m, g)), h, settings)
    # a second chance under gravity for short contacts (bounded cost: see module docstring)
    short = (g > 0) & (t <= _RESCUE_STEPS * h)
    rescue = ~big & np.isnan(k) & short
    _from_tables(e, t, v, m, g, h, settings, k, c, summary, rescue)
    # a table's box and grid depend on the targets it serves: one a shared table missed
    # gets a table of its own, as in a call of its own, in order; the first still missed
    # ends the retries (the call is refused there, naming it)
    label, counts = _contacts(v[rescue], m[rescue], g[rescue])
    alone = np.zeros(e.size, bool)
    alone[np.flatnonzero(rescue)[counts[label] == 1]] = True
    for i in np.flatnonzero(np.isnan(k) & short & ~alone):
        one = np.zeros(e.size, bool)
        one[i] = True
        _from_tables(e, t, v, m, g, h, settings, k, c, summary, one)
        if np.isnan(k[i]):
            break
    return k, c, summary


def _contacts(v, m, g):
    """The contact of each target (labels ``0, 1, ...`` in the order of the distinct
    ``(speed, mass, gravity)``, as ``np.unique`` of the columns) and each contact's count;
    one contact without sorting."""
    if v.size and np.all(v == v[0]) and np.all(m == m[0]) and np.all(g == g[0]):
        return np.zeros(v.size, int), np.array([v.size])
    _, label, counts = np.unique(
        np.stack([v, m, g]), axis=1, return_inverse=True, return_counts=True
    )
    return label.ravel(), counts


def _from_tables(e, t, v, m, g, h, settings, k, c, summary, todo):
    """Fill ``k``, ``c`` and the rows of their :class:`PhaseSummary` ``summary`` (in
    place; the accepting evaluation's) of the targets ``todo`` from one table per
    contact (:func:`~impactsym.engines.pybullet.design_table.table_designs`; ``nan``
    left where it finds no design)."""
    if not todo.any():
        return
    label, _ = _contacts(v[todo], m[todo], g[todo])
    for group in range(label.max() + 1):
        i = np.flatnonzero(todo)[label == group]
        v0, m0, g0 = v[i[0]], m[i[0]], g[i[0]]

        def evaluate(u, z, v0=v0, m0=m0, g0=g0):
            kk = np.exp(u)
            r = phase_summary(kk, 2.0 * np.exp(z) * np.sqrt(kk * m0), m0, v0, g0, h, **settings)
            fields = (getattr(r, f.name) for f in dataclasses.fields(r))
            with np.errstate(divide="ignore"):
                return r.restitution, np.log(r.contact_time), *fields

        x, found = table_designs(
            evaluate, np.stack([e[i], np.log(t[i])]), _textbook(e[i], t[i], m[i]), rtol=_RTOL
        )
        got = np.all(np.isfinite(x), axis=0)
        k[i[got]] = np.exp(x[0, got])
        c[i[got]] = 2.0 * np.exp(x[1, got]) * np.sqrt(k[i[got]] * m[i[got]])
        if got.any():  # (without a design, found may have no rows)
            summary[:, i[got]] = found[:, got]


def _textbook(e, t, m):
    """The continuous textbook design ``(ln k, ln zeta)``, ``(2, size)``: the damping
    ratio of the clipped linear restitution and the stiffness of the contact time."""
    zeta = -np.log(e) / np.sqrt(np.pi**2 + np.log(e) ** 2)
    omega = np.pi / (t * np.sqrt(1.0 - zeta**2))
    return np.stack([np.log(m * omega**2), np.log(zeta)])


def _solve(e, t, v, m, g, h, settings, iterations=_ITERATIONS):
    """Newton in ``(ln k, ln zeta)`` on all designs; ``nan`` where it does not converge.

    ``h`` is one timestep or one per design.
    """
    h = np.broadcast_to(np.asarray(h, float), e.shape)
    u = _textbook(e, t, m)  # (2, size)
    target = np.stack([e, np.log(t)])
    live = np.ones(e.size, bool)
    done = np.zeros(e.size, bool)
    last = np.zeros_like(u)  # the last Newton step, halved back where its point sticks
    retreats = np.zeros(e.size, int)
    for _ in range(iterations):
        i = np.flatnonzero(live)
        if i.size == 0:
            break
        # the point and its two finite-difference neighbours in one call
        pts = np.concatenate([u[:, i], u[:, i] + [[_FD], [0.0]], u[:, i] + [[0.0], [_FD]]], 1)
        mm, vv, gg, hh = (np.tile(a[i], 3) for a in (m, v, g, h))
        k = np.exp(pts[0])
        c = 2.0 * np.exp(pts[1]) * np.sqrt(k * mm)
        em, tm = _means(k, c, mm, vv, gg, hh, settings)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.stack([em, np.log(tm)]).reshape(2, 3, i.size) - target[:, None, i]
        r0 = f[:, 0]
        ok = np.all(np.isfinite(r0), axis=0) & (np.abs(r0[0]) < _RTOL * e[i])
        ok &= np.abs(r0[1]) < _RTOL
        done[i[ok]] = True
        live[i[ok]] = False
        with np.errstate(divide="ignore", invalid="ignore"):
            jac = np.stack([(f[:, 1] - r0) / _FD, (f[:, 2] - r0) / _FD], axis=1)  # (2, 2, n)
            det = jac[0, 0] * jac[1, 1] - jac[0, 1] * jac[1, 0]
            du0 = -(jac[1, 1] * r0[0] - jac[0, 1] * r0[1]) / det
            du1 = -(-jac[1, 0] * r0[0] + jac[0, 0] * r0[1]) / det
            step = np.stack([du0, du1])
            size = np.max(np.abs(step), axis=0)
            step *= np.where(size > 0.5, 0.5 / np.where(size > 0, size, 1.0), 1.0)
        # a point (or a neighbour) that sticks: under gravity the phases stick above some
        # damping, so retreat: halve the last step back, or at the start (or for a
        # neighbour) lower zeta, and try again
        broken = ~np.all(np.isfinite(step), axis=0) & ~ok
        retreat = np.where(np.isfinite(r0).all(axis=0), 0.01, np.log(2.0))
        halve = np.any(last[:, i] != 0.0, axis=0) & ~np.isfinite(r0).all(axis=0)
        back = np.where(halve, -0.5 * last[:, i], [[0.0], [-1.0]] * retreat)
        retreats[i] = np.where(broken, retreats[i] + 1, 0)
        live[i[broken & (retreats[i] > _RETREATS)]] = False
        step = np.where(broken, back, step)
        last[:, i] = np.where(broken & halve, 0.5 * last[:, i], np.where(broken, 0.0, step))
        move = ~ok
        u[:, i[move]] += step[:, move]
    k = np.where(done, np.exp(u[0]), np.nan)
    c = np.where(done, 2.0 * np.exp(u[1]) * np.sqrt(k * m), np.nan)
    if done.any():  # the check: the prediction of the design meets both targets
        em, tm = _means(k[done], c[done], m[done], v[done], g[done], h[done], settings)
        miss = (np.abs(em - e[done]) > _CHECK * e[done]) | (np.abs(tm / t[done] - 1) > _CHECK)
        k[np.flatnonzero(done)[miss]] = np.nan
    return k, c


def _refuse(e, t, v, m, g, h, settings, i):
    """Raise the ``ValueError`` for design ``i``: the reason and a step that reaches it."""
    reaching = None
    for trial in h / 2.0 ** np.arange(1, 7):
        k, _ = _solve(*(a[i : i + 1] for a in (e, t, v, m, g)), trial, settings, _PROBE)
        if np.isfinite(k[0]):
            reaching = float(trial)
            break
    shorter = None
    if reaching is None and g[i] > 0:  # under gravity a shorter contact may leave
        for frac in (0.5, 0.25):
            row = [a[i : i + 1] for a in (e, t, v, m, g)]
            row[1] = row[1] * frac
            k, _ = _solve(*row, h, settings, _PROBE)
            if np.isfinite(k[0]):
                shorter = float(t[i] * frac)
                break
    where = f"element {i}, " if e.size > 1 else ""  # (a call of one: no index to name)
    e, t, v, m, g = (float(a[i]) for a in (e, t, v, m, g))
    steps = t / h
    why = (
        f"the contact lasts only {steps:.3g} timesteps"
        if steps < 3
        else "the phase-mean restitution of PyBullet's map does not reach it at this step "
        "(or the body sticks)"
        + (
            ": under gravity the phases stick, the weight holding the soft contact, above a "
            "damping that falls as the contact lengthens, and the damping this restitution "
            "needs lies past it"
            if g > 0 and reaching is None
            else ""
        )
    )
    hint = (
        f"; timestep = {reaching:.6g} s reaches it"
        if reaching is not None
        else "; no timestep down to timestep / 64 reaches it"
    )
    if shorter is not None:
        hint += f"; contact_time = {shorter:.6g} s reaches it at this timestep"
    raise ValueError(
        f"no PyBullet contact gives restitution = {e!r} with contact_time = {t!r} s "
        f"({where}speed {v!r} m/s, mass {m!r} kg, gravity {g!r}) at timestep = {h!r} s: "
        f"{why}{hint}"
    )
