"""LAMMPS at its timestep: the velocity-Verlet model against a step-by-step reference
and against LAMMPS itself (a sphere on ``fix wall/gran``), per touch phase and over phases;
``limit_damping`` under gravity (the stick band), designs at a timestep, the advisor."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from impactsym.engines import lammps
from impactsym.engines.lammps.phases import phase_statistics
from impactsym.engines.lammps.verlet import stability_limit, verlet_phase


def _recursion(D, L, tau, p, limit, nmax=3000):
    """The step-by-step velocity-Verlet of one contact (normalized), independent of the
    closed form: returns (sticks, restitution, contact_time, departure)."""
    x = p * tau + 0.5 * L * (p * tau) ** 2
    w = 1.0 + L * (p - 0.5) * tau
    for n in range(nmax):
        F = x + 2 * D * w
        if (n > 0 and x <= 0) or (limit and F <= 0):
            break
        w += tau * (L - F)
        x += tau * w
    else:
        return True, 0.0, math.inf, 0.0
    e, t = -(w + 0.5 * tau * L), (p + n) * tau
    while x > 0:  # coast in free flight (only after a force end)
        w += tau * L
        x += tau * w
        if x > 0 and x + 2 * D * w > 0:
            return True, 0.0, math.inf, 0.0
    return False, e, t, -(w + 0.5 * tau * L) if n else e


def test_closed_form_is_the_step_by_step_map():
    rng = np.random.default_rng(7)
    for _ in range(150):
        D, L = rng.uniform(0, 1.5), rng.choice([0.0, rng.uniform(0, 0.4)])
        tau, p, limit = rng.uniform(0.02, 0.35), rng.uniform(1e-3, 1), bool(rng.integers(2))
        if tau * (2 * D) >= 0.9 or tau >= 0.9 * stability_limit(D):
            continue
        r = verlet_phase(D, L, tau, p, limit)
        sticks, e, t, dep = _recursion(D, L, tau, p, limit)
        assert bool(r["sticks"]) == sticks
        if not sticks:
            assert float(r["restitution"]) == pytest.approx(e, abs=1e-9)
            assert float(r["contact_time"]) == pytest.approx(t, abs=1e-9)
            assert float(r["departure_speed"]) == pytest.approx(dep, abs=1e-9)


def test_phase_statistics_bound_and_average_every_phase():
    D, L, tau = (
        np.array([0.2, 0.2, 0.6, 0.1]),
        np.array([0, 0.1, 0.05, 0.02]),
        np.array([0.3, 0.15, 0.06, 0.3]),
    )
    P = (np.arange(4000) + 0.5) / 4000  # a jump moves a sampled mean by <= tau / 4000
    for limit in (True, False):
        st = phase_statistics(D, L, tau, limit)
        for i in range(D.size):
            r = verlet_phase(D[i], L[i], tau[i], P, limit)
            e = r["restitution"]
            assert st["restitution_min"][i] <= e.min() + 1e-12
            assert st["restitution_max"][i] >= e.max() - 1e-12
            assert st["restitution_max"][i] - e.max() < 1e-3
            assert st["restitution"][i] == pytest.approx(e.mean(), abs=2e-5)
            assert st["contact_time"][i] == pytest.approx(
                r["contact_time"].mean(), abs=tau[i] / 4000
            )


def test_refusals_and_continuous_limit():
    c = lammps.hooke_for(restitution=0.5, contact_time=1e-2, mass=1.0)
    with pytest.raises(ValueError, match="unstable"):
        lammps.predict(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0, timestep=1e-2)
    with pytest.raises(ValueError, match="phase needs a timestep"):
        lammps.predict(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0, phase=0.5)
    with pytest.raises(ValueError, match="phase must be in"):
        lammps.predict(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0, timestep=1e-4, phase=1.0)
    fine = lammps.predict(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0, timestep=1e-7)
    assert fine.restitution == pytest.approx(0.5, rel=1e-4)
    assert "continuous (timestep -> 0)" in repr(c)


def test_continuous_band_closed_form():
    # the coast after a force zero: sticks iff e < 4 D load, else leaves at sqrt(e(e - 4 D load))
    m, c = 1.0, lammps.hooke_for(restitution=0.5, contact_time=1e-2, mass=1.0)
    omega = math.sqrt(c.kn / m)
    for load in (0.0, 0.1, 0.25):
        p = lammps.predict(
            kn=c.kn,
            damping=c.damping,
            mass=m,
            speed=9.81 / omega / load if load else 1.0,
            gravity=9.81 if load else 0.0,
        )
        e, D = p.restitution, c.damping_ratio
        assert p.departure_speed / (9.81 / omega / load if load else 1.0) == pytest.approx(
            math.sqrt(e * (e - 4 * D * load)), rel=1e-12
        )
    p = lammps.predict(kn=c.kn, damping=c.damping, mass=m, speed=9.81 / omega / 0.3, gravity=9.81)
    assert p.sticks
    assert p.restitution == p.departure_speed == 0.0


if os.environ.get("CI") == "true":
    import lammps as _engine  # noqa: F401  (CI installs the [engines] extra)
else:
    pytest.importorskip("lammps")

from impactsym.engines.drivers import lammps_drop  # noqa: E402

MASS = 4.0 / 3.0 * math.pi * 0.1**3 * 1000.0  # the dropped sphere; the wall is infinite
T_C = 1e-2


@pytest.mark.parametrize("limit_damping", [True, False])
@pytest.mark.parametrize("style", ["velocity", "mass_velocity"])
def test_prediction_per_phase_is_lammps(limit_damping, style):
    for e_target, gravity in ((0.5, 0.0), (0.3, 9.81)):
        c = lammps.hooke_for(
            restitution=e_target, contact_time=T_C, mass=MASS, limit_damping=limit_damping
        )
        for steps in (10, 20, 50):
            for phase in (0.137, 0.71):
                dt = T_C / steps
                got = lammps_drop(
                    kn=c.kn,
                    damping=c.damping,
                    speed=1.0,
                    timestep=dt,
                    phase=phase,
                    gravity=gravity,
                    limit_damping=limit_damping,
                    damping_style=style,
                )
                assert got["mass"] == pytest.approx(MASS, rel=1e-14)
                p = lammps.predict(
                    kn=c.kn,
                    damping=c.damping,
                    mass=MASS,
                    speed=1.0,
                    gravity=gravity,
                    limit_damping=limit_damping,
                    timestep=dt,
                    phase=phase,
                )
                assert not got["sticks"]
                assert not p.sticks
                assert p.restitution == pytest.approx(got["restitution"], rel=1e-6)
                assert p.contact_time == pytest.approx(got["contact_time"], rel=1e-6)
                assert p.departure_speed == pytest.approx(got["departure_speed"], rel=1e-6)
                lo, hi = p.restitution_range
                assert lo <= got["restitution"] <= hi


@pytest.mark.parametrize("limit_damping", [True, False])
def test_designs_at_the_timestep_hit_the_phase_mean_in_lammps(limit_damping):
    phases = (np.arange(24) + 0.5) / 24
    for steps, e_target in ((10, 0.3), (20, 0.5), (50, 0.8)):
        dt = T_C / steps
        c = lammps.hooke_for(
            restitution=e_target,
            contact_time=T_C,
            mass=MASS,
            limit_damping=limit_damping,
            timestep=dt,
        )
        assert c.restitution == pytest.approx(e_target, rel=1e-8)
        runs = [
            lammps_drop(
                kn=c.kn,
                damping=c.damping,
                speed=1.0,
                timestep=dt,
                phase=p,
                limit_damping=limit_damping,
            )
            for p in phases
        ]
        e = np.array([r["restitution"] for r in runs])
        t = np.array([r["contact_time"] for r in runs])
        assert e.mean() == pytest.approx(e_target, rel=5e-3)
        assert t.mean() == pytest.approx(T_C, rel=5e-3)
        lo, hi = c.restitution_range
        assert lo - 1e-12 <= e.min()
        assert e.max() <= hi + 1e-12


def test_limit_damping_band_under_gravity_is_lammps():
    c = lammps.hooke_for(restitution=0.5, contact_time=T_C, mass=MASS)
    omega, g = math.sqrt(c.kn / MASS), 9.81
    for load, sticks in ((0.2, False), (0.25, False), (0.295, True), (0.31, True)):
        v = g / (omega * load)
        cont = lammps.predict(kn=c.kn, damping=c.damping, mass=MASS, speed=v, gravity=g)
        fine = lammps_drop(kn=c.kn, damping=c.damping, speed=v, timestep=T_C / 2000, gravity=g)
        assert cont.sticks == fine["sticks"] == sticks
        if not sticks:  # the continuous model against LAMMPS at a fine step
            assert cont.restitution == pytest.approx(fine["restitution"] / 1.0, rel=2e-3)
            assert cont.contact_time == pytest.approx(fine["contact_time"], rel=1e-3)
            assert cont.departure_speed == pytest.approx(fine["departure_speed"], rel=5e-3)
            assert cont.departure_speed < 0.9 * cont.restitution * v  # slowed by the coast
        for phase in (0.3, 0.8):  # the discrete model at t_c / 50, exactly
            got = lammps_drop(
                kn=c.kn, damping=c.damping, speed=v, timestep=T_C / 50, phase=phase, gravity=g
            )
            p = lammps.predict(
                kn=c.kn,
                damping=c.damping,
                mass=MASS,
                speed=v,
                gravity=g,
                timestep=T_C / 50,
                phase=phase,
            )
            assert p.sticks == got["sticks"]
            if not got["sticks"]:
                assert p.departure_speed == pytest.approx(got["departure_speed"], rel=1e-6)
                assert p.contact_time == pytest.approx(got["contact_time"], rel=1e-6)


def test_timestep_advisor_keeps_every_phase_within_tolerance_in_lammps():
    c = lammps.hooke_for(restitution=0.5, contact_time=T_C, mass=MASS)
    h = lammps.timestep_for(kn=c.kn, damping=c.damping, mass=MASS, speed=1.0, limit_damping=True)
    assert T_C / 200 < h < T_C / 50
    for phase in (0.05, 0.35, 0.65, 0.95):
        got = lammps_drop(kn=c.kn, damping=c.damping, speed=1.0, timestep=h, phase=phase)
        assert abs(got["restitution"] / 0.5 - 1) <= 0.01 + 1e-9
    wider = lammps.predict(kn=c.kn, damping=c.damping, mass=MASS, speed=1.0, timestep=1.05 * h)
    assert max(abs(v / 0.5 - 1) for v in wider.restitution_range) > 0.01


def test_cli_lammps_timestep_design_and_phase_range_in_lammps(capsys):
    from impactsym.cli import main

    dt = T_C / 20
    argv = ["lammps", "--restitution", "0.4", "--contact-time", repr(T_C), "--mass", repr(MASS)]
    assert main([*argv, "--timestep", repr(dt)]) == 0
    out = capsys.readouterr().out
    words = out.splitlines()[1].split()
    kn, eta = float(words[4]), float(words[5])
    assert "velocity-Verlet at timestep" in out
    line = next(s for s in out.splitlines() if s.startswith("restitution over phases"))
    lo, hi = (float(v) for v in line.split(":")[1].split(".."))
    e = [
        lammps_drop(kn=kn, damping=eta, speed=1.0, timestep=dt, phase=p)["restitution"]
        for p in (np.arange(16) + 0.5) / 16
    ]
    assert np.mean(e) == pytest.approx(0.4, rel=5e-3)
    assert lo - 1e-6 <= min(e) <= max(e) <= hi + 1e-6
    assert main(argv) == 0
    assert "continuous (timestep -> 0)" in capsys.readouterr().out


def test_phase_ranges_hold_every_sampled_phase_of_random_contacts():
    from impactsym.engines.lammps.verlet import positive_limit

    rng = np.random.default_rng(11)
    n = 40
    D = rng.uniform(0.01, 2.5, n)
    L = np.where(rng.random(n) < 0.4, 0.0, rng.uniform(0, 0.4, n))
    tau = rng.uniform(0.02, 0.9, n) * np.minimum(stability_limit(D), positive_limit(D))
    P = (np.arange(1000) + 0.5) / 1000
    for limit in (True, False):
        st = phase_statistics(D, L, tau, limit)
        for i in range(n):
            r = verlet_phase(D[i], L[i], tau[i], P, limit, extremes=False)
            assert bool(st["sticks_somewhere"][i]) == bool(r["sticks"].any())
            if r["sticks"].any():
                continue
            e = r["restitution"]
            assert st["restitution_min"][i] <= e.min() + 1e-12
            assert e.max() <= st["restitution_max"][i] + 1e-12
            assert st["restitution"][i] == pytest.approx(e.mean(), abs=2 * np.ptp(e) / 1000 + 1e-9)
