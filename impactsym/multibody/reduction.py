r"""Reduction of a multibody penalty contact to one scalar contact oscillator (paper section 3).

A multibody system ``M(q) u' = F(q, u, t) + w(q) lambda`` hits an obstacle through the
penalty law ``lambda = -k z - d z'`` on the penetration ``z = g(q)`` (eqs. (3), (4)).
Pre-multiplying by ``w^T M^-1``, freezing ``M``, ``w`` and the curvature of ``g`` at the
impact state and linearizing ``F`` along a projection ``P`` of the normal motion gives the
section-2 oscillator

.. math::

    \tilde m \ddot z + \tilde d \dot z + \tilde c z = F_n, \qquad
    \tilde m = \frac{1}{w^T M^{-1} w}, \quad
    \tilde d = d - \tilde m\, r^T \frac{\partial F}{\partial u} P, \quad
    \tilde c = k - \tilde m\, r^T \frac{\partial F}{\partial q} p,

with ``r = M^-1 w`` and the load ``F_n = m~ (r^T F_0 + kappa_0) + (d~ - d) v0`` (the
toolkit's corrected eq. (5)). The derivation, the choice of the impulse projection
``P = m~ M^-1 w`` over the paper's ``n0 / (n0^T n0)`` and the checks are in
``docs/physics.md``, section 3 and "Where the toolkit departs from the print".

The result object :class:`~impactsym.multibody.oscillator.ReducedContact` lives in
:mod:`impactsym.multibody.oscillator` and is importable from here too.
"""

from __future__ import annotations

import functools
import numbers
from collections.abc import Mapping, Sequence
from typing import Any, overload

import numpy as np
import sympy as sp

from impactsym.multibody.drift import derive_drift
from impactsym.multibody.equations import (
    EquationsOfMotion,
    from_matrices,
    from_model,
    is_mechanics_model,
)
from impactsym.multibody.oscillator import ReducedContact, penalty_parameter, to_scalar
from impactsym.validation import (
    as_sympy,
    as_sympy_matrix,
    broadcast,
    real_array,
    reject_strings,
)

# ReducedContact is re-exported (``impactsym.multibody.reduction.ReducedContact``) and
# documented in impactsym.multibody.oscillator.
__all__ = ["PROJECTIONS", "latex_formulas", "reduce_contact", "typeset_formulas"]

#: Projections of the normal motion onto the coordinates, see :func:`reduce_contact`.
PROJECTIONS = ("impulse", "normal")


@overload
def reduce_contact(
    M: Any,
    F: Any,
    g: Any,
    q: Sequence[Any],
    qd: Sequence[Any],
    at: Mapping[Any, Any],
    k: Any,
    d: Any,
    /,
    *,
    projection: str = ...,
    gap_tol: float = ...,
    simplify: bool = ...,
) -> ReducedContact: ...


@overload
def reduce_contact(
    model: Any,
    g: Any,
    at: Mapping[Any, Any],
    k: Any,
    d: Any,
    /,
    *,
    projection: str = ...,
    gap_tol: float = ...,
    simplify: bool = ...,
) -> ReducedContact: ...


def reduce_contact(
    *args: Any,
    k: Any = None,
    d: Any = None,
    projection: str = "impulse",
    gap_tol: float = 1e-9,
    simplify: bool = True,
) -> ReducedContact:
    r"""Reduce a multibody penalty contact to the scalar oscillator of paper section 2.

    Called as ``reduce_contact(M, F, g, q, qd, at, k, d)`` or, for a model built with
    ``sympy.physics.mechanics``, as ``reduce_contact(model, g, at, k, d)``.

    Parameters
    ----------
    M
        ``n x n`` mass matrix: a SymPy matrix in ``q`` (and parameters) or a numeric
        array. Symmetric and positive definite at the impact state.
    F
        ``n x 1`` generalized forces in ``q``, ``qd`` and time (SymPy or numeric),
        without the contact force.
    g
        Penetration ``g(q)`` (positive when penetrating, zero at impact) as a SymPy
        expression, or a numeric normal ``n0`` (length ``n``) for the linear gap
        ``g = n0^T (q - q0)``.
    q, qd
        Coordinate and velocity symbols (plain symbols or ``dynamicsymbols``).
    model
        A ``KanesMethod`` (after ``kanes_equations``), a ``System`` (after
        ``form_eoms``) or a ``LagrangesMethod`` (after ``form_lagranges_equations``).
        Its mass matrix and forcing are used; ``at`` then gives the generalized
        speeds ``u``.
    at
        The impact state (values of ``q`` and ``qd`` or ``u``) and any parameter
        values, as a dict. Symbols left out stay symbolic in the result.
    k, d
        Penalty stiffness (``> 0``) and damping (``>= 0``): numbers, NumPy arrays
        (vectorized) or SymPy expressions.
    projection
        ``"impulse"`` (default): configuration and velocity change along ``M^-1 n0``,
        the direction a contact impulse moves the system. ``"normal"``: along ``n0``,
        ``n0 z / (n0^T n0)`` as in the paper (not unit-consistent; for comparison).
    gap_tol
        Admissible ``|g(q0)|`` (in the units of ``g``) for a numeric impact state.
    simplify
        Simplify symbolic results.

    Returns
    -------
    ReducedContact
        With ``m_eff, d_eff, c_eff, load, v0, D, f, omega0`` and the section-2
        methods ``contact_time``, ``sticks``, ``restitution``.

    Notes
    -----
    With ``r = M0^{-1} n0``, the speed projection ``P`` and the configuration
    projection ``p`` (both with ``n0^T P = n0^T p = 1``):

    .. math::

        \tilde m = \frac{1}{n_0^T M_0^{-1} n_0}, \quad
        \tilde d = d - \tilde m\, r^T F_{,\dot q}\, P, \quad
        \tilde c = k - \tilde m\, r^T F_{,q}\, p, \quad
        F_n = \tilde m\,(r^T F_0 + \dot q_0^T H \dot q_0) + (\tilde d - d) v_0,

    ``H`` the Hessian of ``g`` (the paper's eq. (5), corrected). Impulse projection:
    ``P = p = m~ M0^{-1} n0``; paper projection: ``P = p = n0 / (n0^T n0)``. The
    linearization point is the impact state ``(q0, q0', t0)``, with ``v0 > 0`` at impact.
    Why the impulse projection, the choices where the paper is silent and the checks: See
    `docs/physics.md#multibody-reduction`.

    Examples
    --------
    A bar (mass ``m``, length ``L``) falling on its end at angle ``theta`` has the
    effective mass ``m / (1 + 3 cos^2 theta)``:

    >>> m, L, grav = sp.symbols("m L g", positive=True)
    >>> x, y, th, vx, vy, om = sp.symbols("x y theta v_x v_y omega")
    >>> M = sp.diag(m, m, m * L**2 / 12)
    >>> F = sp.Matrix([0, -m * grav, 0])
    >>> g = L / 2 * sp.sin(th) - y
    >>> at = {x: 0, y: L / 4, th: sp.pi / 6, vx: 0, vy: -1, om: 0}
    >>> r = reduce_contact(M, F, g, [x, y, th], [vx, vy, om], at, 1000, 10)
    >>> r.m_eff
    4*m/13
    >>> r.load, r.v0
    (4*g*m/13, 1.0)
    """
    if projection not in PROJECTIONS:
        raise ValueError(f"projection must be one of {PROJECTIONS}, got {projection!r}")
    tol, _ = real_array("gap_tol", gap_tol, lower=0.0)
    if (k is None) != (d is None):
        raise TypeError("give both penalty parameters k and d as keywords, or neither")
    if k is not None:  # reduce_contact(..., at, k=..., d=...)
        args = (*args, k, d)
    if args and is_mechanics_model(args[0]):
        if len(args) != 5:
            raise TypeError(
                f"reduce_contact(model, g, at, k, d) takes 5 arguments, got {len(args)}"
            )
        model, g, at, k, d = args
        system = from_model(model)
    else:
        if len(args) != 8:
            raise TypeError(
                "reduce_contact takes (M, F, g, q, qd, at, k, d) or (model, g, at, k, d); "
                f"got {len(args)} positional arguments"
            )
        M, F, g, q, qd, at, k, d = args
        system = from_matrices(M, F, q, qd)
    if not isinstance(at, Mapping):
        raise TypeError(f"at must be a dict of the impact state, got {at!r}")
    k_val = penalty_parameter("k", k, strict=True)
    d_val = penalty_parameter("d", d, strict=False)
    if not any(isinstance(v, sp.Basic) for v in (k_val, d_val)):
        broadcast(k=k_val, d=d_val)
    parts = _reduce(system, g, at, projection, float(tol), simplify)
    return ReducedContact(
        m_eff=parts["m_eff"],
        delta_d=parts["delta_d"],
        delta_c=parts["delta_c"],
        load=parts["load"],
        v0=parts["v0"],
        k=k_val,
        d=d_val,
        projection=projection,
        normal=parts["normal"],
        direction=parts["direction"],
        drift_source=parts["drift"],
    )


def _map_state(system: EquationsOfMotion, at: Mapping[Any, Any]) -> dict:
    reject_strings("at", at)
    state = {}
    for key, value in at.items():
        val = as_sympy(f"at[{key}]", value, finite=True)
        if isinstance(value, numbers.Real) and not isinstance(value, numbers.Rational):
            val = sp.Float(float(value))
        state[system.rename.get(key, key)] = val
    return state


def _reduce(
    system: EquationsOfMotion,
    g: Any,
    at: Mapping[Any, Any],
    projection: str,
    tol: float,
    simplify: bool,
) -> dict[str, Any]:
    Q, U = sp.Matrix(system.Q), sp.Matrix(system.U)
    n = len(Q)
    state = _map_state(system, at)
    reject_strings("g", g)
    if isinstance(g, sp.Basic) and not isinstance(g, sp.MatrixBase):
        gx = as_sympy("g", g, finite=True).xreplace(system.rename)
        if isinstance(gx, sp.MatrixBase) or not gx.is_commutative:
            raise TypeError(f"g must be a scalar expression, got {g!r}")
        n_q = sp.Matrix([gx]).jacobian(Q).T
        g0 = gx.xreplace(state)
        _check_gap(g0, system, tol)
    else:
        n_q = as_sympy_matrix("g", g, finite=True)
        if n_q.shape not in ((n, 1), (1, n)):
            raise ValueError(f"a numeric normal g must have {n} entries, got shape {n_q.shape}")
        n_q = n_q.reshape(n, 1)
    zdot = (n_q.T * system.qdot)[0]
    w = sp.Matrix([zdot]).jacobian(U).T
    kappa = (sp.Matrix([zdot]).jacobian(Q) * system.qdot)[0]
    times = [s for s in zdot.free_symbols if getattr(s, "name", None) == "t"]
    kappa += sum((zdot.diff(s) for s in times), sp.S.Zero)
    A = system.qdot.jacobian(U)

    def at0(expr: Any) -> Any:
        return expr.xreplace(state)

    M0, w0, F0 = at0(system.M), at0(w), at0(system.F)
    if all(x == 0 for x in w0):
        raise ValueError("the contact normal n0 = dg/dq vanishes at the impact state (g)")
    _check_mass(M0)
    try:
        r = M0.LUsolve(w0)
    except (ValueError, ZeroDivisionError) as exc:
        raise ValueError("the mass matrix M is singular at the impact state") from exc
    inv_m = (w0.T * r)[0]
    if inv_m.is_number and not float(inv_m) > 0:
        raise ValueError(
            f"n0^T M^-1 n0 = {float(inv_m)!r} is not positive: M is not positive definite (M)"
        )
    m_eff = 1 / inv_m
    if projection == "impulse":
        P_u = r * m_eff
        P_q = at0(A) * P_u
    else:
        P_u = w0 / (w0.T * w0)[0]
        nq0 = at0(n_q)
        P_q = nq0 / (nq0.T * nq0)[0]
    F_q = at0(system.F.jacobian(Q))
    F_u = at0(system.F.jacobian(U))
    delta_c = -m_eff * (r.T * F_q * P_q)[0]
    delta_d = -m_eff * (r.T * F_u * P_u)[0]
    v0 = at0(zdot)
    load = m_eff * ((r.T * F0)[0] + at0(kappa)) + delta_d * v0
    back = {v: k_ for k_, v in system.rename.items()}
    out = {
        "m_eff": m_eff,
        "delta_d": delta_d,
        "delta_c": delta_c,
        "load": load,
        "v0": v0,
    }
    for key, value in out.items():
        value = value.xreplace(back)
        if simplify and not value.is_number:
            value = sp.simplify(value)
        out[key] = to_scalar(value)
    # how M, w, F and the curvature move on during the contact: derived on first use
    # (ReducedContact.drift), so reductions that never ask pay nothing
    out["drift"] = functools.partial(
        derive_drift,
        M=system.M,
        F=system.F,
        w=w,
        kappa=kappa,
        kinematics=A,
        Q=Q,
        U=U,
        state=state,
        r=r,
        P_u=P_u,
        P_q=P_q,
        v0=v0,
    )
    out["normal"] = _vector(w0.xreplace(back))
    out["direction"] = _vector(P_u.xreplace(back))
    if isinstance(out["v0"], float) and not out["v0"] > 0:
        raise ValueError(
            f"the normal approach speed v0 = n0^T q0' = {out['v0']!r} must be > 0 for an "
            "impact (at)"
        )
    return out


def _check_gap(g0: sp.Expr, system: EquationsOfMotion, tol: float) -> None:
    if g0.is_number:
        value = complex(g0)
        if abs(value.imag) > 0 or abs(value.real) > tol:
            raise ValueError(
                f"g must vanish at the impact state (|g(q0)| <= gap_tol = {tol:g}), "
                f"got g(q0) = {value.real!r}"
            )
        return
    if g0.free_symbols & set(system.Q):
        return  # the configuration is left general: the caller keeps g(q0) = 0
    if g0.equals(0) is False:
        raise ValueError(f"g must vanish at the impact state, got g(q0) = {g0}")


def _check_mass(M0: sp.Matrix) -> None:
    if M0.is_symbolic():
        if not (M0 - M0.T).equals(sp.zeros(*M0.shape)):
            asym = sp.simplify(M0 - M0.T)
            if not asym.is_zero_matrix:
                raise ValueError("the mass matrix M must be symmetric")
        return
    values = np.array(M0.evalf(), dtype=float)
    scale = np.max(np.abs(values))
    if not np.all(np.isfinite(values)):
        raise ValueError("the mass matrix M must be finite at the impact state")
    if scale == 0 or not np.allclose(values, values.T, rtol=1e-10, atol=1e-12 * scale):
        raise ValueError(f"the mass matrix M must be symmetric and nonzero, got {values.tolist()}")
    eig = np.linalg.eigvalsh(values)
    if eig[0] <= 1e-12 * scale:
        raise ValueError(
            f"the mass matrix M must be positive definite (not singular) at the impact state; "
            f"its smallest eigenvalue is {eig[0]:.3g}"
        )


def _vector(column: sp.Matrix) -> sp.Matrix | np.ndarray:
    if all(x.is_number for x in column):
        return np.array([float(x) for x in column.evalf()])
    return column


# ---------------------------------------------------------------------------------
# formulas for the LaTeX report
# ---------------------------------------------------------------------------------
def typeset_formulas() -> list[tuple[str, str, str]]:
    r"""The penalty contact, its reduction and the parameters as ``(label, sentence, body)``.

    The bodies are written by hand: the reduction is a statement about matrices, not one
    expression (:func:`reduce_contact` computes it).

    >>> [label for label, _, _ in typeset_formulas()][:2]
    ['mb-penalty', 'mb-reduced']
    """
    return [
        (
            "mb-penalty",
            "A multibody system in penalty contact (the paper's eqs. (3), (4)): the penalty "
            "law acts on the penetration $z$, linearized about the impact configuration $q_0$.",
            r"M \ddot q = F(q, \dot q, t) + n\,\lambda, \qquad \lambda = -d\,\dot z - k\,z, "
            r"\qquad z = g(q) \approx n_0^{T}(q - q_0)",
        ),
        (
            "mb-reduced",
            "During the short impact the system reduces to one contact oscillator along the "
            "contact normal, the oscillator of paper section 2.",
            r"\tilde m\,\ddot z + \tilde d\,\dot z + \tilde c\, z = F_n, \qquad "
            r"z = g(q),\quad \dot z = n_0^{T}\dot q, \quad z(0) = 0,\ \dot z(0) = v_0 = "
            r"n_0^{T}\dot q_0",
        ),
        (
            "mb-mass",
            "The effective mass is the mass the contact normal sees (paper eq. (5)).",
            r"\tilde m = \frac{1}{n_0^{T} M_0^{-1} n_0}, \qquad "
            r"n_0 = \left.\frac{\partial g}{\partial q}\right|_{q_0}^{T}, \qquad "
            r"r = M_0^{-1} n_0",
        ),
        (
            "mb-damping-stiffness",
            "Effective damping and stiffness (paper eq. (5), corrected): the penalty "
            "parameters plus the linearized system forces along the projection $P$ of the "
            "normal motion ($n_0^T P = 1$).",
            r"\tilde d = d - \tilde m\, r^{T} \frac{\partial F}{\partial \dot q} P, \qquad "
            r"\tilde c = k - \tilde m\, r^{T} \frac{\partial F}{\partial q} P",
        ),
        (
            "mb-load",
            "The load pressing into the contact (paper eq. (5), corrected): the intercept of "
            "the linearization, with the curvature term of $g$.",
            r"F_n = \tilde m\left(r^{T} F_0 + \dot q_0^{T} \frac{\partial^2 g}{\partial q^2}"
            r"\dot q_0\right) + (\tilde d - d)\, v_0",
        ),
        (
            "mb-projections",
            "Projections of the normal motion: the direction an impulse moves the system "
            "(used), and the paper's normal direction (not unit-consistent).",
            r"P_{\mathrm{impulse}} = \tilde m\, M_0^{-1} n_0, \qquad "
            r"P_{\mathrm{paper}} = \frac{n_0}{n_0^{T} n_0}",
        ),
        (
            "mb-normalization",
            "The reduced oscillator in the variables of paper section 2: its contact time "
            "and stick/release verdict follow from section 2.",
            r"\omega_0 = \sqrt{\tilde c/\tilde m}, \quad "
            r"D = \frac{\tilde d}{2\sqrt{\tilde c\,\tilde m}}, \quad "
            r"f = \frac{F_n}{\tilde d\, v_0}, \quad t_c = \frac{\tau_c(D, f)}{\omega_0}",
        ),
    ]


def latex_formulas() -> list[tuple[str, str, str]]:
    r"""The reduced contact equation and its parameters as ``(label, caption, body)``.

    Bodies are amsmath math for ``\[ ... \]`` (see :func:`typeset_formulas`).

    >>> [label for label, _, _ in latex_formulas()][1:3]
    ['mb-reduced', 'mb-mass']
    """
    return typeset_formulas()
