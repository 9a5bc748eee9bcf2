"""MuJoCo's contact law (impactsym.engines.mujoco.model) against the engine's own state
and against the SymPy derivation (impactsym.engines.derivation)."""

from __future__ import annotations

import os

import numpy as np
import pytest
import sympy as sp

from impactsym.engines.derivation import MujocoContact
from impactsym.engines.mujoco import DEFAULT_SOLIMP, DEFAULT_TIMECONST, impedance
from impactsym.engines.mujoco.model import (
    Coefficients,
    check_solimp,
    coefficients,
    effective_impedance,
    oscillator,
)

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("mujoco")

from impactsym.engines.drivers import mujoco_pendulum

SOLIMP = (0.8, 0.95, 0.002, 0.4, 3.0)


def _slide(solref, solimp, timestep=0.002):
    import mujoco

    ref = " ".join(map(str, solref))
    imp = " ".join(map(str, solimp))
    xml = f"""<mujoco><option gravity="0 0 -9.81" timestep="{timestep}"/><worldbody>
    <geom type="plane" size="1 1 .1" condim="1" solref="{ref}" solimp="{imp}"/>
    <body><joint type="slide" axis="0 0 1"/><geom type="sphere" size="0.1" mass="2"
    condim="1" solref="{ref}" solimp="{imp}"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


def test_defaults_are_mujocos():
    import mujoco

    xml = '<mujoco><worldbody><geom type="plane" size="1 1 .1"/></worldbody></mujoco>'
    model = mujoco.MjModel.from_xml_string(xml)
    assert tuple(model.geom_solimp[0]) == DEFAULT_SOLIMP
    assert tuple(model.geom_solref[0]) == (DEFAULT_TIMECONST, 1.0)


def test_impedance_is_mujocos_efc_imp():
    import mujoco

    xml = """<mujoco><worldbody><geom type="plane" size="1 1 .1" solimp="0.5 0.99 0.002 0.3 3"/>
    <body><joint type="slide" axis="0 0 1"/><geom type="sphere" size="0.1" mass="1"
    solimp="0.5 0.99 0.002 0.3 3"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    for depth in (1e-5, 3e-4, 7e-4, 1.5e-3, 3e-3):
        data.qpos[0] = 0.1 - depth
        mujoco.mj_forward(model, data)
        assert impedance(depth, (0.5, 0.99, 0.002, 0.3, 3)) == pytest.approx(
            data.efc_KBIP[0][2], rel=1e-12
        )


@pytest.mark.parametrize("solref", [(0.02, 0.4), (-2500.0, -30.0)])
def test_coefficients_are_mujocos_efc_kbip_with_refsafe(solref):
    import mujoco

    # timestep 0.002 leaves timeconst 0.02 alone; 0.02 makes refsafe raise it to 0.04
    for timestep in (0.002, 0.02):
        model, data = _slide(solref, SOLIMP, timestep)
        for depth in (5e-4, 3e-3):  # inside and beyond the impedance width
            data.qpos[0], data.qvel[0] = 0.1 - depth, -0.3
            mujoco.mj_forward(model, data)
            K, B, _, _ = data.efc_KBIP[0]
            c = coefficients(solref, check_solimp(SOLIMP), timestep)
            assert float(c.stiffness) == pytest.approx(K, rel=1e-13)
            assert float(c.damping) == pytest.approx(B, rel=1e-13)
            # and the pair back
            back = c.solref(
                check_solimp(SOLIMP), form="timeconst" if solref[0] > 0 else "stiffness"
            )
            if solref[0] < 0 or timestep == 0.002:
                np.testing.assert_allclose(np.array(back, float), solref, rtol=1e-13)


def test_derivation_makes_dampratio_lehrs_D_and_gives_load_and_offset():
    mc = MujocoContact()
    flat = {**mc.solref_positive, mc.d: mc.d_max, mc.rho: 1}
    assert sp.simplify(mc.damping_ratio.subs(flat) - mc.dampratio) == 0
    assert sp.simplify(mc.omega0.subs(flat) - 1 / (mc.timeconst * mc.dampratio)) == 0
    assert sp.simplify(mc.normalized_load - (1 - mc.d_eff) * mc.gamma) == 0
    assert sp.simplify(mc.normalized_offset - mc.d_eff * mc.gamma) == 0


def test_oscillator_is_the_derivation_at_random_points():
    # model.py writes the coefficients in closed form (its docstring says why); the
    # SymPy derivation, lambdified here, is the reference at random points
    mc = MujocoContact()
    args = (mc.d, mc.rho, mc.b, mc.kbar, mc.g, mc.v0)
    derived = {
        name: sp.lambdify(args, getattr(mc, name), "numpy")
        for name in ("omega0", "damping_ratio", "normalized_load", "normalized_offset")
    }
    d_eff = sp.lambdify((mc.d, mc.rho), mc.d_eff, "numpy")
    rng = np.random.default_rng(21)
    n = 400
    d = rng.uniform(1e-4, 0.9999, n)
    rho = np.exp(rng.uniform(-3, 3, n))
    b = np.exp(rng.uniform(-5, 8, n))
    kbar = np.exp(rng.uniform(-5, 18, n))
    g = rng.uniform(0, 30, n) * (rng.random(n) < 0.8)
    v0 = np.exp(rng.uniform(-6, 3, n))
    osc = oscillator(Coefficients(b, kbar), d, rho, g, v0)
    values = (d, rho, b, kbar, g, v0)
    np.testing.assert_allclose(osc.omega0, derived["omega0"](*values), rtol=1e-13)
    np.testing.assert_allclose(osc.damping_ratio, derived["damping_ratio"](*values), rtol=1e-13)
    np.testing.assert_allclose(osc.load, derived["normalized_load"](*values), rtol=1e-13)
    np.testing.assert_allclose(osc.offset, derived["normalized_offset"](*values), rtol=1e-13)
    np.testing.assert_allclose(effective_impedance(d, rho), d_eff(d, rho), rtol=1e-14)


def test_coefficients_are_the_derivations_solref_forms_at_random_points():
    mc = MujocoContact()
    rng = np.random.default_rng(5)
    n = 200
    d_max = rng.uniform(1e-3, 0.999, n)
    tc, dr = np.exp(rng.uniform(-8, 0, n)), np.exp(rng.uniform(-4, 4, n))
    stiffness, damping = np.exp(rng.uniform(0, 15, n)), np.exp(rng.uniform(-3, 8, n))
    positive = {
        k: sp.lambdify((mc.timeconst, mc.dampratio, mc.d_max), v)
        for k, v in mc.solref_positive.items()
    }
    negative = {
        k: sp.lambdify((mc.stiffness, mc.damping, mc.d_max), v)
        for k, v in mc.solref_negative.items()
    }
    for i in range(n):
        solimp = (0.5 * d_max[i], d_max[i], 0.001, 0.5, 2.0)
        c = coefficients((tc[i], dr[i]), solimp, None)
        assert float(c.damping) == pytest.approx(positive[mc.b](tc[i], dr[i], d_max[i]), rel=1e-14)
        assert float(c.stiffness) == pytest.approx(
            positive[mc.kbar](tc[i], dr[i], d_max[i]), rel=1e-14
        )
        c = coefficients((-stiffness[i], -damping[i]), solimp, None)
        assert float(c.damping) == pytest.approx(
            negative[mc.b](stiffness[i], damping[i], d_max[i]), rel=1e-14
        )
        assert float(c.stiffness) == pytest.approx(
            negative[mc.kbar](stiffness[i], damping[i], d_max[i]), rel=1e-14
        )


@pytest.mark.parametrize("case", ["slide", "pendulum"])
def test_derived_contact_force_is_mujocos_efc_force(case):
    import mujoco

    mc = MujocoContact()
    if case == "slide":
        model, data = _slide((0.02, 0.4), SOLIMP)
        data.qpos[0], data.qvel[0] = 0.1 - 7e-4, -0.3
    else:
        _, _, model = mujoco_pendulum(solref=(0.02, 0.4), solimp=SOLIMP, omega=1.0)
        data = mujoco.MjData(model)
        data.qpos[0], data.qvel[0] = 0.6 + 1.5e-3, 0.8
    mujoco.mj_forward(model, data)
    assert data.nefc == 1
    J = np.array(data.efc_J[: model.nv])
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)  # MuJoCo 4 signature
    A = float(J @ np.linalg.solve(M, J))
    K, B, imp, _ = data.efc_KBIP[0]
    gravity_normal = -float(J @ np.linalg.solve(M, data.qfrc_bias))  # a0 along the normal
    values = {
        mc.m: 1 / A,
        mc.g: -gravity_normal,
        mc.d: imp,
        mc.rho: A / float(data.efc_diagA[0]),
        mc.b: B,
        mc.kbar: K,
        mc.x: -float(data.efc_pos[0]),
        mc.x_dot: -float(data.efc_vel[0]),
    }
    assert float(mc.contact_force.subs(values)) == pytest.approx(data.efc_force[0], rel=1e-9)


def test_bad_solimp_is_refused_by_name():
    with pytest.raises(TypeError, match="solimp"):
        check_solimp("0.9 0.95")
    with pytest.raises(ValueError, match="d_min, d_max"):
        check_solimp((0.0, 0.95, 0.001))
    with pytest.raises(ValueError, match="width"):
        check_solimp((0.9, 0.95, 0.001, 1.5, 2.0))
