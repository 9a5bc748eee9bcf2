"""The rod impact step of ``impactsym reproduce`` and its figures."""

from __future__ import annotations

import csv
import json
import math

import matplotlib
import matplotlib.pyplot
import numpy as np
import pytest

from impactsym.results import rod as results
from impactsym.results.report import data_files
from impactsym.rod import contact_time, contact_time_map, latex_formulas

matplotlib.use("Agg")


def test_quick_reproduction_writes_figures_table_and_formulas(tmp_path):
    messages: list[str] = []
    files = results.write(tmp_path, quick=True, progress=messages.append)
    names = {p.name for p in files}
    for png in sorted(n for n in names if n.endswith(".png")):  # the report links its data
        assert data_files(png[: -len(".png")], results.DATA, names), png
    for stem in ("rod_time_histories", "rod_finite_stiffness", "rod_contact_time_maps"):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert {"rod_contact_times.csv", "rod_formulas.json", "rod_formulas.tex"} <= names
    assert all(p.stat().st_size > 0 for p in files)
    assert messages
    for name in names:  # every file has its sentence in the report
        assert name in results.CAPTIONS or name.rsplit(".", 1)[0] in results.CAPTIONS

    with (tmp_path / "rod_contact_times.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 9 * 7
    row = rows[0]  # alpha = 0.05, f = 0: the classical rigid striker
    assert float(row["alpha"]) == 0.05
    assert float(row["t_force"]) == contact_time(0.05, 0.0, condition="force")
    assert any(math.isinf(float(r["t_force"])) for r in rows)  # sticking is in the map

    labels = [entry["label"] for entry in json.loads((tmp_path / "rod_formulas.json").read_text())]
    assert labels == [label for label, _, _ in latex_formulas(3)]


def test_contact_time_map_rows_and_ratio():
    study = contact_time_map([0.1, 30.0], [0.0, 2.0])
    rows = study.rows()
    assert len(rows) == 4
    assert rows[1][:2] == (30.0, 0.0)
    assert np.isnan(study.ratio[1, 0])  # alpha = 0.1, f = 2 sticks
    assert abs(study.ratio[0, 1] - 1) < 0.05
    axes = study.plot()
    assert len(axes) == 3
    matplotlib.pyplot.close(axes[0].figure)
    with pytest.raises(ValueError, match="1-D"):
        contact_time_map([[0.1]], [0.0])


def test_latex_formulas_compile(tmp_path, compile_latex):
    body = "".join(f"% {label}\n\\[\n{math_}\n\\]\n" for label, _, math_ in latex_formulas(3))
    tex = tmp_path / "rod.tex"
    tex.write_text(
        "\\documentclass{article}\\usepackage{amsmath}\\begin{document}\n"
        + body
        + "\\end{document}\n"
    )
    run = compile_latex(tex)
    assert run.returncode == 0, run.stdout[-2000:]
