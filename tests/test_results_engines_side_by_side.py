"""The side-by-side step of ``impactsym reproduce``: its quick-mode table, figure and
record, captions that say which engines were measured (with their versions) and which
points are predicted, with the engines installed and without (their absence simulated by
:func:`impactsym.results.engines_side_by_side.engine_versions` reporting none)."""

from __future__ import annotations

import csv
import json

import matplotlib
import numpy as np
import pytest

from impactsym import reproduce
from impactsym.engines import side_by_side as sbs
from impactsym.results import engines_side_by_side as results

matplotlib.use("Agg")

STEP = [("the engines side by side", "impactsym.results.engines_side_by_side")]
_CACHE: dict = {}


@pytest.fixture(autouse=True)
def _designs_once(monkeypatch):
    """The quick grid's designs are the same in every run: make them once."""
    real = sbs.cases

    def cached(**kwargs):
        key = tuple(sorted((k, str(v)) for k, v in kwargs.items()))
        if key not in _CACHE:
            _CACHE[key] = real(**kwargs)
        return list(_CACHE[key])

    monkeypatch.setattr(sbs, "cases", cached)


def _run(tmp_path, monkeypatch, versions=None):
    monkeypatch.setattr(reproduce, "STEPS", STEP)
    if versions is not None:
        monkeypatch.setattr(results, "engine_versions", lambda: dict(versions))
    out = tmp_path / "out"
    reproduce.reproduce(out, quick=True, progress=lambda message: None)
    with open(out / results.TABLE, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    return out, rows, (out / "report.md").read_text(encoding="utf-8")


def test_without_engines_nothing_runs_and_every_point_is_predicted(tmp_path, monkeypatch):
    def no_engine(*args, **kwargs):
        raise AssertionError("no engine may be run when none is installed")

    monkeypatch.setattr(sbs, "measure_cases", lambda cases, **kw: [no_engine() for _ in cases])
    out, rows, markdown = _run(tmp_path, monkeypatch, dict.fromkeys(sbs.ENGINES))
    for stem in ("engines_side_by_side_g0.png", "engines_side_by_side_g0.pdf"):
        assert (out / stem).stat().st_size > 1000
    # two recipes per engine and PyBullet's own velocity restitution
    assert len(rows) == (2 * len(sbs.ENGINES) + 1) * len(results.TARGETS[0])
    rigid = [r for r in rows if r["recipe"] == "native-restitution"]
    assert [r["engine"] for r in rigid] == ["PyBullet"]
    assert rigid[0]["parameters"] == "restitution=0.5 plane_restitution=1"
    assert {r["engine"] for r in rows} == set(sbs.ENGINES)
    assert all(r["e_measured_mean"] == "" for r in rows)
    for r in rows:  # the designs' predicted phase mean is the target
        if r["recipe"] == "impactsym":
            assert float(r["e_predicted_mean"]) == pytest.approx(float(r["e_wanted"]), rel=5e-3)
    record = json.loads((out / results.RUNS).read_text())
    assert record["engines"] == dict.fromkeys(sbs.ENGINES)
    text = results.captions(out)["engines_side_by_side_g0"]
    assert "No marker: no engine was installed" in text
    assert "No marker: no engine was installed" in markdown


def test_with_the_engines_the_table_holds_measurements_that_the_models_explain(
    tmp_path, monkeypatch
):
    versions = results.engine_versions()
    if not all(versions.values()):
        pytest.skip("MuJoCo, LAMMPS, Drake and PyBullet are not all installed")
    out, rows, markdown = _run(tmp_path, monkeypatch)
    for r in rows:
        e = float(r["e_measured_mean"])
        # every phase measured is the model's prediction of that phase
        assert float(r["max_abs_measured_minus_predicted"]) < 1e-8
        if r["recipe"] == "impactsym":  # the 0.5 % in every engine
            assert e == pytest.approx(float(r["e_wanted"]), rel=5e-3)
            assert float(r["tc_measured_mean_s"]) == pytest.approx(results.CONTACT_TIME, rel=5e-3)
        assert float(r["e_predicted_min"]) <= float(r["e_measured_min"]) + 1e-12
        assert float(r["e_measured_max"]) <= float(r["e_predicted_max"]) + 1e-12
    record = json.loads((out / results.RUNS).read_text())
    assert record["engines"] == versions
    assert record["phases"] == pytest.approx(((np.arange(4) + 0.5) / 4).tolist())
    text = results.captions(out)["engines_side_by_side_g0"]
    for name, version in versions.items():
        assert f"{name} {version}" in text
        assert f"{name} {version}" in markdown
    assert "engines_side_by_side.csv" in markdown
