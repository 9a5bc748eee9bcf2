"""The multibody reduction (paper section 3, eqs. (3)-(5)), :mod:`impactsym.multibody.reduction`:
limits, units, interfaces, bad input, and the reduced model against a full nonlinear SciPy
simulation (:mod:`references.multibody_systems`)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from conftest import CODE
from hypothesis import given, settings
from hypothesis import strategies as st
from references.multibody_systems import FullSimulation, bar_system, pendulum_kane
from sympy.physics import mechanics as me

from impactsym.multibody.reduction import latex_formulas, reduce_contact
from impactsym.multibody.simulation import double_pendulum, falling_bar
from impactsym.results.documents import compile_latex

x, v = sp.symbols("x v")
m, k, d, F = sp.symbols("m k d F", positive=True)


def particle(M=1.0, force=0.0, kk=1.0, dd=0.0, speed=1.0, **kw):
    return reduce_contact(
        sp.Matrix([[M]]), sp.Matrix([force]), x, [x], [v], {x: 0, v: speed}, kk, dd, **kw
    )


# ---------------------------------------------------------------------------------
# limits: the single particle is section 2 exactly
# ---------------------------------------------------------------------------------
@pytest.mark.parametrize("projection", ["impulse", "normal"])
def test_single_particle_reduces_exactly_to_section_2(projection):
    v0 = sp.Symbol("v0", positive=True)
    r = reduce_contact(
        sp.Matrix([[m]]), sp.Matrix([F]), x, [x], [v], {x: 0, v: v0}, k, d, projection=projection
    )
    assert (r.m_eff, r.d_eff, r.c_eff, r.load, r.v0) == (m, d, k, F, v0)
    assert sp.simplify(r.D - d / (2 * sp.sqrt(k * m))) == 0
    assert sp.simplify(r.f - F / (d * v0)) == 0
    assert sp.simplify(r.omega0 - sp.sqrt(k / m)) == 0
    assert r.is_symbolic


def test_particle_with_dynamicsymbols_gives_numbers():
    q = me.dynamicsymbols("q")
    r = reduce_contact(
        sp.Matrix([[2.0]]), sp.Matrix([3.0]), q, [q], [q.diff()], {q: 0.0, q.diff(): 0.5}, 8.0, 1.0
    )
    assert (r.m_eff, r.d_eff, r.c_eff, r.load, r.v0) == (2.0, 1.0, 8.0, 3.0, 0.5)
    assert isinstance(r.m_eff, float)
    np.testing.assert_allclose([r.D, r.f], [1.0 / (2 * 4.0), 3.0 / (1.0 * 0.5)], rtol=1e-15)


def test_own_spring_and_damper_add_to_penalty_and_load_is_the_pressing_force():
    # m x'' = F - c x' - s x - (k x + d x'): the reduced oscillator is exactly
    # m x'' + (d + c) x' + (k + s) x = F; F(v0) = F - c v0 would count c twice.
    c, s, v0 = sp.symbols("c s v0", positive=True)
    r = reduce_contact(
        sp.Matrix([[m]]), sp.Matrix([F - c * v - s * x]), x, [x], [v], {x: 0, v: v0}, k, d
    )
    assert (r.d_eff, r.c_eff, r.load) == (d + c, k + s, F)


def test_bar_effective_mass_from_impulse_momentum():
    # Impulse P up at the end: dv_y = P/m, d(omega) = -P (L/2) cos(theta) / J, so the end's
    # normal velocity changes by P (1/m + (L/2)^2 cos^2 / J) = P (1 + 3 cos^2) / m.
    L, th0 = sp.symbols("L theta0", positive=True)
    X, Y, TH, VX, VY, OM = sp.symbols("X Y TH VX VY OM")
    M = sp.diag(m, m, m * L**2 / 12)
    at = {X: 0, Y: L / 2 * sp.sin(th0), TH: th0, VX: 0, VY: -v, OM: 0}
    r = reduce_contact(
        M, sp.Matrix([0, 0, 0]), L / 2 * sp.sin(TH) - Y, [X, Y, TH], [VX, VY, OM], at, k, d
    )
    assert sp.simplify(r.m_eff - m / (1 + 3 * sp.cos(th0) ** 2)) == 0
    # upright bar: the normal passes through the centre of mass, m~ = m
    assert sp.simplify(r.subs({th0: sp.pi / 2}).m_eff - m) == 0


def test_curvature_term_enters_the_load():
    # pendulum tip (mass m, length l) hitting the floor y = -h without gravity: the only
    # normal load is the centripetal acceleration -l cos(q) q'^2 of the tip, m~ = m/sin^2 q
    q, u = sp.symbols("q u")
    arm, q0, u0 = 0.8, 0.6, -2.0  # swinging towards the floor
    h = arm * np.cos(q0)
    r = reduce_contact(
        sp.Matrix([[m * arm**2]]),
        sp.Matrix([0]),
        arm * sp.cos(q) - h,
        [q],
        [u],
        {q: q0, u: u0},
        k,
        d,
    )
    m_tilde = m / np.sin(q0) ** 2
    assert float(sp.simplify(r.m_eff / m_tilde)) == pytest.approx(1.0, rel=1e-12)
    assert float(r.load / (-m_tilde * arm * np.cos(q0) * u0**2)) == pytest.approx(1.0, rel=1e-12)
    assert r.v0 == pytest.approx(-arm * np.sin(q0) * u0, rel=1e-12)


def test_impulse_projection_matches_high_frequency_compliance():
    # For M q'' + C q' + K q = n lambda the compliance n^T (M s^2 + C s + K)^{-1} n is
    # eps^2/m~ - eps^3 Delta_d/m~^2 + ... (eps = 1/s) for the exact reduction: the impulse
    # projection reproduces the eps^3 term (and eps^4 with C = 0), the paper's does not.
    eps = sp.Symbol("epsilon")
    M = sp.Matrix([[3, 1, 0], [1, 2, 1], [0, 1, 4]])
    C = sp.Matrix([[2, -1, 0], [-1, 3, 1], [0, 1, 1]])
    K = sp.Matrix([[5, 2, 0], [2, 4, -1], [0, -1, 3]])
    n = sp.Matrix([1, 2, -1])
    q = sp.symbols("q0:3")
    u = sp.symbols("u0:3")
    at = {**dict.fromkeys(q, 0), **dict(zip(u, [1, 1, 1], strict=True))}
    g = (n.T * sp.Matrix(q))[0]

    def reduced_series(damping, stiffness, projection):
        force = -damping * sp.Matrix(u) - stiffness * sp.Matrix(q)
        r = reduce_contact(M, force, g, q, u, at, 1, 0, projection=projection)
        mm, dd, cc = r.m_eff, r.delta_d, r.delta_c  # eps^2 / (mm + dd eps + cc eps^2)
        return {2: 1 / mm, 3: -dd / mm**2, 4: dd**2 / mm**3 - cc / mm**2}

    def exact_series(damping, stiffness):
        A = M + damping * eps + stiffness * eps**2
        G = sp.expand((n.T * A.adjugate() * n)[0]) / sp.expand(A.det()) * eps**2
        return sp.series(G, eps, 0, 5).removeO()

    for order, damping, stiffness in ((3, C, K), (4, 0 * C, K)):
        exact = exact_series(damping, stiffness).coeff(eps, order)
        impulse = reduced_series(damping, stiffness, "impulse")[order]
        paper = reduced_series(damping, stiffness, "normal")[order]
        assert float(impulse) == pytest.approx(float(exact), rel=1e-12)
        assert abs(float(paper - exact)) > 1e-2 * abs(float(exact))


# ---------------------------------------------------------------------------------
# interfaces: numeric arrays and a numeric normal
# ---------------------------------------------------------------------------------
def test_numeric_arrays_and_a_numeric_normal_work():
    X = sp.symbols("X0:2")
    U = sp.symbols("U0:2")
    M = np.array([[2.0, 0.5], [0.5, 1.0]])
    n0 = np.array([1.0, 1.0])
    r = reduce_contact(M, np.array([1.0, 0.0]), n0, X, U, {U[0]: 1.0, U[1]: 0.0}, 100.0, 1.0)
    assert r.m_eff == pytest.approx(1 / (n0 @ np.linalg.solve(M, n0)), rel=1e-14)
    assert r.load == pytest.approx(r.m_eff * n0 @ np.linalg.solve(M, [1.0, 0.0]), rel=1e-14)
    assert r.v0 == 1.0
    assert np.allclose(r.direction, r.m_eff * np.linalg.solve(M, n0), rtol=1e-14)


# ---------------------------------------------------------------------------------
# units: scaling tests
# ---------------------------------------------------------------------------------
@pytest.mark.parametrize("projection", ["impulse", "normal"])
def test_scaling_all_masses_scales_effective_parameters(projection):
    # masses, forces, dampers, springs and penalties times s: m~, d~, c~, F_n times s;
    # D, f, omega0 unchanged
    s = 7.0
    base = double_pendulum()
    heavy = double_pendulum(
        masses=(s * 1.0, s * 0.5),
        joint_stiffness=(s * 50.0, s * 20.0),
        joint_damping=(s * 1.0, s * 0.5),
    )
    a = base.reduce(1e4, 30.0, 0.4, projection=projection)
    b = heavy.reduce(s * 1e4, s * 30.0, 0.4, projection=projection)
    for name in ("m_eff", "d_eff", "c_eff", "load"):
        assert getattr(b, name) == pytest.approx(s * getattr(a, name), rel=1e-12)
    for name in ("D", "f", "omega0", "v0"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-12)


def test_changing_the_length_unit_leaves_the_impulse_reduction_invariant():
    # the bar in centimetres: lengths, speeds and g times 100, rotational drag times 1e4;
    # k [N/m = kg/s^2] and d [kg/s] keep their numbers. Physical results must not change.
    metre = falling_bar()
    cm = falling_bar(length=100.0, gravity=981.0, rotational_drag=2.0e4)
    a = metre.reduce(2e4, 40.0, 0.3)
    b = cm.reduce(2e4, 40.0, 30.0)
    for name in ("m_eff", "d_eff", "c_eff", "D", "f", "omega0"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-12)
    assert b.load == pytest.approx(100 * a.load, rel=1e-12)  # force in kg cm / s^2


def test_paper_projection_depends_on_the_length_unit():
    # n0^T n0 adds 1 (y) and (L/2 cos theta)^2 (theta): the paper's eq. (5) projection is
    # not unit-consistent, its effective damping changes with metres vs centimetres
    a = falling_bar().reduce(2e4, 40.0, 0.3, projection="normal")
    b = falling_bar(length=100.0, gravity=981.0, rotational_drag=2.0e4).reduce(
        2e4, 40.0, 30.0, projection="normal"
    )
    assert abs(b.d_eff / a.d_eff - 1) > 0.05


# ---------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------
def test_singular_mass_matrix_is_refused():
    X, U = sp.symbols("X0:2"), sp.symbols("U0:2")
    with pytest.raises(ValueError, match=r"mass matrix M.*(singular|positive definite)"):
        reduce_contact(
            np.array([[1.0, 1.0], [1.0, 1.0]]),
            [0.0, 0.0],
            X[0],
            X,
            U,
            {X[0]: 0.0, U[0]: 1.0, U[1]: 0.0},
            1.0,
            0.0,
        )


def test_symbolic_singular_mass_matrix_is_refused():
    X, U = sp.symbols("X0:2"), sp.symbols("U0:2")
    with pytest.raises(ValueError, match="singular"):
        reduce_contact(sp.Matrix([[m, m], [m, m]]), [0, 0], X[0], X, U, {X[0]: 0, U[0]: 1}, k, d)


def test_vanishing_normal_is_refused():
    q, u = sp.symbols("q u")
    with pytest.raises(ValueError, match="normal n0"):
        reduce_contact(sp.Matrix([[1.0]]), [0.0], q**2, [q], [u], {q: 0.0, u: 1.0}, 1.0, 0.0)


def test_gap_not_closed_at_the_impact_state_is_refused():
    with pytest.raises(ValueError, match=r"g must vanish.*g\(q0\) = -0.001"):
        reduce_contact(sp.Matrix([[1.0]]), [0.0], x - 0.001, [x], [v], {x: 0.0, v: 1.0}, 1, 0)
    h = sp.Symbol("h", positive=True)
    with pytest.raises(ValueError, match="g must vanish"):
        reduce_contact(sp.Matrix([[1.0]]), [0.0], x - h, [x], [v], {x: 0, v: 1}, 1, 0)
    # within the tolerance it is accepted
    reduce_contact(sp.Matrix([[1.0]]), [0.0], x - 1e-12, [x], [v], {x: 0.0, v: 1.0}, 1, 0)


def test_other_bad_input_is_refused_with_the_argument_named():
    with pytest.raises(ValueError, match="projection must be one of"):
        particle(projection="tangent")
    with pytest.raises(TypeError, match="at must be a dict"):
        reduce_contact(sp.Matrix([[1]]), [0], x, [x], [v], [(x, 0)], 1, 0)
    with pytest.raises(TypeError, match=r"takes \(M, F, g, q, qd, at, k, d\)"):
        reduce_contact(sp.Matrix([[1]]), [0], x, [x], [v], {x: 0, v: 1}, 1)
    with pytest.raises(ValueError, match=r"v0 .* must be > 0"):
        particle(speed=-1.0)
    X, U = sp.symbols("X0:2"), sp.symbols("U0:2")
    with pytest.raises(ValueError, match="must be symmetric"):
        reduce_contact(
            np.array([[2.0, 1.0], [0.0, 2.0]]),
            [0, 0],
            X[0],
            X,
            U,
            {X[0]: 0, U[0]: 1, U[1]: 0},
            1,
            0,
        )


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: reduce_contact([[1]], [0], [CODE], [x], [v], {x: 0, v: 1}, 1, 0), "g"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {CODE: 0, v: 1}, 1, 0), "at"),
        (lambda: reduce_contact([[1]], [0], x, [x], [v], {x: CODE, v: 1}, 1, 0), "at"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()


# ---------------------------------------------------------------------------------
# the reduced model against the full simulation
# ---------------------------------------------------------------------------------
def sweep(model, example, omegas, dampings, forces):
    """Full (SciPy) and reduced contact times over a (k, d, v) grid."""
    sim, ex = FullSimulation(model), example
    m_eff = ex.reduce().m_eff
    accel = ex.reduce(1.0, 0.0, 1e-9).load / m_eff  # normal acceleration at rest
    rows = []
    for omega in omegas:
        for D in dampings:
            for f in forces:
                kk, dd = m_eff * omega**2, 2 * D * m_eff * omega
                speed = m_eff * accel / (dd * f)
                if speed > 2.0:
                    continue
                for condition in ("position", "force"):
                    t_full = sim.contact_time(kk, dd, speed, condition, 40 / omega)
                    red = {
                        p: ex.reduce(kk, dd, speed, projection=p).contact_time(condition)
                        for p in ("impulse", "normal")
                    }
                    red = {p: (t if t * omega <= 40 else np.inf) for p, t in red.items()}
                    rows.append((condition, t_full, red))
    return rows


def scores(rows, projection, condition):
    full = np.array([r[1] for r in rows if r[0] == condition])
    red = np.array([r[2][projection] for r in rows if r[0] == condition])
    hits = np.mean(np.isinf(full) == np.isinf(red))
    both = np.isfinite(full) & np.isfinite(red)
    return hits, np.abs(red[both] / full[both] - 1), int(both.sum())


@pytest.mark.parametrize(
    ("model", "example"), [(bar_system, falling_bar), (pendulum_kane, double_pendulum)]
)
def test_reduced_model_predicts_the_full_simulation(model, example):
    rows = sweep(
        model(),
        example(),
        omegas=(300.0, 1000.0),
        dampings=(0.08, 0.3, 1.2),
        forces=(0.1, 0.6, 2.5),
    )
    for condition in ("position", "force"):
        hits, err, n = scores(rows, "impulse", condition)
        hits_paper, err_paper, _ = scores(rows, "normal", condition)
        assert n >= 5
        assert hits >= 0.9
        assert np.median(err) < 0.03
        assert np.max(err) < 0.1
        # the impulse projection is the better one
        assert np.median(err) < np.median(err_paper)
        assert hits >= hits_paper


def test_impulse_projection_converges_faster_than_the_paper_projection():
    # falling bar with drag: contact-time error against omega0 at fixed D, f
    sim, ex = FullSimulation(bar_system()), falling_bar()
    m_eff = ex.reduce().m_eff
    accel = ex.reduce(1.0, 0.0, 1e-9).load / m_eff
    errors = {"impulse": [], "normal": []}
    for omega in (300.0, 3000.0):
        kk, dd = m_eff * omega**2, 2 * 0.15 * m_eff * omega
        speed = m_eff * accel / (dd * 0.3)
        t_full = sim.contact_time(kk, dd, speed, "position", 40 / omega)
        for p in errors:
            t_red = ex.reduce(kk, dd, speed, projection=p).contact_time("position")
            errors[p].append(abs(t_red / t_full - 1))
    for p in errors:
        assert errors[p][1] < errors[p][0] / 3  # both converge as the contact stiffens
    assert errors["impulse"][0] < errors["normal"][0] / 3
    assert errors["impulse"][1] < errors["normal"][1] / 3


# ---------------------------------------------------------------------------------
# formulas
# ---------------------------------------------------------------------------------
def test_latex_formulas_are_labelled_and_balanced():
    formulas = latex_formulas()
    labels = [label for label, _, _ in formulas]
    assert len(set(labels)) == len(labels)
    assert all(body.count("{") == body.count("}") for _, _, body in formulas)


def test_latex_formulas_compile(tmp_path, pdflatex):
    doc = ["\\documentclass{article}", "\\usepackage{amsmath}", "\\begin{document}"]
    for _, caption, body in latex_formulas():
        doc += [caption, "\\[", body, "\\]"]
    doc.append("\\end{document}")
    tex = tmp_path / "f.tex"
    tex.write_text("\n".join(doc))
    assert compile_latex(tex, tmp_path).read_bytes().startswith(b"%PDF")


# ---------------------------------------------------------------------------------
# properties over random linear systems
# ---------------------------------------------------------------------------------
def random_system(seed, n):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    C, K = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    return M, C + C.T, K + K.T, rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)


def linear_reduction(M, C, K, F0, normal, u0, projection):
    n = len(normal)
    q, u = sp.symbols(f"q0:{n}"), sp.symbols(f"u0:{n}")
    force = sp.Matrix(F0) - sp.Matrix(C) * sp.Matrix(u) - sp.Matrix(K) * sp.Matrix(q)
    g = sum(c * s for c, s in zip(normal, q, strict=True))
    at = {**dict.fromkeys(q, 0.0), **dict(zip(u, u0, strict=True))}
    return reduce_contact(M, force, g, q, u, at, 1e3, 1.0, projection=projection)


def reduction_in_coordinates(T, M, C, K, F0, normal, u0, projection):
    """The reduction of the same system written in coordinates p with q = T p:
    M -> T^T M T, C -> T^T C T, K -> T^T K T, F -> T^T F, n0 -> T^T n0, p0' = T^-1 q0'."""
    return linear_reduction(
        T.T @ M @ T,
        T.T @ C @ T,
        T.T @ K @ T,
        T.T @ F0,
        T.T @ normal,
        np.linalg.solve(T, u0),
        projection,
    )


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 3))
def test_impulse_reduction_is_invariant_under_a_change_of_coordinates(seed, n):
    # q = T p changes the coordinates, not the physics: every reduced quantity is the same
    M, C, K, F0, normal, u0 = random_system(seed, n)
    T = np.eye(n) + 0.4 * np.random.default_rng(seed + 1).normal(size=(n, n))
    u0 = u0 * np.sign(normal @ u0) + normal / np.linalg.norm(normal)  # approach: v0 > 0
    a = linear_reduction(M, C, K, F0, normal, u0, "impulse")
    b = reduction_in_coordinates(T, M, C, K, F0, normal, u0, "impulse")
    for name in ("m_eff", "d_eff", "c_eff", "load", "v0"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-9, abs=1e-9)
    # m~ is the least "mass" x^T M x over the motions x with n0^T x = 1, reached along P
    x = np.random.default_rng(seed + 2).normal(size=n)
    x = x / (normal @ x)
    assert x @ M @ x >= a.m_eff * (1 - 1e-12)
    assert a.direction @ M @ a.direction == pytest.approx(a.m_eff, rel=1e-12)
    assert normal @ a.direction == pytest.approx(1.0, rel=1e-12)


def test_paper_projection_is_not_invariant_under_a_change_of_coordinates():
    M, C, K, F0, normal, u0 = random_system(7, 3)
    u0 = u0 * np.sign(normal @ u0) + normal
    T = np.diag([1.0, 10.0, 0.1])  # e.g. metres to decimetres in one coordinate
    a = linear_reduction(M, C, K, F0, normal, u0, "normal")
    b = reduction_in_coordinates(T, M, C, K, F0, normal, u0, "normal")
    assert b.m_eff == pytest.approx(a.m_eff, rel=1e-12)  # the effective mass is invariant
    assert abs(b.d_eff / a.d_eff - 1) > 1e-3


def test_penalty_parameters_may_be_given_as_keywords():
    x, v = sp.symbols("x v")
    args = (sp.Matrix([[2.0]]), sp.Matrix([1.0]), x, [x], [v], {x: 0, v: 1.5})
    positional = reduce_contact(*args, 50.0, 3.0)
    keywords = reduce_contact(*args, k=50.0, d=3.0)
    assert (keywords.D, keywords.f, keywords.omega0) == (
        positional.D,
        positional.f,
        positional.omega0,
    )
    with pytest.raises(TypeError, match="both penalty parameters"):
        reduce_contact(*args, k=50.0)
