"""notebooks/05_until_rest.ipynb runs top to bottom from a clean kernel."""

import re

from notebook_runner import run_notebook


def test_until_rest_notebook_runs_and_shows_the_sequences():
    notebook = run_notebook("05_until_rest.ipynb")
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "bounce_sequence: 8 contacts" in text  # the recursion and the package agree
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 6  # psi, two side-by-side sequences, the maps, rod sequences, rod maps
    # the rod: energy balanced, and the light striker's restitution as the closed form
    residuals = [float(line.rsplit(" ", 1)[1]) for line in text.splitlines() if "residual" in line]
    assert len(residuals) == 2
    assert max(residuals) < 1e-9
    line = next(line for line in text.splitlines() if line.startswith("alpha = 0.05"))
    _, exact, closed, _ = (float(v) for v in re.findall(r"\d+\.\d+", line))
    assert abs(exact - closed) < 1e-10
