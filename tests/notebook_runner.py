"""Execute a notebook top to bottom in a clean kernel; compare or store its outputs.

The notebooks are committed with their outputs, so they show on any viewer and the
documentation site shows them without running them again. Each notebook's test executes
it (:func:`run_notebook`) and checks that the stored outputs are the ones the current code
prints (:func:`assert_outputs_current`). After a change that alters what a notebook
prints, store the new outputs with::

    python tests/notebook_runner.py 01_rod_impact.ipynb [...]   # or --all
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"

#: what a stored output must never contain: it would differ on every run or machine
UNSTABLE = {
    "memory address": re.compile(r"\b0x[0-9a-f]{6,}\b"),
    "timing": re.compile(r"\b\d+(\.\d+)? ?(s|ms|seconds)\b elapsed|\bin \d+\.\d+ s\b|\d+it/s"),
    "checkout path": re.compile(re.escape(str(ROOT))),
}


def run_notebook(name: str, timeout: int = 600) -> nbformat.NotebookNode:
    """Run ``notebooks/<name>`` (inline figures); raise on any cell error.

    The kernel imports ``impactsym`` from this checkout (its root first on
    ``PYTHONPATH``), not from whatever copy happens to be installed.
    """
    notebook = nbformat.read(NOTEBOOKS / name, as_version=4)
    client = NotebookClient(
        notebook,
        timeout=timeout,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
        record_timing=False,  # no timestamps in the stored notebook
    )
    previous = {key: os.environ.get(key) for key in ("PYTHONPATH", "MPLBACKEND")}
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), previous["PYTHONPATH"]]))
    os.environ.pop("MPLBACKEND", None)  # inline figures, whatever the calling shell chose
    try:
        client.execute()
    finally:
        for key, value in previous.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    return notebook


#: a float printed to 13 or more significant digits, or in e-notation at 1e-12 or below
_LONG_FLOAT = re.compile(r"(?<![\w.])-?\d+\.\d{12,}(?![\d])")
_TINY_FLOAT = re.compile(r"(?<![\w.])-?\d(\.\d+)?e-(1[2-9]|[2-9]\d|\d{3})\b")


def _stable(text: str | None) -> str | None:
    """``text`` with what differs between machines (the last bits of NumPy's vectorized
    ``exp``/``log``, which depend on the CPU) masked: a float printed to 13 or more
    significant digits is rounded to 11, and a number at 1e-12 or below (rounding-level
    residuals, e.g. "energy-balance residual 4.8e-14") becomes ``tiny``."""
    if text is None:
        return None
    text = _LONG_FLOAT.sub(lambda m: f"{float(m.group()):.11g}", text)
    return _TINY_FLOAT.sub("tiny", text)


def comparable_outputs(notebook: nbformat.NotebookNode) -> list[list[tuple]]:
    """Per code cell, its outputs as they are compared: stream text (consecutive chunks of
    one stream joined), the ``text/plain`` and ``text/latex`` of displayed data, and an
    image by its presence only (pixels differ between Matplotlib builds); in the texts,
    digits at the rounding level are masked (:func:`_stable`: they differ between CPUs)."""
    cells = []
    for cell in notebook.cells:
        if cell.cell_type != "code":
            continue
        outputs: list[tuple] = []
        for output in cell.outputs:
            kind = output.output_type
            if kind == "stream":
                if outputs and outputs[-1][0] == "stream" and outputs[-1][1] == output.name:
                    outputs[-1] = ("stream", output.name, outputs[-1][2] + _stable(output.text))
                else:
                    outputs.append(("stream", output.name, _stable(output.text)))
            elif kind in ("display_data", "execute_result"):
                data = output.get("data", {})
                images = tuple(sorted(k for k in data if k.startswith("image/")))
                text = tuple(_stable(data.get(k)) for k in ("text/plain", "text/latex"))
                outputs.append(("data", text, images))
            else:
                outputs.append((kind, output.get("ename"), output.get("evalue")))
        cells.append(outputs)
    return cells


def assert_outputs_current(name: str, executed: nbformat.NotebookNode) -> None:
    """The outputs stored in ``notebooks/<name>`` are those of ``executed`` (the notebook
    run from a clean kernel by the current code), cell by cell."""
    stored = nbformat.read(NOTEBOOKS / name, as_version=4)
    old, new = comparable_outputs(stored), comparable_outputs(executed)
    assert len(old) == len(new), f"{name}: the code cells changed since the outputs were stored"
    hint = f"store them anew: python tests/notebook_runner.py {name}"
    for index, (before, after) in enumerate(zip(old, new, strict=True)):
        assert before == after, f"{name}, code cell {index + 1}: stored outputs are stale; {hint}"


def unstable_outputs(notebook: nbformat.NotebookNode) -> list[str]:
    """Stored outputs that would differ between runs or machines (memory addresses,
    timings, this checkout's path), as ``"cell N: what"`` lines."""
    found = []
    for index, cell in enumerate(c for c in notebook.cells if c.cell_type == "code"):
        for output in cell.outputs:
            texts = [output.get("text", "")]
            texts += [v for k, v in output.get("data", {}).items() if k.startswith("text/")]
            for what, pattern in UNSTABLE.items():
                if any(pattern.search(text) for text in texts if isinstance(text, str)):
                    found.append(f"cell {index + 1}: {what}")
    return found


def store_outputs(name: str) -> None:
    """Execute ``notebooks/<name>`` from a clean kernel and write it back with its outputs
    (atomically); refuse outputs that would not be reproducible."""
    notebook = run_notebook(name)
    unstable = unstable_outputs(notebook)
    if unstable:
        raise SystemExit(f"{name}: unstable outputs, not stored: {unstable}")
    for cell in notebook.cells:
        cell.metadata.pop("execution", None)
    target = NOTEBOOKS / name
    fd, tmp = tempfile.mkstemp(dir=NOTEBOOKS, suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as stream:
        nbformat.write(notebook, stream)
    os.replace(tmp, target)


def main(argv: list[str]) -> None:
    names = sorted(p.name for p in NOTEBOOKS.glob("*.ipynb")) if argv == ["--all"] else argv
    if not names:
        raise SystemExit("usage: python tests/notebook_runner.py NAME.ipynb [...] | --all")
    for name in names:
        print(f"executing {name} ...", flush=True)
        store_outputs(name)


if __name__ == "__main__":
    main(sys.argv[1:])
