"""notebooks/06_nonlinear_contact.ipynb runs top to bottom from a clean kernel, and what its
prose says about the printed numbers holds."""

import math
import re

from notebook_runner import assert_outputs_current, run_notebook

NAME = "06_nonlinear_contact.ipynb"


def test_nonlinear_contact_notebook_runs_and_its_prose_holds():
    notebook = run_notebook(NAME)
    assert_outputs_current(NAME, notebook)
    check_prose(notebook)


def check_prose(notebook):
    """What the notebook's text says about its printed numbers."""
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 4  # restitution curves, formula table, boundaries, bounces

    # "Every residual is 0"
    residuals = re.findall(r"damping number .* residual (\S+)$", text, re.M)
    assert residuals == ["0"] * 5
    # "All five deliver ... 0.5"; a pressing force lowers each restitution
    rows = re.findall(r"^(\S+)\s+\S+\s+[\d.]+\s+[\d.]+\s+[\d.]+\s+([\d.]+)$", text, re.M)
    assert [law for law, _ in rows] == [
        "linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"
    ]  # fmt: skip
    assert all(0.0 < float(e) < 0.5 for _, e in rows)
    assert len({e for _, e in rows}) == 5  # by different amounts

    # Hunt-Crossley: the closed form meets the integration
    assert "residual of the exit equation: 0" in text
    assert float(re.search(r"largest difference: (\S+)", text).group(1)) < 1e-10
    delivered = dict(re.findall(r"^(\S+)\s+asked 0.2, delivers ([\d.]+)", text, re.M))
    assert delivered == {
        "lankarani-nikravesh": "0.672", "hunt-crossley-1975": "0.547", "flores": "0.156"
    }  # fmt: skip
    assert "lambda v0 = 4.919" in text

    # "Asked for 0.5 the clipped contact gives 0.550"
    assert "(tensile force kept): e = 0.5000" in text
    assert "(tensile force cut): e = 0.5503" in text
    assert "asked 0.3: the clipped contact delivers 0.397" in text
    assert "asked 0.2: the clipped contact delivers 0.325" in text
    floor = float(re.search(r"lowest under-damped restitution with the cut: ([\d.]+)", text)[1])
    assert abs(floor - math.exp(-2)) < 1e-4
    alpha_dem = float(re.search(r"DEM alpha = ([\d.]+)", text)[1])
    alpha_cut = float(re.search(r"clipped contact, e = 0.5: alpha = ([\d.]+)", text)[1])
    assert alpha_cut > alpha_dem  # the clipped contact needs more damping

    # the boundaries: Hunt-Crossley's coincide, Tsuji sticks at f = 0 beyond sqrt(5)
    assert "Hunt-Crossley, both conditions the same boundary: True" in text
    assert "(position condition): [0.0, 0.0]" in text

    # "the time to rest is the constant-restitution one to a fraction of a percent";
    # the last contact sticks
    n_contacts = int(re.search(r"(\d+) contacts, sticks: True", text)[1])
    assert n_contacts > 10
    exact, rigid = (
        float(v) for v in re.search(r"time to rest ([\d.]+) s; .*: ([\d.]+) s", text).groups()
    )
    assert abs(exact / rigid - 1) < 1e-2
    first = re.search(r"first departure speeds: \[([\d., ]+)\]", text)[1].split(",")
    assert abs(float(first[0]) - 0.8) < 1e-3  # the designed 0.8 while gravity is negligible
    last = re.search(r"last departure speeds: \[([\d., ]+)\]", text)[1].split(",")
    assert float(last[-1]) == 0.0
