"""notebooks/02_spring_damper_contact.ipynb runs top to bottom from a clean kernel."""

from notebook_runner import run_notebook


def test_spring_damper_notebook_runs_and_shows_the_boundary():
    notebook = run_notebook("02_spring_damper_contact.ipynb")
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "D*_force = inf" in text  # the f = 0 limit is printed
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 3  # Fig. 1a, Fig. 1b, the four maps
