r"""Equations of motion ``M(q) u' = F(q, u, t)`` in plain symbols, from matrices or from a
``sympy.physics.mechanics`` model (paper section 3, eq. (3)).

Internal: used by :mod:`impactsym.multibody.reduction`, which reduces these equations to
one contact oscillator (``docs/physics.md``, section 3). The user's coordinates and speeds
(plain symbols or ``dynamicsymbols``) are renamed to real dummies so that Jacobians and
substitutions never meet time derivatives.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef

from impactsym.validation import as_sympy_matrix


@dataclass(frozen=True)
class EquationsOfMotion:
    """Equations of motion in plain symbols: ``M(Q) U' = F(Q, U, t)``, ``Q' = qdot(Q, U)``.

    ``rename`` maps the user's ``q``, ``u`` (and, for a model, the rates ``q'`` that are
    speeds) to the dummies ``Q``, ``U``; the reduction maps its results back through it.
    """

    M: sp.Matrix
    F: sp.Matrix
    Q: tuple[sp.Symbol, ...]
    U: tuple[sp.Symbol, ...]
    qdot: sp.Matrix
    rename: dict  # user's q, u (and their derivatives) -> Q, U


def is_mechanics_model(obj: object) -> bool:
    """Whether ``obj`` is a ``KanesMethod``, ``LagrangesMethod`` or mechanics ``System``."""
    return type(obj).__name__ in ("KanesMethod", "System", "LagrangesMethod") and hasattr(obj, "q")


def _dummies(symbols: Sequence[Any], name: str, stem: str) -> tuple[list[sp.Expr], list]:
    items = list(symbols)
    for s in items:
        if not isinstance(s, (sp.Symbol, sp.Derivative, AppliedUndef)):
            raise TypeError(f"{name} must hold symbols or dynamicsymbols, got {s!r}")
    if len(set(items)) != len(items):
        raise ValueError(f"{name} has repeated symbols: {items!r}")
    return items, [sp.Dummy(f"{stem}{i}", real=True) for i in range(len(items))]


def from_matrices(M: Any, F: Any, q: Any, qd: Any) -> EquationsOfMotion:
    """``M q'' = F`` with speeds ``u = q'`` from a mass matrix, forces and the symbols.

    Refuses, naming the argument, shapes that do not match ``q`` and repeated or
    non-symbol coordinates.
    """
    q_items, Q = _dummies(_flat("q", q), "q", "Q")
    u_items, U = _dummies(_flat("qd", qd), "qd", "U")
    n = len(q_items)
    if n == 0:
        raise ValueError("q must hold at least one coordinate")
    if len(u_items) != n:
        raise ValueError(f"qd must have as many entries as q ({n}), got {len(u_items)}")
    Mm = as_sympy_matrix("M", M, finite=True)
    if Mm.shape != (n, n):
        raise ValueError(f"M must be {n} x {n} to match q, got shape {Mm.shape}")
    Fm = as_sympy_matrix("F", F, finite=True)
    if Fm.shape == (1, n) and n > 1:
        raise ValueError(f"F must be a column ({n} x 1), got a row of shape {Fm.shape}")
    if Fm.shape not in ((n, 1), (1, n)):
        raise ValueError(f"F must be {n} x 1 to match q, got shape {Fm.shape}")
    rename = dict(zip(u_items, U, strict=True)) | dict(zip(q_items, Q, strict=True))
    return EquationsOfMotion(
        M=Mm.xreplace(rename),
        F=Fm.reshape(n, 1).xreplace(rename),
        Q=tuple(Q),
        U=tuple(U),
        qdot=sp.Matrix(U),
        rename=rename,
    )


def from_model(model: Any) -> EquationsOfMotion:
    """The mass matrix and forcing of a ``sympy.physics.mechanics`` model.

    Kinematic differential equations ``q' = f(q, u)`` of a ``KanesMethod`` are kept in
    ``qdot``; constrained models (dependent coordinates or speeds) are refused.
    """
    kind = type(model).__name__
    if kind == "System":
        method = model.eom_method
        if method is None:
            raise ValueError("the System has no equations of motion yet; call form_eoms() first")
        if len(model.q_dep) or len(model.u_dep):
            raise ValueError(
                "models with dependent coordinates or speeds (constraints) are not supported"
            )
        return from_model(method)
    try:
        M, F = model.mass_matrix, model.forcing
    except (AttributeError, ValueError) as exc:
        raise ValueError(
            f"the {kind} has no equations of motion yet; call "
            f"{'kanes_equations' if kind == 'KanesMethod' else 'form_lagranges_equations'}() "
            "first"
        ) from exc
    from sympy.physics.vector import dynamicsymbols

    t = dynamicsymbols._t
    q = list(model.q)
    if kind == "LagrangesMethod":
        speeds = [qi.diff(t) for qi in q]
        kin: dict = {}
    else:
        speeds = list(model.u)
        kin = dict(model.kindiffdict())
        if M.shape[0] != len(speeds):
            raise ValueError(
                "models with dependent speeds (nonholonomic constraints) are not supported"
            )
    q_items, Q = _dummies(q, "model.q", "Q")
    u_items, U = _dummies(speeds, "model.u", "U")
    rename = dict(zip(u_items, U, strict=True)) | dict(zip(q_items, Q, strict=True))
    # where a speed is a coordinate rate (u = q'), the impact state may also give q'
    rename |= {rate: rename[u] for rate, u in kin.items() if u in rename}
    qdot = sp.Matrix([kin[qi.diff(t)] for qi in q_items]) if kin else sp.Matrix(u_items)
    return EquationsOfMotion(
        M=sp.Matrix(M).xreplace(kin).xreplace(rename),
        F=sp.Matrix(F).xreplace(kin).xreplace(rename),
        Q=tuple(Q),
        U=tuple(U),
        qdot=qdot.xreplace(rename),
        rename=rename,
    )


def _flat(name: str, value: Any) -> list:
    if isinstance(value, sp.MatrixBase):
        return list(value)
    if isinstance(value, (sp.Basic, str, bytes)) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name} must be a sequence of symbols, got {value!r}")
    return list(np.asarray(value, dtype=object).ravel())
