"""notebooks/05_until_rest.ipynb runs top to bottom from a clean kernel."""

from notebook_runner import run_notebook


def test_until_rest_notebook_runs_and_shows_the_sequences():
    notebook = run_notebook("05_until_rest.ipynb")
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "bounce_sequence: 8 contacts" in text  # the recursion and the package agree
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 4  # psi, two side-by-side sequences, the maps
