"""The notebooks are committed with their outputs, from one clean run, and derive.

Fast checks of the stored notebooks, without running them: every code cell ran once, in
order, from a clean kernel; nothing failed; no output would differ between runs or
machines (memory addresses, timings, a checkout's path); each notebook shows SymPy
derivation steps as typeset output and at least one figure. Whether the stored outputs are
those of the current code is checked by each notebook's own test, which executes it
(``assert_outputs_current`` in ``tests/notebook_runner.py``).
"""

from __future__ import annotations

import nbformat
import pytest
from notebook_runner import NOTEBOOKS, comparable_outputs, unstable_outputs

NAMES = sorted(path.name for path in NOTEBOOKS.glob("*.ipynb"))


def load(name: str) -> nbformat.NotebookNode:
    return nbformat.read(NOTEBOOKS / name, as_version=4)


def test_there_are_seven_notebooks():
    assert len(NAMES) == 7


@pytest.mark.parametrize("name", NAMES)
def test_notebooks_are_stored_executed_from_a_clean_kernel(name):
    notebook = load(name)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    # one run, top to bottom, from a clean kernel: execution counts 1, 2, 3, ...
    assert [cell.execution_count for cell in code] == list(range(1, len(code) + 1))
    assert not [o for cell in code for o in cell.outputs if o.output_type == "error"]
    assert unstable_outputs(notebook) == []
    assert not [cell for cell in code if "execution" in cell.metadata]  # no timestamps


@pytest.mark.parametrize("name", NAMES)
def test_notebooks_show_derivations_and_figures(name):
    outputs = [o for cell in comparable_outputs(load(name)) for o in cell]
    typeset = [o for o in outputs if o[0] == "data" and o[1][1]]  # text/latex
    figures = [o for o in outputs if o[0] == "data" and "image/png" in o[2]]
    assert len(typeset) >= 2, f"{name}: fewer than two typeset SymPy outputs"
    assert figures, f"{name}: no figure stored"


def test_comparison_sees_a_changed_number_but_not_a_changed_picture():
    notebook = load(NAMES[0])
    before = comparable_outputs(notebook)
    for cell in notebook.cells:
        for output in getattr(cell, "outputs", []):
            if "image/png" in output.get("data", {}):
                output.data["image/png"] = "AAAA"  # other pixels: still current
    assert comparable_outputs(notebook) == before
    stream = next(
        o for cell in notebook.cells for o in getattr(cell, "outputs", []) if o.get("text")
    )
    stream.text = stream.text.replace("0", "1", 1) + " "
    assert comparable_outputs(notebook) != before


def test_comparison_masks_only_rounding_level_digits():
    from notebook_runner import _stable

    # the last bits of a 17-digit float and a rounding-level residual differ between
    # CPUs: masked; an ordinary printed figure is not
    assert _stable("(4.099689860596786, 2.0)") == _stable("(4.099689860596872, 2.0)")
    assert _stable("residual 4.8e-14") == _stable("residual 6.1e-14") == "residual tiny"
    assert _stable("e = 0.4997 at dt 2e-3") == "e = 0.4997 at dt 2e-3"
    assert _stable("(4.0996898606, 1)") != _stable("(4.0996898616, 1)")
    assert _stable("error 1.5e-08") != _stable("error 2.5e-08")
