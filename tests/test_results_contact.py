"""The spring-damper step of ``impactsym reproduce`` (:mod:`impactsym.results.contact`)."""

from __future__ import annotations

import csv
import math

import matplotlib

from impactsym.results import contact as results
from impactsym.results.report import data_files

matplotlib.use("Agg")

MEGABYTE = 1_000_000


def test_quick_reproduction_writes_figures_tables_and_formulas(tmp_path):
    messages: list[str] = []
    files = results.write(tmp_path, quick=True, progress=messages.append)
    names = {p.name for p in files}
    for png in sorted(n for n in names if n.endswith(".png")):  # the report links its data
        assert data_files(png[: -len(".png")], results.DATA, names), png
    for stem in (
        "fig1a_contact_surface_force",
        "fig1b_stick_boundary",
        "contact_time_map_position",
        "restitution_map_force",
    ):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert {"stick_boundary.csv", "contact_times_force.csv", "spring_damper_formulas.json"} <= names
    assert messages
    for path in files:  # every file has its sentence in the report (by name or stem prefix)
        assert any(path.name == key or path.stem.startswith(key) for key in results.CAPTIONS), (
            path.name
        )
    for path in files:
        if path.suffix == ".pdf":
            assert path.stat().st_size < MEGABYTE, path.name
    with (tmp_path / "stick_boundary.csv").open() as handle:
        first = next(csv.DictReader(handle))  # f = 0: D* = 1 (position) and inf (force)
    assert float(first["f"]) == 0.0
    assert float(first["D_star_position"]) == 1.0
    assert math.isinf(float(first["D_star_force"]))
