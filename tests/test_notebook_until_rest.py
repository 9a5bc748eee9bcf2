"""notebooks/05_until_rest.ipynb runs top to bottom from a clean kernel, and what its
prose says about the printed numbers holds."""

import math
import re

from notebook_runner import assert_outputs_current, run_notebook


def test_until_rest_notebook_runs_and_shows_the_sequences():
    notebook = run_notebook("05_until_rest.ipynb")
    assert_outputs_current("05_until_rest.ipynb", notebook)
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "bounce_sequence: 8 contacts" in text  # the recursion and the package agree
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 6  # psi, two side-by-side sequences, the maps, rod sequences, rod maps
    # the rod: energy balanced, and the light striker's restitution as the closed form
    residuals = [
        float(line.rsplit(" ", 1)[1])
        for line in text.splitlines()
        if "energy-balance residual" in line
    ]
    assert len(residuals) == 4  # two rigid, two finite-kappa sequences
    assert max(residuals) < 1e-9
    line = next(line for line in text.splitlines() if line.startswith("alpha = 0.05"))
    _, exact, closed, _ = (float(v) for v in re.findall(r"\d+\.\d+", line))
    assert abs(exact - closed) < 1e-10
    # "the element can even catch the body from behind": v* < 0 at a contact after the first
    behind = re.search(r"contact (\d+) starts with the body moving away: v\* = ([\d.-]+)", text)
    assert int(behind.group(1)) > 1
    assert float(behind.group(2)) < 0
    # the light striker "loses a sizeable part of its speed": 1 - 2/e, about a quarter
    loss = float(re.search(r"light striker: loses ([\d.]+)% of its speed", text).group(1))
    assert 20 < loss < 30
    assert abs(loss / 100 - (1 - 2 / math.e)) < 1e-3
    # "from a mass ratio of order one on a second contact can start"
    counts = [
        int(c) for c in re.search(r"contacts per alpha: \[([\d, ]+)\]", text).group(1).split(",")
    ]
    assert len(counts) == 25
    assert counts[0] == 1  # the light striker: one contact
    assert max(counts) >= 2
    assert 0.3 < float(re.search(r"second contact: ([\d.]+)", text).group(1)) < 3
    # "the stress there exceeds the impact stress"
    light_ratio, heavy_ratio = (
        float(v)
        for v in re.search(r"impact stress: ([\d.]+) \(alpha = 0.05\), ([\d.]+)", text).groups()
    )
    assert light_ratio > 1
    assert heavy_ratio > 1

    # section 7: a stiff contact spring approaches the rigid restitution like 1/kappa
    rigid = float(re.search(r"f = 0: restitution ([\d.]+)", text).group(1))
    rows = re.findall(r"kappa = (\S+): restitution ([\d.]+), kappa x error ([-\d.]+)", text)
    kappas, errors = [float(r[0]) for r in rows], [float(r[1]) - rigid for r in rows]
    assert kappas == [1e2, 1e3, 1e4]
    assert abs(errors[0]) > abs(errors[1]) > abs(errors[2]) > 0
    scaled = [k * e for k, e in zip(kappas, errors, strict=True)]
    assert abs(scaled[2] / scaled[1] - 1) < 0.05  # "settles to a constant"
