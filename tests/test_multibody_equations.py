"""Equations of motion from matrices or ``sympy.physics.mechanics`` models,
:mod:`impactsym.multibody.equations`: every kind of model reduces like the hand-written
matrices of the same system, and malformed input is refused by name."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from conftest import CODE
from references.multibody_systems import bar_system, pendulum_kane
from sympy.physics import mechanics as me

from impactsym.multibody.reduction import reduce_contact
from impactsym.multibody.simulation import double_pendulum, falling_bar

x, v = sp.symbols("x v")
m, k, d, F = sp.symbols("m k d F", positive=True)


@pytest.mark.parametrize("projection", ["impulse", "normal"])
@pytest.mark.parametrize(
    ("model", "example"), [(bar_system, falling_bar), (pendulum_kane, double_pendulum)]
)
def test_mechanics_models_reduce_like_hand_written_matrices(model, example, projection):
    # System (bar) and KanesMethod (pendulum) models against the matrices of the examples
    mod, ex = model(), example()
    a = reduce_contact(mod.model, mod.g, mod.at(0.3), 1e4, 5.0, projection=projection)
    b = ex.reduce(1e4, 5.0, 0.3, projection=projection)
    for name in ("m_eff", "d_eff", "c_eff", "load", "v0"):
        assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-12, abs=1e-12)
    # with u = q' the impact state may name the coordinate rates instead of the speeds
    rates = {qi.diff(): mod.at(0.3)[ui] for qi, ui in zip(mod.q, mod.u, strict=True)}
    c = reduce_contact(
        mod.model,
        mod.g,
        dict(zip(mod.q, mod.q0, strict=True)) | rates,
        1e4,
        5.0,
        projection=projection,
    )
    assert c.v0 == pytest.approx(b.v0, rel=1e-12)


def test_kanes_method_with_generalized_speeds_other_than_qdot():
    # particle on a line with q' = 2 u: M = 4 m in u; the normal speed is 2 u, m~ = m
    q, u = me.dynamicsymbols("q u")
    N = me.ReferenceFrame("N")
    P = me.Point("P")
    P.set_vel(N, 2 * u * N.x)
    kane = me.KanesMethod(N, [q], [u], kd_eqs=[q.diff() - 2 * u])
    kane.kanes_equations([me.Particle("p", P, m)], [(P, F * N.x)])
    r = reduce_contact(kane, q, {q: 0, u: v}, k, d)
    assert (sp.simplify(r.m_eff), r.load, r.v0) == (m, F, 2 * v)


def test_lagranges_method_model():
    q = me.dynamicsymbols("q")
    N = me.ReferenceFrame("N")
    P = me.Point("P")
    P.set_vel(N, q.diff() * N.x)
    p = me.Particle("p", P, m)
    p.potential_energy = 0
    lag = me.LagrangesMethod(me.Lagrangian(N, p), [q], forcelist=[(P, F * N.x)], frame=N)
    lag.form_lagranges_equations()
    r = reduce_contact(lag, q, {q: 0, q.diff(): v}, k, d)
    assert (r.m_eff, r.load, r.v0) == (m, F, v)


def test_mismatched_shapes_are_refused():
    X, U = sp.symbols("X0:3"), sp.symbols("U0:3")
    at = {X[0]: 0, U[0]: 1, U[1]: 0, U[2]: 0}
    with pytest.raises(ValueError, match="M must be 3 x 3"):
        reduce_contact(sp.eye(2), [0, 0, 0], X[0], X, U, at, 1, 0)
    with pytest.raises(ValueError, match="F must be 3 x 1"):
        reduce_contact(sp.eye(3), [0, 0], X[0], X, U, at, 1, 0)
    with pytest.raises(ValueError, match="F must be a column"):
        reduce_contact(sp.eye(3), sp.Matrix([[0, 0, 0]]), X[0], X, U, at, 1, 0)
    with pytest.raises(ValueError, match="qd must have as many entries as q"):
        reduce_contact(sp.eye(3), [0, 0, 0], X[0], X, U[:2], at, 1, 0)
    with pytest.raises(ValueError, match="numeric normal g must have 3 entries"):
        reduce_contact(sp.eye(3), [0, 0, 0], [1.0, 0.0], X, U, at, 1, 0)


def test_bad_coordinates_and_unfinished_models_are_refused_with_the_argument_named():
    with pytest.raises(TypeError, match="q must hold symbols"):
        reduce_contact(sp.Matrix([[1]]), [0], x, [1.0], [v], {x: 0, v: 1}, 1, 0)
    with pytest.raises(ValueError, match="call form_eoms"):
        reduce_contact(me.System(), x, {}, 1, 0)


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: reduce_contact([[CODE]], [0], x, [x], [v], {x: 0, v: 1}, 1, 0), "M"),
        (lambda: reduce_contact([[1]], [CODE], x, [x], [v], {x: 0, v: 1}, 1, 0), "F"),
        (lambda: reduce_contact([[1]], [[0], [CODE]], x, [x], [v], {x: 0}, 1, 0), "F"),
        (lambda: reduce_contact([[1]], [0], x, [CODE], [v], {x: 0, v: 1}, 1, 0), "q"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()


def test_nan_in_F_is_named_as_nan():
    with pytest.raises(ValueError, match=r"^F must be finite, got NaN at F\[1, 0\]"):
        reduce_contact(np.eye(2), [0.0, math.nan], x, [x, v], [v, x], {x: 0, v: 1}, 1, 0)
