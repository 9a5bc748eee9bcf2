r"""Tables of the pressed impact of a contact law, in (damping number, pressing number).

With a pressing force the normalized impact of a law (:mod:`impactsym.contact.laws`) is a
function of its damping number :math:`\delta` and pressing number ``f`` for each exponent
and condition. Three tables hold it (``docs/nonlinear_contact.md``, "Tables with a
pressing force"), each built once from the exact integration that the caller passes in:

* :func:`build_boundary`: the stick boundary :math:`f^*(\delta)`, as :math:`\ln f^*` in
  :math:`u = \operatorname{asinh}(\delta/0.1)` (a table of one variable,
  :mod:`impactsym.contact.lawtable`), from the sticking verdict
  (:func:`~impactsym.contact.lawonset.stick_onset` to :data:`BOUNDARY_RTOL`);
* :func:`build_ends`: contact time and restitution where the body releases, in ``u`` and
  :math:`\sigma = -\ln(1 - f/F(u))`, ``F`` the boundary table: the boundary is
  :math:`\sigma = \infty`, so no patch straddles it, and the table stops at
  :math:`\sigma = \ln(1/` :data:`GAP` :math:`)`;
* :func:`build_extrema`: maximum penetration and peak force in ``(u, f)`` on both sides
  (they are those of the first compression, smooth across the boundary).

Where the body sticks (``f > F(u)(1 +`` :data:`GAP` ``)``) the contact time is ``inf`` and
the restitution ``0``; inside the band :math:`|f/F - 1| \le` :data:`GAP`, outside the
tables' rectangle, and on patches left out by the build, :func:`pressed_values` says so and
the caller integrates.

Why these coordinates
---------------------
Near the boundary the contact time and restitution are not smooth in ``f``: the orbit
meets ``z = 0`` (position condition) or the zero of the force tangentially, and the end
of contact moves as :math:`\sqrt{f^* - f}` (the restitution falls to 0 like it under the
position condition and jumps to 0 under the force condition). In
:math:`\sigma = -\ln(1 - f/F)` every power :math:`(1 - f/F)^a = e^{-a\sigma}` and
:math:`\ln(1 - f/F) = -\sigma` is smooth, so a branch point at the boundary becomes a
function analytic in a strip around the real :math:`\sigma` axis, and patches of fixed
width converge up to the table's edge :math:`\sigma = \ln 10^4 = 9.2`: no refinement
towards the boundary. The edge is not closer because the exact values themselves lose
accuracy there (:math:`10^{-11}` at :math:`\sigma = 9`, :math:`10^{-10}` at 13, where
``e`` is about :math:`10^{-3}`). The
boundary table's own error :math:`\epsilon = F/f^* - 1` (about :math:`10^{-10}`) moves
the branch point to :math:`\sigma = \ln(1/\epsilon) \pm i\pi`, far from the table. The
ends table breaks where the boundary table does (``roots``), so ``F`` is one polynomial
on each patch.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.contact import lawpatch, lawtable
from impactsym.contact.lawonset import stick_onset

#: Damping numbers tabled with a pressing force (outside: integrated).
DELTA_LOW, DELTA_TOP = 0.01, 2.0
#: Largest pressing number tabled (larger: integrated).
F_TOP = 2.0
#: Relative band around the boundary left to the integration: ``|f/F - 1| <= GAP``.
GAP = 1e-4
#: Chebyshev points per piece of the boundary table (log f* is smooth: few long pieces).
BOUNDARY_NODES = 28
#: Pieces the boundary table starts from (every law needed 4 or more: the coarser levels
#: would cost 40 % of the build for nothing).
BOUNDARY_START = 4
#: Relative width of the bracket of each boundary node.
BOUNDARY_RTOL = 1e-12
#: Smallest f* sought (below: the boundary piece is left out, its elements integrated).
BOUNDARY_FLOOR = 1e-6
#: The variable ``u`` of the tables: :math:`\delta = ` ``SCALE`` :math:`\sinh u`.
SCALE = 0.1
#: Narrowest piece of the boundary table, and patches of the ends table (u, sigma).
MIN_WIDTH_U, MIN_WIDTH_SIGMA = 1e-3, 1e-3
#: Narrowest patches of the extrema table (u, f): a kink of the peak force (where the
#: force at touch stops being the largest) leaves a band this wide to the integration.
EXTREMA_WIDTH = (0.05, 0.025)
#: Most patches of one table (the build stops halving there; the rest is left out).
MAX_PATCHES = 600
#: Acceptance of a patch of the ends table: relative tail and absolute floor (near the
#: boundary the exact contact time and restitution are good to about 1e-11).
ENDS_TAIL, ENDS_FLOOR = 1e-11, 5e-11
#: Patches where a contact time exceeds this are left out.
CAP = 100.0

Exact = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
Verdict = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]

SIGMA_TOP = float(-np.log(GAP))
U_LOW, U_TOP = float(np.arcsinh(DELTA_LOW / SCALE)), float(np.arcsinh(DELTA_TOP / SCALE))


def damping_number(u: np.ndarray) -> np.ndarray:
    """:math:`\\delta` of the tables' variable ``u``.

    >>> round(float(damping_number(np.arcsinh(5.0))), 12)
    0.5
    """
    return SCALE * np.sinh(u)


def build_boundary(sticks: Verdict, exponent: float, *, label: str) -> lawtable.ChebyshevTable:
    r""":math:`\ln f^*` on ``[U_LOW, U_TOP]`` from the verdict ``sticks(delta, f, q)``
    (``-inf`` where the body sticks already at ``f = 0``; pieces where
    :math:`f^* <` :data:`BOUNDARY_FLOOR` are left out)."""

    def log_onset(u: np.ndarray) -> np.ndarray:
        delta = damping_number(u)
        onset = stick_onset(sticks, delta, np.full(u.shape, exponent), floor=BOUNDARY_FLOOR,
                            rtol=BOUNDARY_RTOL, label=label, below_floor=np.nan)  # fmt: skip
        with np.errstate(divide="ignore"):
            return np.log(onset)[None]

    return lawtable.build(log_onset, U_LOW, U_TOP, min_width=MIN_WIDTH_U, nodes=BOUNDARY_NODES,
                          tail=1e-11, floor=1e-11, start=BOUNDARY_START)  # fmt: skip


def boundary_values(boundary: lawtable.ChebyshevTable, u: np.ndarray) -> np.ndarray:
    """``F(u)`` of the boundary table (``nan`` where it is left out, ``0`` where the body
    sticks at ``f = 0``)."""
    (log_f,), _ = boundary(u)
    return np.exp(log_f)


def build_ends(
    exact: Exact, boundary: lawtable.ChebyshevTable, exponent: float
) -> lawpatch.PatchTable:
    r"""Contact time and restitution where the body releases, in ``(u, sigma)``: at
    :math:`f = F(u)(1 - e^{-\sigma})` (module docstring)."""

    def ends(u: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        f = boundary_values(boundary, u) * -np.expm1(-sigma)
        out = np.full((2, u.size), np.nan)
        ok = np.flatnonzero(np.isfinite(f) & (f > 0))
        if ok.size:
            tau, e = exact(damping_number(u[ok]), f[ok], np.full(ok.size, exponent))[:2]
            out[:, ok] = np.where(np.isinf(tau), np.nan, np.stack((tau, e)))  # a stuck node
        return out

    def skip(boxes: np.ndarray) -> np.ndarray:
        """Patches nobody asks for: no release (F = 0, or left out) or every f > F_TOP."""
        u = np.stack((boxes[:, 0], 0.5 * (boxes[:, 0] + boxes[:, 1]), boxes[:, 1]))
        F = boundary_values(boundary, u.ravel()).reshape(u.shape)
        F = np.where(np.isnan(F), 0.0, F)  # nan: a piece of the boundary left out
        lowest = F.min(axis=0) * -np.expm1(-boxes[:, 2])
        return (F.max(axis=0) == 0) | (lowest > F_TOP)

    return lawpatch.build(
        ends, (U_LOW, 0.0), (U_TOP, SIGMA_TOP), min_width=(MIN_WIDTH_U, MIN_WIDTH_SIGMA),
        cap=CAP, skip=skip, roots=boundary.edges[1:-1], tail=ENDS_TAIL, floor=ENDS_FLOOR,
        max_patches=MAX_PATCHES,
    )  # fmt: skip


def build_extrema(exact: Exact, exponent: float) -> lawpatch.PatchTable:
    """Maximum penetration and peak force in ``(u, f)`` on ``[U_LOW, U_TOP] x [0, F_TOP]``."""

    def extrema(u: np.ndarray, f: np.ndarray) -> np.ndarray:
        return np.stack(exact(damping_number(u), f, np.full(u.size, exponent))[2:4])

    return lawpatch.build(extrema, (U_LOW, 0.0), (U_TOP, F_TOP), min_width=EXTREMA_WIDTH,
                          max_patches=MAX_PATCHES)  # fmt: skip


def pressed_values(
    delta: np.ndarray,
    f: np.ndarray,
    *,
    boundary: lawtable.ChebyshevTable,
    ends: lawpatch.PatchTable | None,
    extrema: lawpatch.PatchTable | None,
) -> tuple[np.ndarray, np.ndarray]:
    """(contact time, restitution, maximum penetration, peak force) of flat arrays from the
    tables, shape ``(4, n)`` (``nan`` in rows whose table is ``None``), and where the
    tables answer: inside the rectangle, off the band of the boundary, on covered
    patches."""
    n = delta.size
    values = np.full((4, n), np.nan)
    u = np.arcsinh(delta / SCALE)
    inside = (u >= U_LOW) & (u <= U_TOP) & (f > 0) & (f <= F_TOP)
    F = np.full(n, np.nan)
    F[inside] = boundary_values(boundary, u[inside])
    with np.errstate(divide="ignore", invalid="ignore"):
        s = f / F
    stick = inside & (s > 1.0 + GAP)
    release = inside & (s < 1.0 - GAP)
    inside = stick | release
    if ends is not None:
        values[0, stick], values[1, stick] = np.inf, 0.0
        r = np.flatnonzero(release)
        got, ok = ends(u[r], -np.log1p(-s[r]))
        values[:2, r] = got
        inside[r[~ok]] = False
    if extrema is not None:
        i = np.flatnonzero(inside)
        got, ok = extrema(u[i], f[i])
        values[2:, i] = got
        inside[i[~ok]] = False
    return values, inside
