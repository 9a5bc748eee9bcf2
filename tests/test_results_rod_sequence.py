"""Tests of :mod:`impactsym.results.rod_sequence`: the figures and table of the rod impact
continued past separation, as ``impactsym reproduce`` writes them."""

from __future__ import annotations

import math

import pytest


def test_quick_reproduction_writes_the_sequence_figures_and_table(tmp_path):
    import csv

    import matplotlib

    matplotlib.use("Agg")
    from impactsym.results import rod_sequence as results
    from impactsym.results.report import data_files

    messages: list[str] = []
    files = results.write(tmp_path, quick=True, progress=messages.append)
    names = {p.name for p in files}
    for png in sorted(n for n in names if n.endswith(".png")):  # the report links its data
        assert data_files(png[: -len(".png")], results.DATA, names), png
    for stem in ("rod_sequence", "rod_sequence_stress", "rod_restitution"):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    for name in names:
        assert name in results.CAPTIONS or name.rsplit(".", 1)[0] in results.CAPTIONS
    with (tmp_path / "rod_restitution.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    light = rows[0]  # alpha = 0.05: one contact, e -> 2/e
    assert float(light["restitution"]) == pytest.approx(2 / math.e, abs=1e-9)
    assert all(0.0 < float(r["restitution"]) < 1.0 for r in rows)
    assert messages
