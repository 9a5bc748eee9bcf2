"""The bounce-sequence step of ``impactsym reproduce`` (:mod:`impactsym.results.bounce`)."""

from __future__ import annotations

import csv
import math

import matplotlib

from impactsym.contact import bounce_sequence
from impactsym.results import bounce as results
from impactsym.results.report import data_files

matplotlib.use("Agg")


def test_quick_reproduction_writes_sequences_maps_and_tables(tmp_path):
    messages: list[str] = []
    files = results.write(tmp_path, quick=True, progress=messages.append)
    names = {p.name for p in files}
    for png in sorted(n for n in names if n.endswith(".png")):  # the report links its data
        assert data_files(png[: -len(".png")], results.DATA, names), png
    stems = ["bounce_sequence_1", "bounce_sequence_2"]
    stems += [
        f"bounce_{m}_map_{c}" for m in ("contacts", "time_to_rest") for c in results.CONDITIONS
    ]
    for stem in stems:
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert {"bounce_sequence.csv", "bounce_map.csv"} <= names
    assert all(p.stat().st_size > 0 for p in files)
    assert messages
    for name in names:  # every file has its sentence in the report
        stem = name.rsplit(".", 1)[0]
        assert name in results.CAPTIONS or any(stem.startswith(k) for k in results.CAPTIONS)

    with (tmp_path / "bounce_sequence.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    D, f = results.SEQUENCES[0]
    seq = bounce_sequence(D, f, condition="force")
    mine = [r for r in rows if float(r["D"]) == D and r["condition (0 position, 1 force)"] == "1"]
    assert len(mine) == seq.n_contacts
    assert float(mine[-1]["start"]) == seq.time_to_rest
    assert math.isinf(float(mine[-1]["end"]))

    with (tmp_path / "bounce_map.csv").open() as handle:
        grid = list(csv.DictReader(handle))
    assert len(grid) == 25 * 21
    no_force = [r for r in grid if float(r["f"]) == 0 and 0 < float(r["D"]) < 1]
    assert all(r["n_force"] == "1" and math.isinf(float(r["rest_force"])) for r in no_force)
