"""MuJoCo's RK4 phase summary (impactsym.engines.mujoco.discrete with .rk4): the limit
phase -> 0+ of the entering step, the stage count against a plain stage-by-stage loop,
and the summary against a dense midpoint scan of the model with its error bound."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.mujoco.discrete import phase_summary, step_contact
from impactsym.engines.mujoco.model import check_solimp, coefficients, impedance_at
from impactsym.engines.mujoco.rk4_entry import entering_step

DEFAULT = check_solimp((0.9, 0.95, 0.001, 0.5, 2.0))
#: found by a random search against a dense scan (solref, speed, gravity, timestep): the
#: summary's first grid phase, 1e-300, was not the limit 0+ (A: end step 7 -> 6 at phase
#: 0.0056 missed, 5.6e-3 steps and 8.7e-4 in e off); restitution jumps of a stage leaving
#: the contact in the last step, end step unchanged (B: -0.08 at 0.3426, 2.1e-3 in e off;
#: +0.018 at 0.2159, 3.6e-4 off)
CASES = {
    "A": ((0.03640869451271829, 0.4499225523475248), 0.39827588358843957, 9.81, 0.01),
    "B": ((0.020940364769412377, 0.3822827980561439), 0.14209664477443607, 9.81, 0.005),
    "B0": ((0.021943294535348372, 0.25867933921603425), 0.1937023894214917, 0.0, 0.01),
}


def _run(case, phase):
    solref, speed, gravity, dt = CASES[case]
    co = coefficients(solref, DEFAULT, dt)
    return step_contact(co, DEFAULT, 1.0, gravity, speed, dt, phase, integrator="rk4")


def _plain(case, phase):
    """The contact by MuJoCo's RK4 stage by stage in plain floats (a stage feels the force
    at ``x > 0`` with a positive force term): restitution, contact time in steps, and the
    stage pattern: stage ``i`` of step ``j`` at ``x > 0`` flips bit ``4j + i mod 28``,
    steps with all four stages in contact left out."""
    solref, speed, g, h = CASES[case]
    c = coefficients(solref, DEFAULT, h)
    b, kbar = float(c.damping), float(c.stiffness)

    def accel(x, v):
        d = float(impedance_at(np.array(abs(x)), DEFAULT))
        drive = g + b * v + d * kbar * x
        return (g - d * drive if x > 0 and drive > 0 else g), x > 0 and drive > 0

    t = (phase - 1.0) * h
    x, v = speed * t + 0.5 * g * t * t, speed + g * t
    pattern = 0
    for n in range(1000):
        a0, f0 = accel(x, v)
        if n > 0 and not f0:
            return -v / speed, t / h, pattern
        x1, v1 = x + 0.5 * h * v, v + 0.5 * h * a0
        a1 = accel(x1, v1)[0]
        x2, v2 = x + 0.5 * h * v1, v + 0.5 * h * a1
        a2 = accel(x2, v2)[0]
        x3, v3 = x + h * v2, v + h * a2
        a3 = accel(x3, v3)[0]
        inside = [i for i, y in enumerate((x, x1, x2, x3)) if y > 0]
        if len(inside) < 4:
            for i in inside:
                pattern ^= 1 << (4 * n + i) % 28
        x, v = (
            x + h * (v / 6 + v1 / 3 + v2 / 3 + v3 / 6),
            v + h * (a0 / 6 + a1 / 3 + a2 / 3 + a3 / 6),
        )
        t += h
    raise AssertionError("no end within 1000 steps")


@pytest.mark.parametrize("case", sorted(CASES))
def test_model_and_stage_count_are_the_plain_loops(case):
    phases = np.linspace(0.003, 0.997, 41)
    got = _run(case, phases)
    for j, p in enumerate(phases):
        e, t, pattern = _plain(case, float(p))
        assert got.restitution[j] == pytest.approx(e, rel=1e-9, abs=1e-12)
        assert got.contact_time[j] / CASES[case][3] == pytest.approx(t, rel=1e-12)
        assert got.stage_pattern[j] == pattern


def test_entering_step_is_the_plain_rk4_step():
    """Cancellation-free stages against MuJoCo's own arithmetic at ordinary phases."""
    rng = np.random.default_rng(3)
    g, v, h = rng.choice([0.0, 9.81], 200), rng.uniform(0.05, 3.0, 200), 0.005
    p = rng.uniform(0.01, 0.99, 200)

    def stage(x, u):
        drive = g + 3.0 * u + 2e5 * x
        return np.where((x > 0) & (drive > 0), g - 400.0 * drive, g), drive

    def acc(x, u):
        return stage(x, u)[0]

    x_new, v_new, inside = entering_step(stage, g, v, np.full(200, h), p)
    t0 = (p - 1.0) * h
    x, u = v * t0 + 0.5 * g * t0 * t0, v + g * t0
    a0 = acc(x, u)
    x1, u1 = x + 0.5 * h * u, u + 0.5 * h * a0
    a1 = acc(x1, u1)
    x2, u2 = x + 0.5 * h * u1, u + 0.5 * h * a1
    a2 = acc(x2, u2)
    x3, u3 = x + h * u2, u + h * a2
    a3 = acc(x3, u3)
    np.testing.assert_allclose(x_new, x + h * (u / 6 + u1 / 3 + u2 / 3 + u3 / 6), atol=1e-15)
    np.testing.assert_allclose(v_new, u + h * (a0 / 6 + a1 / 3 + a2 / 3 + a3 / 6), rtol=1e-12)
    bits = [y > 0 for y in (x, x1, x2, x3)]
    assert (inside == bits[0] + 2 * bits[1] + 4 * bits[2] + 8 * bits[3]).all()
    assert (inside > 0).any()
    assert (inside < 15).any()


@pytest.mark.parametrize("case", sorted(CASES))
def test_first_grid_phase_is_the_limit_from_above(case):
    """Phase 1e-300 (the summary's first grid point) gives what phases 1e-13 .. 1e-9 tend
    to; before, (phase - 1) h rounded to -h and the first state sat at distance 0."""
    tiny = _run(case, np.array([1e-300, 1e-13, 1e-11, 1e-9]))
    dt = CASES[case][3]
    np.testing.assert_allclose(tiny.restitution[0], tiny.restitution[1:], rtol=1e-6)
    np.testing.assert_allclose(tiny.contact_time[0] / dt, tiny.contact_time[1:] / dt, atol=1e-8)
    assert (tiny.stage_pattern[0] == tiny.stage_pattern[1:]).all()


@pytest.mark.parametrize("case", sorted(CASES))
def test_summary_mean_and_range_against_a_dense_scan(case):
    """The midpoint rule over 2^15 phases is off by at most half a cell times the
    variation between neighbouring samples (jumps included); the summary must lie within
    that (the defects were 10-60 times larger)."""
    solref, speed, gravity, dt = CASES[case]
    n = 2**15
    p = (np.arange(n) + 0.5) / n
    r = _run(case, p)
    e, t = r.restitution, r.contact_time / dt
    bound_e = 0.5 / n * np.abs(np.diff(e)).sum() + 1e-9
    bound_t = 0.5 / n * np.abs(np.diff(t)).sum() + 1e-9
    co = coefficients(solref, DEFAULT, dt)
    s = phase_summary(co, DEFAULT, 1.0, gravity, speed, dt, integrator="rk4")
    assert abs(float(s.restitution) - e.mean()) <= bound_e
    assert abs(float(s.contact_time) / dt - t.mean()) <= bound_t
    assert float(s.restitution_min) <= e.min() + 1e-12
    assert float(s.restitution_max) >= e.max() - 1e-12
