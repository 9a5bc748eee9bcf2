r"""The bracketed flat-impedance continuous design of MuJoCo's ``solref``: the reference
and the fallback of :mod:`~impactsym.engines.mujoco.flat_design`.

The restitution of the flat contact falls with the dampratio, continuously or by a jump
where the release switches from the force to the penetration, so one bracket
``[1e-3, 100]`` and the Illinois method in ``log`` dampratio find it
(:func:`bracketed_dampratio`); with a contact time the contact time grows with the
timeconst at every dampratio (an inner bracket ``[1e-6, 1e3]``) and the outer solve
brackets the dampratio on a grid of 21 values, because at some dampratios no timeconst
gives the contact time (:func:`nested_both`). Each step costs a release kernel, so
:mod:`~impactsym.engines.mujoco.flat_design` hands them only what its fast iterations do
not settle; what they cannot reach they refuse with its cause (a jump, sticking, out of
the brackets), naming the element (`docs/physics.md#simulation-engines`). Internal.
SI units throughout.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.mujoco.continuous import ContactPhase, flat_phase
from impactsym.engines.mujoco.model import coefficients, impedance_at
from impactsym.numeric.roots import bracketed_illinois

__all__ = [
    "DR_RANGE",
    "TC_RANGE",
    "bracketed_dampratio",
    "flat_restitution",
    "nested_both",
    "unreachable",
]

DR_RANGE = (1e-3, 1e2)  #: the dampratios the bracketed design searches
TC_RANGE = (1e-6, 1e3)  #: the timeconsts its inner bracket searches


def unreachable(
    what: str, mask: np.ndarray, targets: np.ndarray, hint: str, index: Any = None
) -> None:
    """Raise ``ValueError`` for the first element of ``mask``, naming it (``index``: the
    caller's numbers of the elements, default their positions) and its target."""
    if mask.any():
        first = np.flatnonzero(mask)[0]
        number = first if index is None else int(np.asarray(index)[first])
        raise ValueError(
            f"restitution = {float(targets.flat[first])!r} (element {number}) cannot be "
            f"reached: {what}; {hint}"
        )


def flat_restitution(tc, dr, simp, rho, g, v0, *, extremes: bool = True) -> ContactPhase:
    """The contact phase at ``solref = (tc, dr)`` for a flat ``simp`` (closed form)."""
    d = float(impedance_at(np.zeros(()), simp))
    return flat_phase(coefficients((tc, dr), simp, None), d, rho, g, v0, extremes=extremes)


def bracketed_dampratio(e_t, v0, g, tc, simp, rho, *, index):
    """The bracketed design of the dampratio (Illinois in ``log dr`` on ``[1e-3, 100]``);
    refusals name the elements by ``index``."""
    n = e_t.size
    # the last dampratio tried and its restitution, per element: the gap check below
    # reads the restitution at the root the solver last evaluated instead of redoing it
    last_dr, last_e = np.full(n, np.nan), np.full(n, np.nan)

    def e_of(dr, idx):
        e = flat_restitution(tc[idx], dr, simp, rho[idx], g[idx], v0[idx], extremes=False)
        last_dr[idx], last_e[idx] = dr, e.restitution
        return e.restitution

    def e_at(dr):
        known = last_dr == dr
        if known.all():
            return last_e.copy()
        out = last_e.copy()
        out[~known] = e_of(dr[~known], np.flatnonzero(~known))
        return out

    # e falls with the dampratio, continuously or by a jump where the release switches
    # from the force to the penetration (then refused below); one bracket suffices
    idx = np.arange(n)
    # the ends as the solver (in log dampratio) sees them, so their restitutions serve it
    lo, hi = (np.exp(np.log(np.full(n, q))) for q in DR_RANGE)
    e_lo = e_of(lo, idx)
    unreachable(
        "the body sticks or rebounds too slowly for every dampratio in [1e-3, 100]",
        e_lo <= e_t,
        e_t,
        "a higher speed, less gravity or a shorter timeconst (contact_time=...) reaches it",
        index,
    )
    e_hi = e_of(hi, idx)
    hi = np.where(e_hi <= e_t, hi, np.nan)
    unreachable(
        "even dampratio = 100 rebounds faster",
        np.isnan(hi),
        e_t,
        "a lower speed or more gravity reaches it",
        index,
    )
    dr = bracketed_illinois(
        lambda x, i: e_t[i] - e_of(x, i),
        lo,
        hi,
        log=True,
        rtol=1e-10,
        f_lo=e_t - e_lo,
        f_hi=e_t - e_hi,
    )

    def stuck(x):
        return np.isinf(flat_restitution(tc, x, simp, rho, g, v0, extremes=False).contact_time)

    e_dr = lambda x: e_at(x) if x is dr else e_of(x, idx)  # noqa: E731
    _check_gap(e_dr, e_t, dr, "dampratio", stuck, index)
    return dr


def _check_gap(e_of, e_t, at, name, stuck, index):
    """Refuse a target the solver could not reach: the body starts to stick there, or the
    restitution jumps where the release switches from force to position.

    ``stuck(x)`` says where the design at ``x`` sticks (for a wanted contact time: where
    no timeconst gives it without sticking); ``index`` numbers the elements.
    """
    achieved = e_of(at)
    miss = np.abs(achieved - e_t) > 1e-6 * np.maximum(e_t, 1e-3)
    if not miss.any():
        return
    i = np.flatnonzero(miss)[0]
    below, above = e_of(at * (1 - 1e-7))[i], e_of(at * (1 + 1e-7))[i]
    start = f"restitution = {float(e_t[i])!r} (element {int(index[i])}) cannot be reached: "
    hint = "a higher speed, less gravity or another contact_time"
    if any(stuck(at * (1 + step))[i] for step in (1e-7, 1e-5, 1e-3)):
        raise ValueError(
            f"{start}the body starts to stick at {name} = {float(at[i]):.6g}, where the "
            f"restitution is still {max(below, above):.4g}; with more damping it sticks, "
            f"so smaller targets are out of reach here; {hint} reaches them"
        )
    raise ValueError(
        f"{start}at {name} = {float(at[i]):.6g} the restitution jumps from {below:.4g} to "
        f"{above:.4g} (the force no longer vanishes before the penetration does), so "
        f"targets in between are out of reach here; {hint} moves the jump"
    )


def nested_both(e_t, v0, g, t_c, rho, simp, *, index):
    """``(timeconst, dampratio)`` for ``e_t`` and ``t_c`` under gravity (flat), bracketed.

    Nested brackets: for a dampratio the contact time grows with the timeconst (inner
    Illinois solve); the restitution at that timeconst falls with the dampratio (outer
    solve, bracketed on a grid because no timeconst may exist at some dampratios).
    Refusals name the elements by ``index``.
    """

    def inner(dr, idx):
        # timeconst that gives the contact time t_c at this dampratio
        lo = np.full(idx.size, TC_RANGE[0])
        hi = np.full(idx.size, TC_RANGE[1])

        def t_of(tc, j):
            k = idx[j]
            t = flat_restitution(tc, dr[j], simp, rho[k], g[k], v0[k], extremes=False)
            t = t.contact_time
            return np.arctan(np.log(np.where(np.isfinite(t), t, 1e300) / t_c[idx[j]]))

        j_all = np.arange(idx.size)
        ok = (t_of(lo, j_all) < 0) & (t_of(hi, j_all) > 0)
        tc = np.full(idx.size, np.nan)
        if ok.any():
            sel = np.flatnonzero(ok)
            tc[sel] = bracketed_illinois(
                lambda x, j: t_of(x, sel[j]), lo[sel], hi[sel], log=True, rtol=1e-11
            )
            miss = np.abs(t_of(tc[sel], sel)) > 1e-8  # a jump (stick), not a root
            tc[sel[miss]] = np.nan
        return tc

    def residual(dr, idx):
        tc = inner(dr, idx)
        out = np.full(idx.size, -1.0)  # no timeconst gives t_c: treat as too much damping
        good = np.isfinite(tc)
        if good.any():
            j = idx[good]
            e = flat_restitution(tc[good], dr[good], simp, rho[j], g[j], v0[j], extremes=False)
            out[good] = e.restitution - e_t[j]
        return out

    n = e_t.size
    idx = np.arange(n)
    grid = np.geomspace(*DR_RANGE, 21)
    vals = np.stack([residual(np.full(n, q), idx) for q in grid])
    below = vals <= 0
    has = below.any(axis=0)
    first = np.argmax(below, axis=0)
    unreachable(
        "no (timeconst, dampratio) gives both this restitution and this contact time",
        ~has | (first == 0),
        e_t,
        "a longer contact_time or a higher speed reaches it",
        index,
    )
    dr = bracketed_illinois(
        lambda x, i: -residual(x, i), grid[first - 1], grid[first], log=True, rtol=1e-12
    )
    _check_gap(
        lambda x: residual(x, idx) + e_t,
        e_t,
        dr,
        "dampratio",
        lambda x: ~np.isfinite(inner(x, idx)),
        index,
    )
    return inner(dr, idx), dr
