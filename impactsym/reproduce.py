"""``impactsym reproduce``: regenerate every result of the package from nothing."""

from __future__ import annotations

import importlib
import shutil
import time
from collections.abc import Callable
from pathlib import Path

Progress = Callable[[str], None]

#: Analyses in the order they are reproduced: (name, module with a ``write`` function).
STEPS: tuple[tuple[str, str], ...] = (
    ("spring-damper contact (paper section 2)", "impactsym.results.contact"),
    ("multibody penalty contact (paper section 3)", "impactsym.results.multibody"),
)


class OutputExistsError(FileExistsError):
    """The output directory is not empty and ``force`` was not given."""


def prepare_output(out: Path, *, force: bool) -> Path:
    """Create ``out``; refuse a non-empty directory unless ``force`` (then empty it)."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputExistsError(f"output path {str(out)!r} exists and is not a directory")
    if out.is_dir() and any(out.iterdir()):
        if not force:
            raise OutputExistsError(
                f"output directory {str(out)!r} is not empty; pass --force to overwrite it"
            )
        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    return out


def reproduce(
    out: Path, *, quick: bool = False, force: bool = False, progress: Progress = print
) -> list[Path]:
    """Write all figures, tables and formulas of the package into ``out``.

    Returns the list of written files. ``quick`` uses coarser grids (for tests).
    """
    import matplotlib

    matplotlib.use("Agg")
    out = prepare_output(out, force=force)
    written: list[Path] = []
    start = time.perf_counter()
    for number, (title, module_name) in enumerate(STEPS, start=1):
        prefix = f"[{number}/{len(STEPS)}] {title}"
        progress(f"{prefix} ...")
        step_start = time.perf_counter()
        module = importlib.import_module(module_name)
        files = module.write(
            out, quick=quick, progress=lambda msg, p=prefix: progress(f"{p}: {msg}")
        )
        written.extend(files)
        progress(f"{prefix}: {len(files)} files in {time.perf_counter() - step_start:.1f} s")
    progress(
        f"wrote {len(written)} files to {out.resolve()} in {time.perf_counter() - start:.1f} s"
    )
    return written
