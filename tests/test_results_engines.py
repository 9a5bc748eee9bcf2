"""The engine step of ``impactsym reproduce``: its figures and tables, and captions that
say honestly which points were measured in which engine version and which are predicted,
with the engines installed and without (their absence simulated by
:func:`impactsym.results.engines.engine_versions` reporting none)."""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser

import matplotlib
import numpy as np
import pytest

import impactsym.engines.drivers as drivers
from impactsym import reproduce
from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import DROP_MASS, FLAT, mujoco_at_timesteps
from impactsym.results import engines as results
from impactsym.results import engines_timestep

matplotlib.use("Agg")

STEP = [("engine parameters (MuJoCo, LAMMPS)", "impactsym.results.engines")]


class Captions(HTMLParser):
    """The text of each figure's caption, by figure id."""

    def __init__(self) -> None:
        super().__init__()
        self.captions: dict[str, str] = {}
        self._figure = None
        self._inside = False

    def handle_starttag(self, tag, attrs):
        if tag == "figure":
            self._figure = dict(attrs)["id"]
            self.captions[self._figure] = ""
        self._inside = self._inside or tag == "figcaption"

    def handle_endtag(self, tag):
        self._inside = self._inside and tag != "figcaption"

    def handle_data(self, data):
        if self._inside:
            self.captions[self._figure] += data


_CACHE: dict = {}


@pytest.fixture(autouse=True)
def _designs_once(monkeypatch):
    """Each reproduce run makes the same MuJoCo designs, curves and advice: make them once
    (the real functions' results, kept for the module's runs)."""
    designs, advice = engines_timestep.mujoco_designs, engines_timestep.mujoco_advice
    curves = engines_timestep.mujoco_curves

    def cached_curves(solrefs, timesteps):
        key = ("curves", tuple(solrefs.items()), tuple(np.asarray(timesteps).tolist()))
        if key not in _CACHE:
            _CACHE[key] = curves(solrefs, timesteps)
        return dict(_CACHE[key])

    def cached_designs(restitution, *, contact_time=None):
        key = ("designs", restitution, contact_time)
        if key not in _CACHE:
            _CACHE[key] = designs(restitution, contact_time=contact_time)
        return dict(_CACHE[key])

    def cached_advice(targets, **kwargs):
        key = ("advice", tuple(np.asarray(targets).tolist()), tuple(sorted(kwargs.items())))
        if key not in _CACHE:
            _CACHE[key] = advice(targets, **kwargs)
        return dict(_CACHE[key])

    monkeypatch.setattr(engines_timestep, "mujoco_designs", cached_designs)
    monkeypatch.setattr(engines_timestep, "mujoco_advice", cached_advice)
    monkeypatch.setattr(engines_timestep, "mujoco_curves", cached_curves)


def _run(tmp_path, monkeypatch, versions):
    monkeypatch.setattr(reproduce, "STEPS", STEP)
    monkeypatch.setattr(results, "engine_versions", lambda: dict(versions))
    out = tmp_path / "out"
    reproduce.reproduce(out, quick=True, progress=lambda message: None)
    page = (out / "index.html").read_text(encoding="utf-8")
    assert not re.search(r"https?:", page)
    for link in re.findall(r'(?:href|src)="([^"#][^"]*)"', page):
        assert (out / link).is_file(), link
    parser = Captions()
    parser.feed(page)
    return out, parser.captions, (out / "report.md").read_text(encoding="utf-8")


def test_without_engines_every_engine_point_is_said_to_be_predicted(tmp_path, monkeypatch):
    def no_engine(**kwargs):
        raise AssertionError("no engine may be run when none is installed")

    for name in ("mujoco_drop", "lammps_collision", "mujoco_phases", "lammps_drop"):
        monkeypatch.setattr(drivers, name, no_engine)
    out, captions, markdown = _run(tmp_path, monkeypatch, {"MuJoCo": None, "LAMMPS": None})
    record = json.loads((out / "engines_runs.json").read_text())
    assert record == {"engines": {"MuJoCo": None, "LAMMPS": None}, "runs": []}
    textbook, stick = captions["engines_textbook_error"], captions["engines_mujoco_stick_map"]
    for text in (textbook, markdown):
        assert "Every point of this figure is a prediction" in text
        assert "no engine was run" in text
        assert "Markers: measured" not in text
    assert "prediction of impactsym" in stick
    assert "no point of this map is an engine run" in stick
    timestep = json.loads((out / "engines_timestep_runs.json").read_text())
    assert timestep["lammps"] == {}
    lammps_caption = captions["engines_lammps_timestep"]
    assert "No LAMMPS point: LAMMPS was not installed" in lammps_caption
    assert "every curve and band is a prediction" in lammps_caption
    assert "Points with bars: measured" not in lammps_caption
    assert all(not case["measured"] for case in timestep["mujoco"].values())
    mujoco_caption = captions["engines_mujoco_timestep"]
    assert "No MuJoCo point: MuJoCo was not installed" in mujoco_caption
    assert "Points with bars: measured" not in mujoco_caption


def test_lammps_at_its_timestep_files_hold_the_predictions(tmp_path, monkeypatch):
    runs = []

    def fake_drop(*, kn, damping, speed, timestep, phase, limit_damping):
        runs.append((kn, damping, timestep, phase))
        return {"restitution": 0.5, "contact_time": 0.01}

    monkeypatch.setattr(drivers, "lammps_drop", fake_drop)
    out, captions, markdown = _run(tmp_path, monkeypatch, {"MuJoCo": None, "LAMMPS": "1.2-test"})
    for name in ("engines_lammps_timestep.png", "engines_lammps_timestep.pdf"):
        assert (out / name).stat().st_size > 1000
    rows = (out / "engines_lammps_timestep.csv").read_text().splitlines()
    header = rows[0].split(",")
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    column = dict(zip(header, table.T, strict=True))
    # the discrete design's phase mean hits the target at t_c/50 (the 0.5 %)
    assert column["discrete_mean"] == pytest.approx(column["e_target"], rel=5e-3)
    assert column["timestep_s"] == pytest.approx(0.01 / 50)
    assert np.all(column["continuous_min"] <= column["continuous_mean"])
    # the designs' kn, eta_n are hooke_for's, and the advisor's steps are timestep_for's
    design = lammps.hooke_for(
        restitution=column["e_target"], contact_time=0.01, mass=DROP_MASS, speed=1.0
    )
    assert column["continuous_kn"] == pytest.approx(design.kn, rel=1e-12)
    advice = np.loadtxt(out / "engines_lammps_advice.csv", delimiter=",", skiprows=1)
    h = lammps.timestep_for(
        kn=design.kn, damping=design.damping, mass=DROP_MASS, speed=1.0, limit_damping=True
    )
    assert advice[:, 1] == pytest.approx(0.01 / h, rel=1e-9)
    record = json.loads((out / "engines_timestep_runs.json").read_text())
    assert record["engines"]["LAMMPS"] == "1.2-test"
    assert len(runs) == 2 * 3  # quick: two designs of e = 0.5 at three phases
    assert record["lammps"]["discrete"]["restitution"] == [[0.5, 0.5, 0.5]]
    text = captions["engines_lammps_timestep"]
    assert "Points with bars: measured in LAMMPS 1.2-test" in text
    assert "predicted by impactsym.engines.lammps.predict(timestep=...)" in text
    assert "engines_lammps_timestep.csv" in markdown


def test_with_one_engine_its_version_is_named_and_the_other_is_predicted(tmp_path, monkeypatch):
    calls = []

    def fake_drop(*, solref, solimp, speed, gravity, timestep):
        calls.append(solref)
        return 0.5, 0.01

    def fake_phases(*, solref, solimp, speed, gravity, timestep, integrator, phases):
        return {"restitution": np.full(len(phases), 0.5), "sticks": np.zeros(len(phases), bool)}

    monkeypatch.setattr(drivers, "mujoco_drop", fake_drop)
    monkeypatch.setattr(drivers, "mujoco_phases", fake_phases)
    out, captions, markdown = _run(tmp_path, monkeypatch, {"MuJoCo": "9.8.7-test", "LAMMPS": None})
    runs = json.loads((out / "engines_runs.json").read_text())["runs"]
    assert len(runs) == len(calls) == 3 * 2 * 2  # 3 targets, 2 solimp, textbook and design
    assert {r["engine"] for r in runs} == {"MuJoCo"}
    assert {r["version"] for r in runs} == {"9.8.7-test"}
    text = captions["engines_textbook_error"]
    assert "Markers: measured in MuJoCo 9.8.7-test" in text
    assert f"{len(runs)} runs" in text
    assert "LAMMPS was not installed when this was reproduced" in text
    assert "all are predicted" in text
    assert "Curves: predicted by impactsym" in text
    assert "measured in MuJoCo 9.8.7-test" in markdown
    assert "Every point of this figure is a prediction" not in text


def test_mujoco_at_its_timestep_files_hold_the_predictions(tmp_path, monkeypatch):
    calls = []

    def fake_phases(*, solref, solimp, speed, gravity, timestep, integrator, phases):
        calls.append((tuple(solref), timestep))
        return {"restitution": np.full(len(phases), 0.5), "sticks": np.zeros(len(phases), bool)}

    monkeypatch.setattr(drivers, "mujoco_drop", lambda **kwargs: (0.5, 0.01))
    monkeypatch.setattr(drivers, "mujoco_phases", fake_phases)
    out, captions, markdown = _run(tmp_path, monkeypatch, {"MuJoCo": "7.7-test", "LAMMPS": None})
    for name in ("engines_mujoco_timestep", "engines_mujoco_advice"):
        assert (out / f"{name}.png").stat().st_size > 1000
        assert (out / f"{name}.pdf").stat().st_size > 1000
    rows = (out / "engines_mujoco_timestep.csv").read_text().splitlines()
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    column = dict(zip(rows[0].split(","), table.T, strict=True))
    record = json.loads((out / "engines_timestep_runs.json").read_text())
    assert record["engines"]["MuJoCo"] == "7.7-test"
    for case, e, contact_time in engines_timestep.MUJOCO_CASES:
        solrefs = record["mujoco"][case]["solref"]
        assert set(solrefs) == (
            {"continuous", "discrete"} | ({"textbook"} if contact_time is None else set())
        )
        # the discrete design's phase mean is the target at MuJoCo's default timestep
        p = mujoco.predict(
            solref=solrefs["discrete"], speed=1.0, gravity=9.81, timestep=0.002, integrator="euler"
        )
        assert p.restitution == pytest.approx(e, rel=5e-3)
        # the CSV's curves are the predictions for the recorded designs (two timesteps)
        steps = column["timestep_s"][[3, -4]]
        for name, solref in solrefs.items():
            curve = mujoco_at_timesteps(solref=solref, speed=1.0, gravity=9.81, timesteps=steps)
            for key in ("mean", "min", "max", "tc_mean"):
                got = column[f"{case}_{name}_{key}"][[3, -4]]
                assert got == pytest.approx(curve[key], rel=1e-12)
        measured = record["mujoco"][case]["measured"]
        assert measured["discrete"]["mean"] == [0.5] * len(engines_timestep.MUJOCO_STEPS[0])
    assert len(calls) == 5 * len(engines_timestep.MUJOCO_STEPS[0])  # 3 + 2 designs
    advice = np.loadtxt(out / "engines_mujoco_advice.csv", delimiter=",", skiprows=1)
    design = mujoco.solref_for(restitution=advice[:, 0], speed=1.0, gravity=9.81, solimp=FLAT)
    assert advice[:, 2] == pytest.approx(design.solref[1], rel=1e-12)
    assert advice[:, 5] == pytest.approx(0.03 * advice[:, 1] * advice[:, 2], rel=1e-12)
    assert np.all(advice[:, 4] <= 0.01)  # the worst deviation at the advised timestep
    text = captions["engines_mujoco_timestep"]
    assert "Points with bars: measured in MuJoCo 7.7-test" in text
    assert f"over {engines_timestep.MUJOCO_PHASES[0]} evenly spaced touch phases" in text
    assert "predicted by impactsym.engines.mujoco.predict(timestep=...), not engine output" in text
    assert "engines_mujoco_advice.csv" in markdown


def _engines_importable() -> bool:
    versions = results.engine_versions()
    return all(versions.values())


@pytest.mark.skipif(not _engines_importable(), reason="MuJoCo and LAMMPS are not installed")
def test_with_the_engines_installed_the_measured_points_agree_and_name_versions(tmp_path):
    import lammps
    import mujoco

    versions = results.engine_versions()
    assert versions == {"MuJoCo": mujoco.__version__, "LAMMPS": str(lammps.__version__)}
    runs = results.run_engines(versions, (0.3, 0.7))
    assert len(runs) == 2 * 4 + 2 * 2
    for run in runs:  # the engine's own state against impactsym's prediction
        assert run["e_measured"] == pytest.approx(run["e_predicted"], abs=5e-3), run
    out = tmp_path
    (out / results.RUNS).write_text(json.dumps({"engines": versions, "runs": runs}))
    text = results.captions(out)["engines_textbook_error"]
    assert f"measured in MuJoCo {mujoco.__version__}" in text
    assert f"measured in LAMMPS {lammps.__version__}" in text
    assert not re.search(r"not installed|no engine was run", text)
