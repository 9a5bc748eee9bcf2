"""Engine surveys (:mod:`impactsym.engines.survey`) against SciPy integrations of the
contact laws as the engines document them, against the engines themselves (LAMMPS,
MuJoCo) and against the plain-Python reference of MuJoCo's step."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import (
    DROP_MASS,
    FLAT,
    lammps_advice,
    lammps_at_timestep,
    lammps_measured,
    mujoco_advice,
    mujoco_at_timesteps,
    mujoco_measured,
    stick_map,
    textbook_restitution,
    touch_phases,
)


def released(gain, b, k, speed=1.0):
    """Restitution of ``x'' = -gain (b x' + k x)`` from ``x = 0, x' = speed``, released
    when the force ``b x' + k x`` vanishes (a compressive-only contact)."""

    def force(t, y):
        return b * y[1] + k * y[0]

    force.terminal, force.direction = True, -1
    sol = solve_ivp(
        lambda t, y: [y[1], -gain * force(t, y)],
        (0.0, 100.0),
        [0.0, speed],
        events=force,
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
    )
    return -sol.y_events[0][0][1] / speed


TARGETS = np.array([0.1, 0.3, 0.5, 0.8])


def test_textbook_damping_in_lammps_with_limit_damping():
    # Hooke with eta_n from the textbook damping ratio D, the force kept compressive
    D = np.asarray(lammps.textbook_damping_ratio(TARGETS))
    got = textbook_restitution(TARGETS)["LAMMPS coeff_restitution + limit_damping"]
    assert got == pytest.approx([released(1.0, 2 * d, 1.0) for d in D], rel=1e-9)
    assert np.all(got > TARGETS)  # the textbook damping undershoots the damping needed


def test_textbook_damping_in_mujoco_with_a_flat_impedance():
    # MuJoCo's reference acceleration -b v - k x with b = 2 / (dmax timeconst),
    # k = d / (dmax^2 timeconst^2 dampratio^2), applied with the impedance d (flat: d = dmax)
    D = np.asarray(lammps.textbook_damping_ratio(TARGETS))
    tc, d = mujoco.DEFAULT_TIMECONST, FLAT[1]
    expected = [released(d, 2 / (d * tc), d / (d**2 * tc**2 * r**2)) for r in D]
    got = textbook_restitution(TARGETS)["MuJoCo flat solimp"]
    assert got == pytest.approx(expected, rel=1e-9)


def test_stick_map_is_laid_out_dampratio_by_speed_with_three_verdicts():
    speed, dampratio = np.geomspace(0.01, 3.0, 7), np.geomspace(0.05, 2.0, 5)
    verdict, e = stick_map(speed, dampratio)
    assert verdict.shape == e.shape == (5, 7)
    assert set(np.unique(verdict)) <= {0, 1, 2}
    assert np.all(e[verdict == 0] == 0.0)  # a body that sticks does not bounce
    assert np.all(e[verdict > 0] > 0.0)
    # without gravity nothing sticks and the force always ends the contact
    verdict, _ = stick_map(speed, dampratio, gravity=0.0)
    assert np.all(verdict == 1)


def test_textbook_targets_are_refused_by_name():
    with pytest.raises(TypeError, match="^targets must be a real number"):
        textbook_restitution("x")
    with pytest.raises(ValueError, match="^targets must be > 0"):
        textbook_restitution(np.array([0.0, 0.5]))


def test_touch_phases_are_midpoints_and_bad_counts_are_refused():
    assert touch_phases(2).tolist() == [0.25, 0.75]
    # the midpoint rule is exact for a linear function of the phase: mean 1/2
    assert touch_phases(7).mean() == pytest.approx(0.5, rel=1e-15)
    for bad in (0, -1, 2.0, True):
        with pytest.raises(ValueError, match="^count must be a positive integer"):
            touch_phases(bad)


def test_lammps_at_timestep_continuous_design_misses_and_discrete_hits():
    e = np.array([0.1, 0.3, 0.5, 0.7, 0.9])
    out = lammps_at_timestep(e, steps_per_contact=50)
    assert out["timestep"] == pytest.approx(np.full(5, 0.01 / 50))
    assert out["discrete_mean"] == pytest.approx(e, rel=5e-3)  # the 0.5 %
    assert np.max(np.abs(out["continuous_mean"] / e - 1)) > 5e-3  # what it fixes
    for name in ("continuous", "discrete"):
        assert np.all(out[f"{name}_min"] <= out[f"{name}_mean"])
        assert np.all(out[f"{name}_mean"] <= out[f"{name}_max"])
    # the continuous design converges to the target as the timestep shrinks
    fine = lammps_at_timestep(e, steps_per_contact=5000)
    assert fine["continuous_mean"] == pytest.approx(e, rel=1e-3)
    errors = [
        np.max(np.abs(lammps_at_timestep(e, steps_per_contact=n)["continuous_mean"] / e - 1))
        for n in (20, 50, 200)
    ]
    assert errors[0] > errors[1] > errors[2]


def test_lammps_measured_is_the_prediction_at_each_phase_and_inside_the_band():
    pytest.importorskip("lammps")
    out = lammps_at_timestep(np.array([0.3, 0.7]), steps_per_contact=50)
    dt = float(out["timestep"][0])
    got = lammps_measured(
        kn=out["discrete_kn"], damping=out["discrete_damping"], speed=1.0, timestep=dt, phases=4
    )
    assert got["restitution"].shape == (2, 4)
    per_phase = lammps.predict(
        kn=out["discrete_kn"][:, None],
        damping=out["discrete_damping"][:, None],
        mass=DROP_MASS,
        speed=1.0,
        timestep=dt,
        phase=got["phase"][None, :],
    )
    assert got["restitution"] == pytest.approx(np.asarray(per_phase.restitution), rel=1e-6)
    assert np.all(got["min"] >= out["discrete_min"] - 1e-9)
    assert np.all(got["max"] <= out["discrete_max"] + 1e-9)
    # four phases already give the phase mean within the band's half width / 4
    assert got["mean"] == pytest.approx(out["discrete_mean"], abs=0.01)


def test_lammps_advice_keeps_one_percent_in_lammps_itself():
    pytest.importorskip("lammps")
    e = np.array([0.2, 0.8])
    steps = lammps_advice(e)
    assert np.all(steps > 1)
    assert steps[0] > steps[1]  # more damping, finer steps
    design = lammps.hooke_for(restitution=e, contact_time=0.01, mass=DROP_MASS, speed=1.0)
    for k, eta, n, target in zip(design.kn, design.damping, steps, e, strict=True):
        got = lammps_measured(kn=k, damping=eta, speed=1.0, timestep=0.01 / n, phases=5)
        assert np.all(np.abs(got["restitution"] / target - 1) <= 0.01 + 1e-6)


def test_mujoco_measured_is_the_reference_step_over_phases():
    pytest.importorskip("mujoco")
    from references.mujoco_steps import mujoco_steps

    solref, dts = (0.02, 0.25), np.array([5e-4, 2e-3])
    got = mujoco_measured(
        solref=solref,
        solimp=mujoco.DEFAULT_SOLIMP,
        speed=1.0,
        gravity=9.81,
        timesteps=dts,
        phases=4,
    )
    for i, dt in enumerate(dts):
        e = [
            mujoco_steps(
                solref=solref,
                solimp=mujoco.DEFAULT_SOLIMP,
                speed=1.0,
                gravity=9.81,
                timestep=float(dt),
                phase=float(p),
            )["restitution"]
            for p in touch_phases(4)
        ]
        assert got["mean"][i] == pytest.approx(np.mean(e), rel=1e-6)
        assert got["min"][i] == pytest.approx(min(e), rel=1e-6)
        assert got["max"][i] == pytest.approx(max(e), rel=1e-6)
    assert not got["sticks"].any()
    assert got["timestep"].tolist() == dts.tolist()


def test_mujoco_at_timesteps_is_predict_at_each_timestep():
    # one call by exact time scaling, against one predict call per timestep; both solref
    # forms (timeconst, dampratio) and (-stiffness, -damping), default solimp, gravity
    steps = np.array([3e-4, 1.1e-3, 2e-3])
    for solref in ((0.02, 0.25), (-2500.0, -40.0)):
        got = mujoco_at_timesteps(solref=solref, speed=1.0, gravity=9.81, timesteps=steps)
        for i, dt in enumerate(steps):
            p = mujoco.predict(solref=solref, speed=1.0, gravity=9.81, timestep=float(dt))
            assert got["mean"][i] == pytest.approx(p.restitution, rel=1e-9)
            assert got["min"][i] == pytest.approx(p.restitution_range[0], rel=1e-9)
            assert got["max"][i] == pytest.approx(p.restitution_range[1], rel=1e-9)
            assert got["tc_mean"][i] == pytest.approx(p.contact_time, rel=1e-9)
        assert got["timestep"] == pytest.approx(steps, rel=0)


def test_mujoco_at_timesteps_band_holds_mujoco_itself():
    pytest.importorskip("mujoco")
    from impactsym.engines.drivers import mujoco_phases

    # the textbook solref and the discrete design of e = 0.5 at 0.002 s (1 m/s, gravity)
    steps = np.array([5e-4, 2e-3])
    for solref in ((0.02, 0.2154537619662468), (0.02, 0.24860959916306014)):
        curve = mujoco_at_timesteps(solref=solref, speed=1.0, gravity=9.81, timesteps=steps)
        for i, dt in enumerate(steps):
            run = mujoco_phases(
                solref=solref,
                solimp=mujoco.DEFAULT_SOLIMP,
                speed=1.0,
                gravity=9.81,
                timestep=float(dt),
                phases=touch_phases(16),
            )
            e = run["restitution"]
            assert curve["min"][i] - 1e-4 <= e.min() <= e.max() <= curve["max"][i] + 1e-4
            # 16 midpoint phases against the exact phase mean
            assert e.mean() == pytest.approx(curve["mean"][i], abs=3e-3)


def test_mujoco_at_timesteps_refuses_bad_input_by_name():
    with pytest.raises(ValueError, match="timesteps"):
        mujoco_at_timesteps(solref=(0.02, 1.0), speed=1.0, timesteps=[[1e-3]])
    with pytest.raises(ValueError, match="timesteps"):
        mujoco_at_timesteps(solref=(0.02, 1.0), speed=1.0, timesteps=[-1e-3])
    with pytest.raises(ValueError, match="solref"):
        mujoco_at_timesteps(solref=(0.02, 1.0, 3.0), speed=1.0, timesteps=[1e-3])
    with pytest.raises(TypeError, match="solref"):
        mujoco_at_timesteps(solref="0.02 1", speed=1.0, timesteps=[1e-3])


def test_mujoco_advice_is_the_advisor_beside_the_rule_of_thumb(monkeypatch):
    asked = {}

    def advisor(**kwargs):
        asked.update(kwargs)
        return mujoco.TimestepAdvice(np.array([1e-4, 2e-4]), np.array([0.01, 0.009]), 0, (0, 0))

    monkeypatch.setattr(mujoco, "timestep_for", advisor)
    targets = np.array([0.3, 0.7])
    out = mujoco_advice(targets, speed=1.0, gravity=9.81, solimp=FLAT, tolerance=0.02)
    design = mujoco.solref_for(restitution=targets, speed=1.0, gravity=9.81, solimp=FLAT)
    assert asked["tolerance"] == 0.02
    assert asked["solref"][1] == pytest.approx(design.solref[1], rel=0)
    assert out["timestep"].tolist() == [1e-4, 2e-4]
    # MuJoCo's reference acceleration -d (b v + k x) at d = d_max, b = 2 / (d_max tc),
    # k = d_max / (d_max^2 tc^2 dr^2): omega0^2 = d_max k = 1 / (tc dr)^2
    tc, dr = design.solref
    omega0 = np.sqrt(FLAT[1] * FLAT[1] / (FLAT[1] ** 2 * tc**2 * dr**2))
    assert out["rule_of_thumb"] == pytest.approx(0.03 / omega0, rel=1e-12)
