"""notebooks/03_multibody_penalty.ipynb runs top to bottom from a clean kernel, and what
its prose says about the printed numbers holds."""

import re

from notebook_runner import assert_outputs_current, run_notebook


def test_multibody_notebook_runs_and_shows_agreement_and_design():
    notebook = run_notebook("03_multibody_penalty.ipynb")
    assert_outputs_current("03_multibody_penalty.ipynb", notebook)
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "bar      impulse    position" in text  # the agreement table is printed
    assert "full simulation: t_c = 2.0" in text  # the design is checked by simulation
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 4
    # the prose's claims, against the numbers the cells print
    assert "m~ at 30 degrees: 4*m/13" in text
    assert "better everywhere: True" in text  # impulse projection, both systems and conditions
    slopes = {
        title: tuple(map(float, rest))
        for title, *rest in re.findall(
            r"^(falling bar|double pendulum): paper/impulse error ratio ([\d.]+) to ([\d.]+); "
            r"slopes: impulse ([\d.-]+), paper ([\d.-]+)$",
            text,
            flags=re.M,
        )
    }
    low, _, impulse, paper = slopes["falling bar"]
    assert low > 3  # "several times more accurate at every stiffness"
    assert abs(impulse + 1) < 0.2
    assert abs(paper + 1) < 0.2  # "both errors fall only as omega0^-1"
    low, _, impulse, paper = slopes["double pendulum"]
    assert low < 1  # "briefly the smaller one" at the soft end
    assert abs(impulse + 2) < 0.3  # "falls as omega0^-2"
    assert -1.2 < paper < -0.5  # "more slowly, approaching -1"
    assert "paper error changes sign" in text
