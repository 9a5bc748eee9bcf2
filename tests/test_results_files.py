"""The figure and table writers of ``impactsym reproduce`` (:mod:`impactsym.results.files`)."""

from __future__ import annotations

import csv

import matplotlib
import numpy as np

from impactsym.results.files import save_figure, write_csv, write_records

matplotlib.use("Agg")

MEGABYTE = 1_000_000


def test_a_mesh_heavy_pdf_stays_under_a_megabyte(tmp_path):
    # 600 x 500 cells drawn without rasterized=True (as a caller might), two meshes,
    # filled contours and a line: the writer rasterizes the meshes, the text stays text
    import matplotlib.pyplot as plt

    x, y = np.meshgrid(np.linspace(0, 1, 600), np.geomspace(1e-3, 1, 500))
    z = np.sin(40 * x) * np.cos(30 * np.log(y))
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    mesh = left.pcolormesh(x, y, z, shading="auto")
    left.pcolormesh(x, y, np.ma.masked_where(z < 0.9, z), shading="auto", cmap="Greys")
    right.contourf(x, y, z, levels=40)
    right.plot(x[0], 0.5 + 0.4 * np.sin(9 * x[0]), "k")
    fig.colorbar(mesh, ax=left, label="a label")
    paths = {p.suffix: p for p in save_figure(left, tmp_path, "mesh")}
    pdf = paths[".pdf"].read_bytes()
    assert len(pdf) < MEGABYTE
    assert b"/Subtype /Image" in pdf
    assert paths[".png"].stat().st_size > 0
    assert not plt.fignum_exists(fig.number)  # closed after saving


def test_the_same_figure_gives_the_same_pdf(tmp_path):
    import matplotlib.pyplot as plt

    def draw():
        _, ax = plt.subplots()
        ax.pcolormesh(np.arange(12.0).reshape(3, 4))
        return ax

    first = save_figure(draw(), tmp_path, "a")[1].read_bytes()
    second = save_figure(draw(), tmp_path, "b")[1].read_bytes()
    assert first == second


def test_tables_keep_17_digits_and_dict_rows(tmp_path):
    path = write_csv(tmp_path / "t.csv", ["x", "y"], [(0.1, 1 / 3)])
    with path.open() as handle:
        rows = list(csv.reader(handle))
    assert rows == [["x", "y"], ["0.10000000000000001", "0.33333333333333331"]]
    assert float(rows[1][1]) == 1 / 3
    path = write_records(tmp_path / "r.csv", ["a", "b"], [{"a": 1, "b": "two"}])
    assert path.read_text().splitlines() == ["a,b", "1,two"]
