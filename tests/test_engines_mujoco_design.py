"""MuJoCo designs (impactsym.engines.mujoco.design): what solref_for designs is what
MuJoCo itself gives; unreachable targets are refused with the reason."""

from __future__ import annotations

import importlib
import math
import os

import numpy as np
import pytest
import sympy as sp

from impactsym.engines.mujoco import from_reduced, solref_for
from impactsym.multibody import reduce_contact

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("mujoco")

from impactsym.engines.drivers import fine_timestep, mujoco_drop, mujoco_pendulum

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


def _textbook_dampratio(e):
    return -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
@pytest.mark.parametrize(("solimp", "tol"), [(FLAT, 0.01), (DEFAULT, 0.02)])
def test_designed_restitution_is_what_mujoco_gives(gravity, solimp, tol):
    # under gravity, 0.1 at 1 m/s lies in the restitution gap (see the test below)
    targets = np.array([0.2 if gravity else 0.1, 0.3, 0.5, 0.7, 0.95])
    speed = 1.0
    design = solref_for(restitution=targets, speed=speed, gravity=gravity, solimp=solimp)
    rows = []
    for i, target in enumerate(targets):
        sr = (float(design.solref[0][i]), float(design.solref[1][i]))
        e, t = mujoco_drop(
            solref=sr,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=fine_timestep(sr, speed, gravity),
        )
        assert e == pytest.approx(target, rel=tol)
        assert t == pytest.approx(design.contact_time[i], rel=0.02)
        text = (0.02, _textbook_dampratio(target))
        e_text, _ = mujoco_drop(
            solref=text,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=fine_timestep(text, speed, gravity),
        )
        rows.append((target, e, e_text))
    # the textbook dampratio misses low targets by far more than the tolerance
    low = rows[0]
    assert abs(low[2] - low[0]) / low[0] > 5 * tol


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_negative_solref_and_contact_time_design_in_mujoco(gravity):
    targets = np.array([0.2, 0.6, 0.9])
    for form in ("timeconst", "stiffness"):
        design = solref_for(
            restitution=targets,
            speed=0.7,
            gravity=gravity,
            contact_time=0.01,
            solimp=FLAT,
            form=form,
        )
        for i, target in enumerate(targets):
            sr = (float(design.solref[0][i]), float(design.solref[1][i]))
            e, t = mujoco_drop(
                solref=sr,
                solimp=FLAT,
                speed=0.7,
                gravity=gravity,
                timestep=fine_timestep(sr, 0.7, gravity),
            )
            assert e == pytest.approx(target, rel=0.01)
            assert t == pytest.approx(0.01, rel=0.02)


def test_restitution_gap_under_gravity_is_refused_and_mujoco_shows_the_jump():
    with pytest.raises(ValueError, match=r"jumps from 0\.14\d+ to 0\.07\d+") as info:
        solref_for(restitution=0.1, speed=1.0, gravity=9.81, solimp=FLAT)
    jump = float(str(info.value).split("dampratio = ")[1].split()[0])
    e_below, _ = mujoco_drop(solref=(0.02, jump * 0.99), solimp=FLAT, speed=1.0, gravity=9.81)
    e_above, _ = mujoco_drop(solref=(0.02, jump * 1.01), solimp=FLAT, speed=1.0, gravity=9.81)
    assert e_below > 0.14
    assert e_above < 0.08


def test_multibody_contact_with_the_reduced_effective_mass():
    L, r, m, angle, omega = 0.5, 0.05, 2.0, 0.6, 2.0
    th, thd = sp.symbols("theta thetadot")
    inertia = m * L**2 + sp.Rational(2, 5) * m * r**2
    height = L * math.sin(angle) + r
    reduced = reduce_contact(
        sp.Matrix([[inertia]]),
        sp.Matrix([m * 9.81 * L * sp.cos(th)]),
        L * sp.sin(th) + r - height,
        [th],
        [thd],
        {th: angle, thd: omega},
        1.0,
        0.0,
    )
    kw = from_reduced(reduced)
    # MuJoCo's own estimate A_diag of the inverse effective mass, from the model
    _, _, model = mujoco_pendulum(solref=(0.02, 0.3), solimp=FLAT, omega=omega, timestep=1e-4)
    weight = float(model.body_invweight0[1][0])
    assert 1.0 / kw["mass"] != pytest.approx(weight, rel=0.1)  # a genuine multibody case
    design = solref_for(restitution=0.4, solimp=FLAT, inverse_weight=weight, **kw)
    e, t, _ = mujoco_pendulum(solref=design.solref, solimp=FLAT, omega=omega, timestep=1e-5)
    assert e == pytest.approx(0.4, rel=0.01)
    assert t == pytest.approx(design.contact_time, rel=0.02)


def test_unreachable_target_says_why_and_what_reaches_it():
    with pytest.raises(ValueError, match=r"cannot be reached.*higher speed"):
        solref_for(restitution=0.9, speed=0.01, gravity=9.81, solimp=FLAT, contact_time=0.5)


def test_bad_targets_are_refused_by_name():
    with pytest.raises(ValueError, match="restitution"):
        solref_for(restitution=1.2, speed=1.0)
    with pytest.raises(ValueError, match="form"):
        solref_for(restitution=0.5, speed=1.0, form="impedance")
    with pytest.raises(TypeError, match="numeric ReducedContact"):
        from_reduced(object())


def test_cli_design_is_what_mujoco_gives(capsys):
    from impactsym.cli import main

    # the continuous design (the CLI designs for dt = 0.002 unless told), at dt = 1e-5
    argv = ["mujoco", "--restitution", "0.4", "--speed", "1", "--contact-time", "0.01"]
    assert main([*argv, "--continuous", "--solimp", "0.9", "0.9", "0.001", "0.5", "2"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    solref = tuple(float(x) for x in first.split('"')[1].split())
    e, t = mujoco_drop(solref=solref, solimp=FLAT, speed=1.0, timestep=1e-5)
    assert e == pytest.approx(0.4, rel=0.01)
    assert t == pytest.approx(0.01, rel=0.02)


def test_tiny_d_min_design_is_what_mujoco_gives(capsys):
    # solimp[0] = 1e-300 overflowed the step estimate (exit code 3); MuJoCo clamps it
    from impactsym.cli import main

    solimp = ["1e-300", "0.95", "0.001", "0.5", "2"]
    argv = ["mujoco", "--restitution", "0.5", "--speed", "1", "--continuous"]
    assert main([*argv, "--solimp", *solimp]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    solref = tuple(float(x) for x in first.split('"')[1].split())
    e, _ = mujoco_drop(solref=solref, solimp=[float(x) for x in solimp], speed=1.0, timestep=1e-5)
    assert e == pytest.approx(0.5, rel=0.01)


def test_default_solimp_design_of_both_restitution_and_contact_time():
    targets = np.array([0.2, 0.6, 0.9])
    design = solref_for(restitution=targets, speed=0.7, gravity=9.81, contact_time=0.01)
    for i, target in enumerate(targets):
        sr = (float(design.solref[0][i]), float(design.solref[1][i]))
        e, t = mujoco_drop(
            solref=sr,
            solimp=DEFAULT,
            speed=0.7,
            gravity=9.81,
            timestep=fine_timestep(sr, 0.7, 9.81),
        )
        assert e == pytest.approx(target, rel=0.02)
        assert t == pytest.approx(0.01, rel=0.02)


def test_refsafe_is_checked_on_the_final_varying_design(monkeypatch):
    design = importlib.import_module("impactsym.engines.mujoco.design")

    # the varying design moves the timeconst below 2 timestep (the flat start is above)
    with pytest.raises(ValueError, match=r"contact_time = 0\.0013932.*2 \* timestep"):
        solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932, timestep=0.001)
    # MuJoCo with the design's timeconst raised to 2 timestep: contact time off by > 2 %
    free = solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932)
    assert free.solref[0] < 0.002
    _e, t = mujoco_drop(solref=(0.002, free.solref[1]), solimp=DEFAULT, speed=1.0, timestep=1e-6)
    assert abs(t / 0.0013932 - 1) > 0.02
    # a design whose prediction misses the targets is refused (tolerance made impossible)
    monkeypatch.setattr(design, "_DESIGN_TOL", 0.0)
    with pytest.raises(ValueError, match="is not reached"):
        solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932)
