"""Generated documents for ``impactsym reproduce``: formulas.tex (and its PDF when a
LaTeX engine is installed) and the NumPy-only Python module."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable
from pathlib import Path

from impactsym.export import write_latex_document, write_python_module
from impactsym.results.files import atomic_path

CAPTIONS = {
    "formulas.tex": "Every formula the package derives, as a standalone LaTeX document "
    "(eq. (1), closed forms, eq. (2) and the N series, inverted terms, the spring-damper "
    "solution, ridge times, boundary equations, the reduced multibody equation).",
    "formulas.pdf": "The same document compiled with pdflatex.",
    "impactsym_numpy.py": "The rod time functions and the spring-damper contact functions, "
    "ridge times and boundary equations as a Python module that needs NumPy only.",
}


class LatexError(RuntimeError):
    """pdflatex failed on the generated document."""


def compile_latex(tex: Path, out_dir: Path) -> Path:
    """Compile ``tex`` with pdflatex (twice, for references); return the PDF path.

    Raises :class:`LatexError` with the end of the log when the engine reports an error.
    """
    engine = shutil.which("pdflatex")
    if engine is None:
        raise LatexError("pdflatex is not installed")
    with tempfile.TemporaryDirectory() as work:
        for _ in range(2):
            run = subprocess.run(
                [
                    engine,
                    "-interaction=nonstopmode",
                    "-halt-on-error",
                    "-output-directory",
                    work,
                    str(tex.resolve()),
                ],
                capture_output=True,
                text=True,
                check=False,
                stdin=subprocess.DEVNULL,
                env={**os.environ, "SOURCE_DATE_EPOCH": "0", "FORCE_SOURCE_DATE": "1"},
            )
            if run.returncode != 0:
                raise LatexError(f"pdflatex failed on {tex.name}:\n{run.stdout[-3000:]}")
        pdf = out_dir / tex.with_suffix(".pdf").name
        with atomic_path(pdf) as tmp:
            shutil.copyfile(Path(work) / pdf.name, tmp)
    return pdf


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write formulas.tex (+ formulas.pdf with pdflatex) and impactsym_numpy.py."""
    progress("LaTeX document of all formulas")
    tex = write_latex_document(out / "formulas.tex")
    files = [tex]
    if shutil.which("pdflatex"):
        progress("compiling formulas.tex with pdflatex")
        files.append(compile_latex(tex, out))
    else:
        progress("pdflatex not found: formulas.tex written, not compiled")
    progress("NumPy-only Python module")
    files.append(write_python_module(out / "impactsym_numpy.py"))
    return files
