"""Hostile inputs to LAMMPS at its timestep: every bad timestep, phase and tolerance is
named, an unreachable target is refused with a timestep that reaches it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym.engines import lammps

DESIGN = lammps.hooke_for(restitution=0.5, contact_time=1e-2, mass=1.0)
OK = {"kn": DESIGN.kn, "damping": DESIGN.damping, "mass": 1.0, "speed": 1.0}


@pytest.mark.parametrize("bad", [0.0, -1e-4, math.nan, math.inf, [1e-4, 2e-4]])
def test_bad_timestep_is_named(bad):
    with pytest.raises(ValueError, match="timestep"):
        lammps.predict(**OK, timestep=bad)


def test_timestep_of_the_wrong_type_is_named():
    with pytest.raises(TypeError, match="timestep"):
        lammps.predict(**OK, timestep="1e-4")


@pytest.mark.parametrize("bad", [-0.1, 1.0, 1.5, math.nan])
def test_bad_phase_is_named(bad):
    with pytest.raises(ValueError, match="phase"):
        lammps.predict(**OK, timestep=1e-4, phase=bad)


def test_phase_broadcasts_and_its_mean_is_the_phase_mean():
    phases = (np.arange(400) + 0.5) / 400
    per = lammps.predict(**OK, timestep=5e-4, phase=phases)
    assert per.restitution.shape == (400,)
    mean = lammps.predict(**OK, timestep=5e-4)
    assert np.mean(per.restitution) == pytest.approx(mean.restitution, abs=1e-3)
    lo, hi = mean.restitution_range
    assert lo <= per.restitution.min()
    assert per.restitution.max() <= hi
    assert "mean over touch phases" in repr(mean)


def test_unstable_and_overcorrecting_steps_are_refused():
    with pytest.raises(ValueError, match="unstable"):
        lammps.predict(**OK, timestep=7e-3)
    stiff = lammps.hooke_for(restitution=1e-3, contact_time=1e-2, mass=1.0)
    assert stiff.damping_ratio > 10
    with pytest.raises(ValueError, match="non-positive eigenvalue"):
        lammps.predict(kn=stiff.kn, damping=stiff.damping, mass=1.0, speed=1.0, timestep=1e-3)


def test_unreachable_design_names_a_timestep_that_reaches_it():
    with pytest.raises(ValueError, match=r"not reached at timestep = 0.004.*timestep <= "):
        lammps.hooke_for(restitution=0.2, contact_time=1e-2, mass=1.0, timestep=4e-3)
    with pytest.raises(ValueError, match="needs contact_time"):
        lammps.hooke_for(restitution=0.5, max_penetration=1e-3, speed=1.0, mass=1.0, timestep=1e-4)


@pytest.mark.parametrize("bad", [0.0, 1.0, -0.01, math.nan, [0.01, 0.02]])
def test_advisor_tolerance_is_named(bad):
    with pytest.raises(ValueError, match="tolerance"):
        lammps.timestep_for(**OK, limit_damping=True, tolerance=bad)


def test_advisor_refuses_a_sticking_contact():
    omega = math.sqrt(DESIGN.kn)
    with pytest.raises(ValueError, match="sticks"):
        lammps.timestep_for(
            kn=DESIGN.kn,
            damping=DESIGN.damping,
            mass=1.0,
            speed=9.81 / omega / 0.3,
            gravity=9.81,
            limit_damping=True,
        )
