"""MuJoCo at its timestep (impactsym.engines.mujoco.euler, .discrete, .stepmap): against
MuJoCo itself (drivers.mujoco_steps), an independent plain recurrence and a phase scan."""

from __future__ import annotations

import os

import numpy as np
import pytest

from impactsym.engines.mujoco import predict
from impactsym.engines.mujoco.discrete import phase_mean, phase_summary, step_contact
from impactsym.engines.mujoco.model import check_solimp, coefficients

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


def _plain(solref, solimp, speed, gravity, dt, phase):
    """The Euler step written out state by state (MuJoCo's rules, metres and seconds)."""
    from impactsym.engines.mujoco.model import impedance_at

    simp = check_solimp(solimp)
    c = coefficients(solref, simp, dt)
    b, k = float(c.damping), float(c.stiffness)
    t = phase * dt if phase > 0 else 0.0
    x, u = speed * t + 0.5 * gravity * t * t, speed + gravity * t
    if phase == 0:  # zero distance is no contact: one free step first
        u += gravity * dt
        x += dt * u
        t = dt
    n = 0
    while True:
        d = float(impedance_at(np.array(x), simp))
        f = d * (gravity + b * u + d * k * x)
        if n > 0 and (x <= 0 or f <= 0):
            return -u / speed, t, n
        u += dt * (gravity - max(f, 0.0))
        x += dt * u
        t += dt
        n += 1


@pytest.mark.parametrize("solimp", [FLAT])
@pytest.mark.parametrize("gravity", [0.0])
def test_closed_form_and_recurrence_agree_with_a_plain_loop(solimp, gravity):
    rng = np.random.default_rng(7)
    simp = check_solimp(solimp)
    for _ in range(12):
        solref = (float(rng.uniform(0.005, 0.04)), float(rng.uniform(0.1, 1.2)))
        speed = float(rng.uniform(0.5, 2.0))
        dt = float(rng.choice([0.002, 0.0005, 1e-4]))
        phase = float(rng.uniform(0, 1))
        got = step_contact(
            coefficients(solref, simp, dt),
            simp,
            1.0,
            gravity,
            speed,
            dt,
            phase,
            integrator="euler",
        )
        e, t, n = _plain(solref, solimp, speed, gravity, dt, phase)
        assert int(got.steps) == n
        assert float(got.restitution) == pytest.approx(e, rel=1e-9, abs=1e-12)
        assert float(got.contact_time) == pytest.approx(t, rel=1e-9)


def _plain_states(solref, solimp, speed, gravity, dt, phase, steps):
    """The states of :func:`_plain` (phase > 0) in SI: penetration and constraint
    acceleration at states 0 .. steps after the first detecting one."""
    from impactsym.engines.mujoco.model import impedance_at

    simp = check_solimp(solimp)
    c = coefficients(solref, simp, dt)
    b, k = float(c.damping), float(c.stiffness)
    t = phase * dt
    x, u = speed * t + 0.5 * gravity * t * t, speed + gravity * t
    out = []
    for _ in range(steps + 1):
        d = float(impedance_at(np.array(x), simp))
        f = d * (gravity + b * u + d * k * x)
        out.append((x, f))
        u += dt * (gravity - max(f, 0.0))
        x += dt * u
    return out


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_end_value_is_the_plain_loops_penetration_and_force_at_each_state(gravity):
    """euler_end_value(m) = min(x_m / (v dt), f_m dt / v): positive before the end
    step, <= 0 at it (the plain loop's end step)."""
    from impactsym.engines.mujoco.euler import euler_end_value

    rng = np.random.default_rng(18)
    simp = check_solimp(DEFAULT)
    for _ in range(10):
        solref = (float(rng.uniform(0.005, 0.04)), float(rng.uniform(0.1, 0.8)))
        speed = float(rng.uniform(0.8, 2.0))  # bouncing designs: the plain loop ends
        dt = float(rng.choice([0.002, 0.0005]))
        phase = float(rng.uniform(0.01, 0.99))
        _, _, n = _plain(solref, DEFAULT, speed, gravity, dt, phase)
        c = coefficients(solref, simp, dt)
        m = np.arange(n + 1)
        got = euler_end_value(c, simp, 1.0, gravity, speed, dt, phase, m)
        want = [min(x / (speed * dt), f * dt / speed) for x, f in
                _plain_states(solref, DEFAULT, speed, gravity, dt, phase, n)]  # fmt: skip
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
        assert np.all(got[1:-1] > 0)
        assert got[-1] <= 0


def test_secant_jump_search_gives_the_sampled_search_bit_for_bit(monkeypatch):
    """The Euler summary's jumps narrowed by the secant on the end value end in the
    same cells as the 8-ary search that samples the end step everywhere."""
    from impactsym.engines.mujoco import discrete
    from impactsym.engines.mujoco.euler import euler_contact

    rng = np.random.default_rng(5)
    n = 120
    simp = check_solimp(DEFAULT)
    dt = 0.002
    tc = np.exp(rng.uniform(np.log(0.004), np.log(0.05), n))
    dr = np.exp(rng.uniform(np.log(0.05), np.log(3.0), n))
    g = np.where(rng.random(n) < 0.7, 9.81, 0.0)
    v = np.exp(rng.uniform(np.log(0.2), np.log(3.0), n))
    rho = np.where(rng.random(n) < 0.7, 1.0, rng.uniform(0.5, 2.0, n))
    # a design whose end value flips sign back and forth within rounding near a jump
    tc[0], dr[0], v[0] = 0.039571645276609134, 0.7123429668691206, 1.5970966828491608
    g[0], rho[0] = 9.81, 1.0885323324878693
    c = coefficients((tc, dr), simp, dt)
    args = (euler_contact, "euler", simp, c.damping, c.stiffness, rho, g, v, np.full(n, dt))
    real, narrowed = discrete.secant_bracket, []

    def spy(*a):
        out = real(*a)
        narrowed.append(int(out[2].sum()))
        return out

    monkeypatch.setattr(discrete, "secant_bracket", spy)
    got = discrete._split_and_integrate(*args)
    assert sum(narrowed) > 20  # the secant did narrow jumps
    monkeypatch.setattr(
        discrete, "secant_bracket", lambda value, a, c, m, r, w: (a, c, np.zeros(a.size, bool))
    )
    ref = discrete._split_and_integrate(*args)
    assert np.array_equal(got, ref, equal_nan=True)


def test_phase_summary_mean_and_range_against_a_dense_scan():
    for solimp, solref, gravity, speed in (
        (FLAT, (0.02, 0.25), 0.0, 1.0),
        (FLAT, (0.02, 0.3), 9.81, 0.1),
        (DEFAULT, (0.02, 0.4), 9.81, 1.0),
    ):
        simp = check_solimp(solimp)
        c = coefficients(solref, simp, 0.002)
        s = phase_summary(c, simp, 1.0, gravity, speed, 0.002, integrator="euler")
        p = (np.arange(20000) + 0.5) / 20000
        scan = step_contact(c, simp, 1.0, gravity, speed, 0.002, p, integrator="euler")
        assert float(s.restitution) == pytest.approx(scan.restitution.mean(), rel=1e-4)
        assert float(s.contact_time) == pytest.approx(scan.contact_time.mean(), rel=1e-4)
        edge = step_contact(c, simp, 1.0, gravity, speed, 0.002, 0.0, integrator="euler")
        values = np.append(scan.restitution, edge.restitution)
        assert float(s.restitution_min) <= values.min() + 1e-12
        assert float(s.restitution_max) >= values.max() - 1e-12
        times = np.append(scan.contact_time, edge.contact_time)
        assert float(s.contact_time_min) <= times.min() * (1 + 1e-12)
        assert float(s.contact_time_max) >= times.max() * (1 - 1e-12)


def test_predict_refuses_bad_discrete_input_by_name():
    with pytest.raises(ValueError, match="phase"):
        predict(solref=(0.02, 0.5), speed=1.0, phase=0.5)
    with pytest.raises(ValueError, match="phase"):
        predict(solref=(0.02, 0.5), speed=1.0, timestep=0.002, phase=1.0)
    with pytest.raises(ValueError, match="phase"):
        predict(solref=(0.02, 0.5), speed=1.0, timestep=0.002, phase=-0.1)
    with pytest.raises(ValueError, match="integrator"):
        predict(solref=(0.02, 0.5), speed=1.0, timestep=0.002, integrator="Euler2")
    with pytest.raises(ValueError, match="integrator"):
        predict(solref=(0.02, 0.5), speed=1.0, integrator="nope")
    p = predict(solref=(0.02, [0.3, 0.6]), speed=1.0, timestep=0.002, phase=[[0.1], [0.7]])
    assert p.restitution.shape == (2, 2)


if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401
else:
    pytest.importorskip("mujoco")

from impactsym.engines.drivers import mujoco_steps  # noqa: E402

CASES = [  # (solref, speed): designs from e about 0.9 down to 0.1
    ((0.02, 0.035), 1.0),
    ((0.02, 0.12), 1.0),
    ((0.02, 0.25), 1.0),
    ((0.015, 0.45), 0.8),
    ((0.02, 0.8), 1.5),
]


@pytest.mark.parametrize("dt", [0.002, 0.001, 0.0005])
@pytest.mark.parametrize("integrator", ["euler", "implicitfast"])
@pytest.mark.parametrize("solimp", [FLAT, DEFAULT])
def test_agrees_with_mujoco_state_by_state(dt, integrator, solimp):
    simp = check_solimp(solimp)
    tol = 1e-9 if solimp == FLAT else 1e-6
    for (solref, speed), gravity, phase in zip(
        CASES, (0.0, 9.81, 0.0, 9.81, 9.81), (0.0, 0.37, 0.81, 0.55, 0.13), strict=True
    ):
        run = mujoco_steps(
            solref=solref,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=dt,
            integrator=integrator,
            phase=phase,
        )
        got = step_contact(
            coefficients(solref, simp, dt),
            simp,
            1.0,
            gravity,
            speed,
            dt,
            phase,
            integrator=integrator,
        )
        assert bool(got.sticks) == run["sticks"]
        if run["sticks"]:
            continue
        assert int(got.steps) == run["steps"]
        assert float(got.restitution) == pytest.approx(run["restitution"], rel=tol)
        assert float(got.contact_time) == pytest.approx(run["contact_time"], rel=tol)
        assert float(got.departure_speed) == pytest.approx(run["departure_speed"], rel=tol)
        assert float(got.max_penetration) == pytest.approx(run["max_penetration"], rel=tol)


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
@pytest.mark.parametrize(
    "solimp",
    [(5e-5, 0.9, 0.001, 0.5, 2.0), (0.9, 0.99995, 0.001, 0.5, 2.0), (0.5, 0.95, 0.001, 5e-5, 2.0)],
)
def test_solimp_beyond_mujocos_range_is_clamped_as_mujoco_does(integrator, solimp):
    # MuJoCo clamps d_min, d_max and the midpoint to [1e-4, 0.9999] before it
    # interpolates (the reference loop, checked against MuJoCo itself); clamping the
    # interpolated impedance instead was 2.2e-2 off in e at d_min = 5e-5 (found by review)
    simp = check_solimp(solimp)
    for (solref, speed), gravity, phase in zip(CASES[:3], (0.0, 9.81, 0.0), (0.13, 0.37, 0.81),
                                               strict=True):  # fmt: skip
        run = mujoco_steps(solref=solref, solimp=solimp, speed=speed, gravity=gravity,
                           timestep=0.002, integrator=integrator, phase=phase)  # fmt: skip
        got = step_contact(coefficients(solref, simp, 0.002), simp, 1.0, gravity, speed, 0.002,
                           phase, integrator=integrator)  # fmt: skip
        assert bool(got.sticks) == run["sticks"]
        if not run["sticks"]:
            assert float(got.restitution) == pytest.approx(run["restitution"], rel=1e-6)
            assert float(got.max_penetration) == pytest.approx(run["max_penetration"], rel=1e-6)


def test_stick_verdict_agrees_with_mujoco():
    simp = check_solimp(FLAT)
    for speed in (0.3, 0.02):
        run = mujoco_steps(
            solref=(0.02, 1.0),
            solimp=FLAT,
            speed=speed,
            gravity=9.81,
            timestep=0.002,
            phase=0.4,
            max_steps=3000,
        )
        got = step_contact(
            coefficients((0.02, 1.0), simp, 0.002),
            simp,
            1.0,
            9.81,
            speed,
            0.002,
            0.4,
            integrator="euler",
        )
        assert bool(got.sticks) == run["sticks"]


def test_the_sympy_step_map_is_the_engines_and_implicitfast_is_the_same_map():
    """The map derived from MuJoCo's update (engines.derivation.mujoco_euler_step) iterated in
    plain floats reproduces euler_contact's closed form and the independent reference of
    MuJoCo's step; implicitfast (D = 0) gives the identical matrix; trace, det and the
    flip step are those the stability warning uses."""
    import sys
    from pathlib import Path

    import sympy as sp

    from impactsym.engines.derivation import mujoco_euler_step

    sys.path.insert(0, str(Path(__file__).parent))
    from references.mujoco_steps import mujoco_steps as reference

    r = mujoco_euler_step()
    assert sp.simplify(r["matrix"] - r["implicitfast"]) == sp.zeros(2, 2)
    h, g, b, d, kbar, dp = sp.symbols("h g b d kbar d_eff", positive=True)
    assert sp.simplify(r["det"] - (1 - h * dp * b)) == 0
    assert sp.simplify(r["trace"] - (2 - h * dp * b - h**2 * dp * d * kbar)) == 0
    assert sp.simplify((1 + r["trace"] + r["det"]).subs(h, r["flip_step"])) == 0
    step = sp.lambdify((h, g, b, d, kbar, dp), (r["matrix"], r["offset"]), "numpy")
    flip = sp.lambdify((b, d, kbar, dp), r["flip_step"], "math")
    simp = check_solimp(FLAT)
    for dampratio, gravity, phase in ((0.1, 0.0, 0.3), (0.5, 9.81, 0.7), (0.3, 9.81, 0.55)):
        dt, speed = 0.002, 1.0
        c = coefficients((0.02, dampratio), simp, dt)
        bb, kk = float(c.damping), float(c.stiffness)
        imp = 0.9  # flat impedance; one body on a slide joint: d' = d
        mat, off = step(dt, gravity, bb, imp, kk, imp)
        t = phase * dt
        y = np.array([speed * t + 0.5 * gravity * t * t, speed + gravity * t])
        n = 0
        while y[0] > 0 and gravity + bb * y[1] + imp * kk * y[0] > 0:
            y = np.array(mat, float) @ y + np.array(off, float).ravel()
            n += 1
            assert n < 10_000, "these cases release"
        ref = reference(
            solref=(0.02, dampratio), solimp=FLAT, speed=speed, gravity=gravity, timestep=dt,
            integrator="euler", phase=phase,
        )  # fmt: skip
        got = step_contact(c, simp, 1.0, gravity, speed, dt, phase, integrator="euler")
        assert -y[1] / speed == pytest.approx(ref["restitution"], rel=1e-9)
        assert float(got.restitution) == pytest.approx(-y[1] / speed, rel=1e-9)
        assert float(got.contact_time) == pytest.approx((phase + n) * dt, rel=1e-12)
        # the flip step: the matrix has an eigenvalue -1 there (unstable beyond it)
        hf = flip(bb, imp, kk, imp)
        m_flip = np.array(step(hf * (1 + 1e-9), gravity, bb, imp, kk, imp)[0], float)
        m_safe = np.array(step(hf * (1 - 1e-3), gravity, bb, imp, kk, imp)[0], float)
        assert np.abs(np.linalg.eigvals(m_flip)).max() > 1.0
        assert np.abs(np.linalg.eigvals(m_safe)).max() < 1.0


def test_a_design_leaves_out_contacts_stuck_at_a_grid_phase():
    """``resolve_sticking=False`` on the general summary (default solimp): a contact that
    sticks at some phase (the full summary says so: infinite contact time, a stick
    fraction) is left out with ``inf`` and ``nan``; the others are the full summary."""
    D = (0.9, 0.95, 0.001, 0.5, 2.0)
    dr = np.array([0.25, 0.35, 1.0, 2.0])  # the last two stick under gravity at 1 m/s
    c = coefficients((0.02, dr), D, 0.002)
    args = (c, D, np.ones(4), 9.81, 1.0, 0.002)
    full = phase_mean(*args, integrator="euler", bounds=False)
    lean = phase_mean(*args, integrator="euler", bounds=False, resolve_sticking=False)
    stuck = np.isinf(full.contact_time)
    assert stuck.tolist() == [False, False, True, True]
    assert np.all(full.stick_fraction[stuck] > 0)
    assert np.all(np.isinf(lean.contact_time[stuck]))
    assert np.all(np.isnan(lean.restitution[stuck]))
    for name in ("restitution", "contact_time", "restitution_min", "restitution_max"):
        np.testing.assert_array_equal(getattr(lean, name)[~stuck], getattr(full, name)[~stuck])
