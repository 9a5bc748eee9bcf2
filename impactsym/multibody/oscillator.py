r"""The reduced contact oscillator ``m~ z'' + d~ z' + c~ z = F_n`` of a multibody penalty
contact and its section-2 verdicts (paper sections 2 and 3).

:class:`ReducedContact` is the result of :func:`impactsym.multibody.reduce_contact`: the
effective mass, damping, stiffness and load of the normal motion
(``docs/physics.md``, section 3) and, through :func:`impactsym.contact.physical_contact`,
its contact time, restitution and stick/release verdict (section 2). Only ``d~ = d +
delta_d`` and ``c~ = k + delta_c`` depend on the penalty ``k, d``, so the object keeps
``delta_d``, ``delta_c`` and sweeps ``(k, d)`` without a new reduction.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import sympy as sp

from impactsym.records import ArrayRecord
from impactsym.validation import (
    as_sympy,
    as_sympy_matrix,
    broadcast,
    check_condition,
    real_array,
    reject_strings,
)

__all__ = ["ReducedContact"]

Scalar = Any  # a float, a NumPy array (vectorized k, d) or a SymPy expression


@dataclass(frozen=True, eq=False)
class ReducedContact(ArrayRecord):
    """The scalar contact oscillator ``m~ z'' + d~ z' + c~ z = F_n`` of a multibody contact.

    Built by :func:`~impactsym.multibody.reduction.reduce_contact`. Attributes are
    Python floats for numeric input, NumPy arrays where ``k`` or ``d`` are arrays, and
    SymPy expressions when symbols remain; :meth:`subs` turns a symbolic reduction into a
    numeric one.

    Attributes
    ----------
    m_eff
        Effective mass ``m~ = 1 / (n0^T M^-1 n0)``.
    d_eff, c_eff
        Effective damping and stiffness (penalty ``d``, ``k`` plus the linearized forces).
    load
        The force ``F_n`` pressing the body into the contact (positive = pressing).
    v0
        Normal approach speed ``n0^T q0'`` (positive for an impact).
    k, d
        The penalty parameters.
    delta_d, delta_c
        ``d~ - d`` and ``c~ - k``: what the system's own forces add; independent of
        ``k`` and ``d``.
    projection
        ``"impulse"`` or ``"normal"``.
    normal
        The normal ``w = n0`` in speed space at the impact state (a NumPy vector, or a
        SymPy column when symbolic).
    direction
        The speed projection ``P`` (``n0^T P = 1``), as ``normal``.
    drift_source
        Derives :attr:`drift` on first use (set by ``reduce_contact``; not compared).
    """

    m_eff: Scalar
    delta_d: Scalar
    delta_c: Scalar
    load: Scalar
    v0: Scalar
    k: Scalar
    d: Scalar
    projection: str
    normal: Any = field(repr=False)
    direction: Any = field(repr=False)
    drift_source: Any = field(default=None, repr=False, compare=False)

    @functools.cached_property
    def drift(self) -> Any:
        """The first-order drift of ``1/m~``, the pressing forces and the curvature during
        the contact (:class:`impactsym.multibody.drift.ContactDrift`), derived on first
        use; ``None`` for a symbolic reduction or one built without ``reduce_contact``."""
        return None if self.drift_source is None else self.drift_source()

    # -- derived quantities --------------------------------------------------------
    @property
    def d_eff(self) -> Scalar:
        """Effective damping ``d~ = d + delta_d``."""
        return self.d + self.delta_d

    @property
    def c_eff(self) -> Scalar:
        """Effective stiffness ``c~ = k + delta_c``."""
        return self.k + self.delta_c

    @property
    def omega0(self) -> Scalar:
        """Angular eigenfrequency ``sqrt(c~ / m~)`` of the undamped reduced oscillator."""
        return _sqrt(self.c_eff / self.m_eff)

    @property
    def D(self) -> Scalar:
        """Lehr's damping ratio ``D = d~ / (2 sqrt(c~ m~))`` (paper section 2)."""
        return self.d_eff / (2 * _sqrt(self.c_eff * self.m_eff))

    @property
    def f(self) -> Scalar:
        """Normalized pressing force ``f = F_n / (d~ v0)`` (``inf`` for ``d~ = 0``)."""
        if self.is_symbolic:
            return self.load / (self.d_eff * self.v0)
        with np.errstate(divide="ignore", invalid="ignore"):
            value = np.asarray(self.load) / (np.asarray(self.d_eff) * self.v0)
        value = np.where(np.asarray(self.load) == 0, 0.0, value)
        return _numeric(value)

    @property
    def is_symbolic(self) -> bool:
        """Whether symbols remain in the attributes."""
        return any(
            isinstance(v, sp.Basic) and not v.is_number
            for v in (self.m_eff, self.delta_d, self.delta_c, self.load, self.v0, self.k, self.d)
        )

    @property
    def equation(self) -> sp.Eq:
        """The reduced equation ``m~ z'' + d~ z' + c~ z = F_n`` with ``z(t)``."""
        t = sp.Symbol("t", real=True)
        z = sp.Function("z")(t)
        m, dd, c, load = (
            as_sympy(name, getattr(self, name)) for name in ("m_eff", "d_eff", "c_eff", "load")
        )
        return sp.Eq(m * z.diff(t, 2) + dd * z.diff(t) + c * z, load)

    def latex(self, name: str, *, condition: str | None = None) -> str:
        """LaTeX of ``equation`` or of one of ``m_eff``, ``d_eff``, ``c_eff``, ``load``, ``v0``.

        ``condition`` is accepted for the common interface of the derivation objects;
        none of these depends on it, so it must be ``None``.

        >>> m, k = sp.symbols("m k", positive=True)
        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[m]]), sp.Matrix([0]), x, [x], [v], {x: 0, v: 1}, k, 0)
        >>> r.latex("m_eff")
        'm'
        """
        if condition is not None:
            raise ValueError(
                f"no reduced quantity depends on the contact condition, got {condition!r}"
            )
        names = ("equation", "m_eff", "d_eff", "c_eff", "load", "v0")
        if not isinstance(name, str) or name not in names:
            raise ValueError(f"name must be one of {names}, got {name!r}")
        value = getattr(self, name)
        if np.ndim(value):
            return sp.latex(as_sympy_matrix(name, value))
        return sp.latex(as_sympy(name, value))

    # -- derived objects -----------------------------------------------------------
    def subs(self, values: Mapping[Any, Any]) -> ReducedContact:
        """Substitute ``values`` (a dict symbol -> value) into a symbolic reduction.

        >>> m, k = sp.symbols("m k", positive=True)
        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[m]]), sp.Matrix([0]), x, [x], [v], {x: 0, v: 1}, k, 0)
        >>> r.subs({m: 2, k: 8}).omega0
        2.0
        """
        if not isinstance(values, Mapping):
            raise TypeError(f"values must be a dict of symbol -> value, got {values!r}")
        reject_strings("values", values)
        values = {
            as_sympy(f"values key {key!r}", key): as_sympy(f"values[{key!r}]", value, finite=True)
            for key, value in values.items()
        }
        new = {}
        for name in ("m_eff", "delta_d", "delta_c", "load", "v0", "k", "d"):
            value = getattr(self, name)
            if isinstance(value, sp.Basic):
                value = to_scalar(value.subs(values))
            new[name] = value
        return replace(self, **new)

    def with_penalty(self, k: Any, d: Any) -> ReducedContact:
        """The same reduction with other penalty parameters (numbers or arrays).

        ``m~``, ``delta_d``, ``delta_c``, the load and ``v0`` do not depend on ``k`` and
        ``d``, so this is how penalty designs sweep ``(k, d)`` cheaply.

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[2.0]]), sp.Matrix([0]), x, [x], [v], {x: 0, v: 1}, 8, 0)
        >>> r.with_penalty([8.0, 32.0], 0.0).omega0
        array([2., 4.])
        """
        k_val = penalty_parameter("k", k, strict=True)
        d_val = penalty_parameter("d", d, strict=False)
        broadcast(k=k_val, d=d_val)
        return replace(self, k=k_val, d=d_val)

    # -- section 2 ----------------------------------------------------------------
    def contact(self, condition: str) -> Any:
        """The section-2 result (``impactsym.contact.physical_contact``) of the reduction.

        It carries ``D, f, omega0, normalized_contact_time, contact_time, restitution,
        sticks`` for the reduced oscillator.

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([1.0]), x, [x], [v], {x: 0, v: 1},
        ...                    1.0, 4.0)
        >>> c = r.contact("force")
        >>> c.D, c.f, c.sticks
        (2.0, 0.25, True)
        """
        check_condition(condition)
        if self.is_symbolic:
            raise TypeError(
                "the reduction is symbolic; substitute numbers with .subs({...}) before "
                "asking for contact times"
            )
        self._check_section2()
        from impactsym.contact import physical_contact

        return physical_contact(
            self.m_eff, self.c_eff, self.d_eff, self.v0, self.load, condition=condition
        )

    def contact_time(self, condition: str) -> float | np.ndarray:
        """Physical contact time ``t_c = tau_c / omega0`` (``inf`` when the contact sticks).

        ``condition="force"`` ends the contact when ``d~ z' + c~ z`` (the normal force of
        the reduced oscillator) turns tensile; ``"position"`` when ``z`` turns negative.

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0]), x, [x], [v], {x: 0, v: 1},
        ...                    1.0, 0.0)
        >>> round(r.contact_time("position"), 12)  # undamped: half a period, pi
        3.14159265359
        """
        return _numeric(self.contact(condition).contact_time)

    def normalized_contact_time(self, condition: str) -> float | np.ndarray:
        """Contact time ``tau_c = omega0 t_c`` in the units of paper section 2.

        A critically damped contact without load releases at ``tau_c = 2`` under the force
        condition (its normalized force is ``(2 - tau) exp(-tau)``):

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[4.0]]), sp.Matrix([0.0]), x, [x], [v], {x: 0, v: 3},
        ...                    9.0, 12.0)
        >>> round(r.normalized_contact_time("force"), 12), round(r.contact_time("force"), 12)
        (2.0, 1.333333333333)
        """
        return _numeric(self.contact(condition).normalized_contact_time)

    def restitution(self, condition: str) -> float | np.ndarray:
        """Coefficient of restitution ``e = -z'(t_c) / v0`` (``0.0`` when sticking).

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[4.0]]), sp.Matrix([0.0]), x, [x], [v], {x: 0, v: 3},
        ...                    9.0, 12.0)
        >>> round(r.restitution("force"), 12)  # z'(2) = -exp(-2) for D = 1
        0.135335283237
        >>> r.restitution("position")  # the penetration never returns to zero
        0.0
        """
        return _numeric(self.contact(condition).restitution)

    def sticks(self, condition: str) -> bool | np.ndarray:
        """Whether the reduced contact sticks (verdict ``"stick"``) under ``condition``.

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0.1]), x, [x], [v], {x: 0, v: 1},
        ...                    1.0, [0.5, 4.0])
        >>> r.sticks("force")
        array([False,  True])
        """
        value = np.asarray(self.contact(condition).sticks, dtype=bool)
        return bool(value) if value.ndim == 0 else value

    def verdict(self, condition: str) -> str | np.ndarray:
        """``"stick"`` or ``"release"`` for each penalty pair.

        >>> from impactsym.multibody import reduce_contact
        >>> x, v = sp.symbols("x v")
        >>> r = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0.1]), x, [x], [v], {x: 0, v: 1},
        ...                    1.0, [0.5, 4.0])
        >>> r.verdict("position").tolist()
        ['release', 'stick']
        """
        sticks = np.asarray(self.sticks(condition))
        out = np.where(sticks, "stick", "release")
        return str(out) if out.ndim == 0 else out

    def _check_section2(self) -> None:
        for name, value, strict in (
            ("m_eff", self.m_eff, True),
            ("c_eff", self.c_eff, True),
            ("d_eff", self.d_eff, False),
            ("v0", self.v0, True),
            ("load", self.load, False),
        ):
            arr = np.asarray(value, dtype=float)
            bad = arr <= 0 if strict else arr < 0
            if np.any(bad):
                first = float(arr[bad].flat[0])
                raise ValueError(
                    f"the reduced oscillator has {name} = {first!r}, outside paper section 2 "
                    f"(which needs m_eff, c_eff, v0 > 0 and d_eff, load >= 0); " + _HINTS[name]
                )


_HINTS = {
    "m_eff": "the mass matrix is not positive definite along the normal",
    "c_eff": "the system's own stiffness along the normal outweighs k; raise k",
    "d_eff": "the system's forces add negative damping along the normal; raise d",
    "v0": "the bodies separate (n0^T q0' <= 0), there is no impact",
    "load": "the system pulls away from the contact (negative load)",
}


def penalty_parameter(name: str, value: Any, *, strict: bool) -> Scalar:
    """Internal: a penalty ``k`` (``strict``: ``> 0``) or ``d`` (``>= 0``) as a float, a NumPy
    array or a SymPy expression, refused by name when negative, NaN or a string.

    Used by :func:`impactsym.multibody.reduction.reduce_contact` and
    :meth:`ReducedContact.with_penalty`.
    """
    if isinstance(value, sp.Basic):
        if value.is_number:
            return penalty_parameter(name, float(value), strict=strict)
        if value.is_negative or (strict and value.is_zero):
            raise ValueError(f"{name} must be {'>' if strict else '>='} 0, got {value}")
        return value
    arr, scalar = real_array(name, value, lower=0.0, strict=strict)
    return float(arr) if scalar else arr


def to_scalar(value: sp.Expr) -> Scalar:
    """Internal: a SymPy number as a Python float (complex refused); symbols stay symbolic.

    Used by the reduction and by :meth:`ReducedContact.subs`.
    """
    if value.is_number:
        number = complex(value)
        if number.imag != 0:
            raise ValueError(f"the reduction gave a complex value {value}")
        return float(number.real)
    return value


def _numeric(value: Any) -> float | np.ndarray:
    arr = np.asarray(value, dtype=float)
    return float(arr) if arr.ndim == 0 else arr


def _sqrt(value: Scalar) -> Scalar:
    if isinstance(value, sp.Basic):
        return to_scalar(sp.sqrt(value)) if value.is_number else sp.sqrt(value)
    return _numeric(np.sqrt(value))
