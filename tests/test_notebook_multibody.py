"""notebooks/03_multibody_penalty.ipynb runs top to bottom from a clean kernel."""

from notebook_runner import run_notebook


def test_multibody_notebook_runs_and_shows_agreement_and_design():
    notebook = run_notebook("03_multibody_penalty.ipynb")
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "bar      impulse    position" in text  # the agreement table is printed
    assert "full simulation: t_c = 2.0" in text  # the design is checked by simulation
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 4
