"""The reduced contact oscillator, :mod:`impactsym.multibody.oscillator`: penalty sweeps,
substitution, and its contact time, restitution and verdict against SciPy integrations of
the reduced oscillator and of the full system (:mod:`references.multibody_systems`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from conftest import CODE
from references.multibody_systems import FullSimulation, Model, reduced_oscillator
from sympy.physics import mechanics as me

from impactsym.multibody.reduction import reduce_contact
from impactsym.multibody.simulation import double_pendulum

x, v = sp.symbols("x v")
m, k, d, F = sp.symbols("m k d F", positive=True)


def particle(M=1.0, force=0.0, kk=1.0, dd=0.0, speed=1.0, **kw):
    return reduce_contact(
        sp.Matrix([[M]]), sp.Matrix([force]), x, [x], [v], {x: 0, v: speed}, kk, dd, **kw
    )


def hostile_particle(k=1.0, d=0.0, load=0.1):
    return reduce_contact([[1.0]], [load], x, [x], [v], {x: 0, v: 1}, k, d)


def test_vectorized_penalty_parameters():
    r = particle(M=2.0, force=1.0, kk=np.array([8.0, 32.0]), dd=np.array([[1.0], [2.0]]))
    assert r.D.shape == (2, 2)
    assert np.allclose(r.omega0, [2.0, 4.0])
    assert np.allclose(r.D, np.array([[1.0], [2.0]]) / (2 * np.sqrt(2 * np.array([8.0, 32.0]))))


def test_symbolic_reduction_substitutes_to_numbers():
    r = reduce_contact(sp.Matrix([[m]]), sp.Matrix([F]), x, [x], [v], {x: 0, v: 2}, k, d)
    num = r.subs({m: 1, F: 3, k: 100, d: 2})
    assert not num.is_symbolic
    assert (num.m_eff, num.load, num.omega0, num.D, num.f) == (1.0, 3.0, 10.0, 0.1, 0.75)
    with pytest.raises(TypeError, match="symbolic"):
        r.contact_time("force")
    assert sp.latex(r.equation)


@pytest.mark.parametrize(
    ("kk", "dd", "name"),
    [
        (-1.0, 0.0, "k"),
        (0.0, 0.0, "k"),
        (1.0, -0.5, "d"),
        (np.array([1.0, -1.0]), 0.0, "k"),
        (sp.Symbol("kn", negative=True), 0, "k"),
        (1.0, float("nan"), "d"),
    ],
)
def test_negative_penalty_parameters_are_refused(kk, dd, name):
    with pytest.raises(ValueError, match=rf"^{name} must"):
        particle(kk=kk, dd=dd)


def test_penalty_parameters_of_the_wrong_type_are_refused():
    with pytest.raises(TypeError, match=r"^k must"):
        particle(kk="stiff")


def test_single_particle_contact_equals_its_full_simulation():
    # m x'' = F - k x - d x' is its own reduction: same contact time as the simulation
    q, u = me.dynamicsymbols("q u")
    N = me.ReferenceFrame("N")
    P = me.Point("P")
    P.set_vel(N, u * N.x)
    kane = me.KanesMethod(N, [q], [u], kd_eqs=[q.diff() - u])
    kane.kanes_equations([me.Particle("p", P, 2.0)], [(P, 3.0 * N.x)])
    model = Model(kane, q, [q], [u], [0.0], [1.0])
    sim = FullSimulation(model)
    for dd, condition in ((4.0, "position"), (4.0, "force"), (0.0, "force"), (60.0, "force")):
        r = reduce_contact(kane, q, model.at(0.7), 800.0, dd)
        t_full = sim.contact_time(800.0, dd, 0.7, condition, 1.0)
        assert r.contact_time(condition) == pytest.approx(t_full, rel=1e-8)
        assert r.sticks(condition) == (t_full == np.inf)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_reduced_contact_time_is_the_first_root_of_the_reduced_oscillator(condition):
    # independent check of the section-2 mapping: integrate m~ z'' + d~ z' + c~ z = F_n
    r = double_pendulum().reduce(4e4, 25.0, 0.2)
    sol = reduced_oscillator(r, condition, 1.0, atol=1e-15, max_step=1e-4)
    assert r.contact_time(condition) == pytest.approx(sol.t_events[0][0], rel=1e-7)
    assert r.restitution(condition) == pytest.approx(-sol.y_events[0][0][1] / r.v0, rel=1e-6)
    assert r.verdict(condition) == "release"


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize("values", [{"k": "x"}, {sp.Symbol("k"): CODE}, {CODE: 1}])
def test_reduced_contact_subs_refuses_strings(values):
    k = sp.Symbol("k", positive=True)
    r = reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, k, 0)
    with pytest.raises(TypeError, match="values .*string"):
        r.subs(values)
    assert r.subs({k: 4}).omega0 == 2.0


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, CODE, 0), "k"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: 0, v: 1}, 1, [CODE]), "d"),
    ],
)
def test_penalty_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()


def test_penalty_arrays_of_different_lengths_are_named():
    with pytest.raises(ValueError, match=r"^k \(shape \(3,\)\) and d \(shape \(2,\)\)"):
        hostile_particle(k=[1.0, 2.0, 3.0], d=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"^k \(shape \(2,\)\) and d \(shape \(3,\)\)"):
        hostile_particle().with_penalty([1.0, 2.0], [0.1, 0.2, 0.3])


@pytest.mark.parametrize(
    ("k", "d", "pattern"),
    [(math.nan, 0.0, "^k must be finite"), (0.0, 0.0, "^k must be > 0"), (1.0, -1.0, "^d ")],
)
def test_penalties_are_validated(k, d, pattern):
    with pytest.raises(ValueError, match=pattern):
        hostile_particle(k=k, d=d)


def test_reduced_contact_is_importable_from_its_former_homes():
    import impactsym.multibody
    from impactsym.multibody import oscillator, reduction

    assert reduction.ReducedContact is oscillator.ReducedContact
    assert impactsym.multibody.ReducedContact is oscillator.ReducedContact
    assert isinstance(hostile_particle(), oscillator.ReducedContact)
