"""notebooks/02_spring_damper_contact.ipynb runs top to bottom from a clean kernel, and
what its prose says about the printed numbers holds."""

import re

from notebook_runner import assert_outputs_current, run_notebook


def test_spring_damper_notebook_runs_and_shows_the_boundary():
    notebook = run_notebook("02_spring_damper_contact.ipynb")
    assert_outputs_current("02_spring_damper_contact.ipynb", notebook)
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "D*_force = inf" in text  # the f = 0 limit is printed
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 3  # Fig. 1a, Fig. 1b, the four maps
    # "the ratios of the computed boundaries to these asymptotes tend to one"
    ratios = re.findall(
        r"f = +([\d.e+-]+): \(1 - D\*_position\) / asymptote = ([\d.]+),"
        r"  D\*_force / asymptote = ([\d.]+)",
        text,
    )
    assert len(ratios) == 5
    position, force = ([float(row[i]) for row in ratios] for i in (1, 2))
    assert abs(position[-1] - 1) < 0.05
    assert abs(force[-1] - 1) < 1e-6
    assert abs(force[0] - 1) > abs(force[-1] - 1)
