r"""Continuous ``solref`` designs for a varying ``solimp``: Newton on the Runge-Kutta contact.

With a varying impedance the continuous contact (:func:`~.continuous.varying_phase`) has
no closed form, so a design solves ``restitution = e`` (and ``log(contact_time / t_c) =
0``) by :func:`impactsym.numeric.roots.newton_system` in the logarithms of the unknowns
(the dampratio; with a contact time the timeconst too), each element stopping at its own
convergence (``|residual| < 1e-9``). The start is the flat design at ``d_max``, exact
for a flat ``solimp``, which the caller supplies.

**Many targets of one contact** (at least ``_MIN_GROUP`` sharing speed, gravity, weight
ratio and contact time; only the restitution differs) start instead from a table of
their own designs: ``_nodes(count)`` restitutions evenly spaced over the group's range
are designed first (Newton from the flat design, as above), and each target starts from
the cubic through the four node designs around it (in ``log`` of the unknowns). The
design is a smooth function of the restitution except where the contact changes kind
(where its end moves across the impedance's width), so a start there is only good to
``h^4`` of the node spacing ``h``: at 256 nodes over ``e = 0.3 .. 0.9`` (1 m/s, gravity
9.81, default ``solimp``) the median start is off by ``5e-10`` in ``log dampratio`` and
the worst by ``2e-7``. Most targets are then converged at the first evaluation, the
others take one or two Newton steps; every design is still accepted by its own
evaluation at ``|residual| < 1e-9``, as from the flat start (a design left above
``1e-6`` after 12 Newton steps is refused). A stencil whose node
designs are not smooth (a fourth difference above ``_SMOOTH`` in the logarithms: a jump
between branches of solutions) is not interpolated; its targets start from the flat
design. A group whose nodes are not all designed (a node target no ``solref`` reaches,
in a gap of the restitution between reachable targets) starts from the flat design
too, so a call designs and refuses what it would without the table, and names the
same target.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.engines.mujoco.continuous import varying_phase
from impactsym.engines.mujoco.flat_brackets import unreachable
from impactsym.engines.mujoco.model import coefficients
from impactsym.numeric.poly import cubic_lagrange
from impactsym.numeric.roots import newton_system

__all__ = ["design_varying"]

_TOL = 1e-9  # |residual| at which a design is accepted (restitution; log contact time)
_MIN_GROUP = 512  # targets of one contact from which their designs start from a table
_MAX_NODES = 256  # node designs of a table (fewer for smaller groups: _nodes)
_SMOOTH = 1e-3  # largest fourth difference (log units) of node designs interpolated

#: ``flat_start(e, v0, g, t_c, rho) -> (timeconst, dampratio)``: the flat designs
FlatStart = Callable[..., tuple[np.ndarray, np.ndarray]]


def design_varying(
    e_t: np.ndarray,
    v0: np.ndarray,
    g: np.ndarray,
    t_c: np.ndarray | None,
    tc0: float,
    simp: tuple[float, ...],
    rho: np.ndarray,
    flat_start: FlatStart,
) -> tuple[np.ndarray, np.ndarray]:
    """``(timeconst, dampratio)`` of the continuous designs, flat arrays (module docstring).

    ``tc0`` is the timeconst kept without a ``t_c``; ``flat_start`` gives the flat
    designs at ``d_max`` of given targets. Raises ``ValueError`` naming the first target
    the Newton iteration cannot reach.
    """
    both = t_c is not None
    u0 = np.full((2 if both else 1, e_t.size), np.nan)
    for members in _groups(v0, g, rho, t_c):
        start = _table_start(e_t, v0, g, t_c, tc0, simp, rho, flat_start, members)
        if start is not None:
            u0[:, members] = start
    rest = np.flatnonzero(np.isnan(u0[0]))
    if rest.size:
        tc, dr = flat_start(
            e_t[rest], v0[rest], g[rest], None if t_c is None else t_c[rest], rho[rest]
        )
        u0[:, rest] = np.stack([np.log(tc), np.log(dr)]) if both else np.log(dr)[None]
    u, r = _solve(e_t, v0, g, t_c, tc0, simp, rho, u0)
    _unreachable_left(r, e_t)
    return (np.exp(u[0]) if both else np.full(e_t.size, tc0)), np.exp(u[-1])


def _solve(e_t, v0, g, t_c, tc0, simp, rho, u0):
    """Newton from ``u0`` (``log`` unknowns ``(k, n)``): ``(u, residual)``; a singular
    Jacobian is refused, naming why (:func:`_no_slope`)."""
    both = t_c is not None

    def residual(u, i):
        tc = np.exp(u[0]) if both else np.full(i.size, tc0)
        phase = varying_phase(
            coefficients((tc, np.exp(u[-1])), simp, None), simp, rho[i], g[i], v0[i]
        )
        r = [phase.restitution - e_t[i]]
        if both:
            t = phase.contact_time
            r.append(np.log(np.where(np.isfinite(t), t, 1e300) / t_c[i]))
        return np.stack(r)

    try:
        return newton_system(
            residual, u0, eps=1e-6, max_step=0.5, tol=_TOL, max_iter=12, shrink=True
        )
    except np.linalg.LinAlgError:  # a residual flat in some unknown: no Newton step
        _no_slope(residual(u0, np.arange(e_t.size)), e_t, t_c, tc0, u0)
        raise  # pragma: no cover - _no_slope always raises


def _unreachable_left(r, e_t) -> None:
    """Refuse the designs Newton left above ``1e-6`` after its 12 iterations (the others
    are at ``_TOL``, or between: a slow convergence near a kink, accepted as before)."""
    unreachable(
        "the varying-impedance design did not converge",
        ~np.all(np.abs(r) < 1e-6, axis=0),
        e_t,
        "try flat impedance (solimp[0] == solimp[1]) or a nearby target",
    )


def _groups(v0, g, rho, t_c):
    """Index arrays of the elements sharing one contact, for groups of ``_MIN_GROUP`` or more."""
    if v0.size < _MIN_GROUP:
        return []
    columns = [v0, g, rho] + ([] if t_c is None else [t_c])
    _, label, counts = np.unique(
        np.stack(columns, axis=1), axis=0, return_inverse=True, return_counts=True
    )
    label = label.ravel()
    big = np.flatnonzero(counts >= _MIN_GROUP)
    return [np.flatnonzero(label == k) for k in big]


def _nodes(count: int) -> int:
    """Node designs of a table for ``count`` targets: at most a quarter of them (each
    costs about five evaluations of the contact, a target started off a table of 256
    nodes mostly one)."""
    return int(np.clip(count // 4, 16, _MAX_NODES))


def _table_start(e_t, v0, g, t_c, tc0, simp, rho, flat_start, members):
    """The starts ``(k, members)`` of a group read off its table of node designs (``nan``
    columns: start from the flat design), or ``None`` where a node was not designed."""
    e = e_t[members]
    e_n = np.linspace(e.min(), e.max(), _nodes(members.size))
    if not np.all(np.diff(e_n) > 0):  # the targets span a few ulps at most: one node
        e_n = e_n[:1]
    m = e_n.size
    i0 = members[:1].repeat(m)  # the group's contact, m times
    t_n = None if t_c is None else t_c[i0]
    both = t_c is not None
    try:  # a node no design reaches (between reachable targets): no table
        tc, dr = flat_start(e_n, v0[i0], g[i0], t_n, rho[i0])
        u0 = np.stack([np.log(tc), np.log(dr)]) if both else np.log(dr)[None]
        u_n, r = _solve(e_n, v0[i0], g[i0], t_n, tc0, simp, rho[i0], u0)
    except ValueError:
        return None
    if not np.all(np.abs(r) < _TOL):
        return None
    if m == 1:
        return np.repeat(u_n, members.size, axis=1)
    return _interpolate(e_n, u_n, e)


def _interpolate(e_n, u_n, e):
    """The cubic through the four node designs around each target (``nan`` where a
    five-point stencil around them has a fourth difference above ``_SMOOTH``)."""
    out, first = cubic_lagrange(e_n, u_n, e)
    d4 = np.abs(u_n[:, :-4] - 4 * u_n[:, 1:-3] + 6 * u_n[:, 2:-2] - 4 * u_n[:, 3:-1] + u_n[:, 4:])
    d4 = np.max(d4, axis=0)  # per window k .. k + 4
    rough = np.zeros(e.size, bool)
    for k in (first - 1, first):  # the windows holding the nodes first .. first + 3
        ok = (k >= 0) & (k < d4.size)
        rough[ok] |= d4[k[ok]] > _SMOOTH
    out[:, rough] = np.nan
    return out


def _no_slope(r0, e_t, t_c, tc0, u0) -> None:
    """Refuse a varying-impedance design whose Newton Jacobian is singular, saying why."""
    stuck = (r0[0] == -e_t) | (~np.isfinite(r0[-1]) if t_c is not None else False)
    if t_c is not None:
        stuck |= r0[-1] >= np.log(1e300 / t_c) - 1.0  # contact time inf: sticks
    i = int(np.flatnonzero(stuck)[0]) if stuck.any() else 0
    wanted = f"restitution = {float(e_t[i])!r}" + (
        "" if t_c is None else f" with contact_time = {float(t_c[i])!r} s"
    )
    tc = np.exp(u0[0, i]) if t_c is not None else tc0
    start = f"({float(tc):.6g}, {float(np.exp(u0[-1, i])):.6g})"
    why = (
        f"at the design's start solref = {start} the body sticks under the "
        f"varying impedance, so restitution and contact time do not change with solref"
        if stuck.any()
        else f"near the design's start solref = {start} the restitution or contact time "
        f"does not change with solref (singular Newton system)"
    )
    raise ValueError(
        f"{wanted} (element {i}): the varying-impedance design cannot proceed: {why}; "
        f"a higher speed, less gravity, another contact_time or a flat solimp "
        f"(solimp[0] == solimp[1]) avoids this"
    )
