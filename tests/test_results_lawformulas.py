"""The reproduce step of the formula table: its CSV holds what formula_table computes."""

from __future__ import annotations

import csv

import numpy as np

from impactsym.contact.lawformulas import FORMULAS, formula_table
from impactsym.results import lawformulas


def test_write_gives_the_table_and_its_figure(tmp_path):
    files = lawformulas.write(tmp_path, quick=True, progress=lambda _: None)
    assert sorted(p.name for p in files) == [
        "formula_restitution.csv",
        "formula_restitution.pdf",
        "formula_restitution.png",
    ]
    with (tmp_path / "formula_restitution.csv").open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["target", *(lawformulas.COLUMNS[f] for f in FORMULAS)]
    values = np.array(rows[1:], dtype=float)
    table = formula_table()
    np.testing.assert_array_equal(values[:, 0], table.target)
    np.testing.assert_array_equal(values[:, 1:].T, table.delivered)
    # every figure names its data, and every data file has a caption
    for names in lawformulas.DATA.values():
        assert all(name in lawformulas.CAPTIONS for name in names)
