"""Engine surveys (:mod:`impactsym.engines.survey`) against SciPy integrations of the
contact laws as the engines document them."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import FLAT, stick_map, textbook_restitution


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
