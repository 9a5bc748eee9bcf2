"""The multibody step of ``impactsym reproduce`` (:mod:`impactsym.results.multibody`)."""

from __future__ import annotations

import json
import subprocess
import sys

from impactsym.results.multibody import DATA
from impactsym.results.report import data_files


def test_reproduce_step_writes_its_files_without_scipy(tmp_path):
    # `impactsym reproduce` must not need SciPy: block it and run the quick step
    code = (
        "import sys; sys.modules['scipy'] = None\n"
        "import matplotlib; matplotlib.use('Agg')\n"
        "from pathlib import Path\n"
        "from impactsym.results.multibody import write\n"
        f"files = write(Path({str(tmp_path)!r}), quick=True, progress=lambda m: None)\n"
        "print('\\n'.join(sorted(p.name for p in files)))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    names = set(run.stdout.split())
    for png in sorted(n for n in names if n.endswith(".png")):  # the report links its data
        assert data_files(png[: -len(".png")], DATA, names), png
    for stem in (
        "multibody_agreement",
        "multibody_verdict_map",
        "multibody_convergence",
        "multibody_design",
    ):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert {
        "multibody_agreement.csv",
        "multibody_summary.json",
        "multibody_reduced_equation.tex",
    } <= names
    pdfs = list(tmp_path.glob("*.pdf"))
    assert len(pdfs) == 4
    assert all(pdf.stat().st_size < 1_000_000 for pdf in pdfs)  # figures worth their bytes
    summary = json.loads((tmp_path / "multibody_summary.json").read_text())
    assert {row["system"] for row in summary["agreement"]} == {"bar", "pendulum"}
    assert "\\tilde m" in (tmp_path / "multibody_reduced_equation.tex").read_text()
