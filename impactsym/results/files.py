"""File writing for ``impactsym reproduce`` and ``impactsym export``: atomic and recorded.

Every file is written to a temporary name in its target directory (``.NAME.XXXX.partial``)
and renamed with :func:`os.replace` once it is complete, so that an interrupted run
never leaves a truncated file under a final name. A directory created by
``impactsym reproduce`` holds the marker file :data:`MARKER`; each completed file
written into such a directory is recorded in it, and a later ``--force`` run deletes
only the recorded files (see :mod:`impactsym.reproduce`).
"""

from __future__ import annotations

import contextlib
import csv
import os
import secrets
from collections.abc import Iterator
from pathlib import Path

#: Name of the marker file ``impactsym reproduce`` keeps in its output directory.
MARKER = ".impactsym-reproduce"
#: First line of the marker file; the following lines name the files it wrote.
MARKER_HEADER = "# written by impactsym reproduce; --force deletes only the files listed here"
#: Suffix of temporary files (removed on failure or interrupt).
PARTIAL = ".partial"


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it to ``path`` when the block ends.

    If the block raises (including ``KeyboardInterrupt``) the temporary file is
    removed and ``path`` is left as it was.

    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "a.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text(), sorted(p.name for p in target.parent.iterdir())
    ('done', ['a.txt'])
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"directory {str(path.parent)!r} does not exist")
    # a fresh name, created by the writer itself so that it gets the usual permissions
    tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}{PARTIAL}"
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _record(path)


def _record(path: Path) -> None:
    """Add ``path`` to the marker of its directory, if that directory has one."""
    marker = path.parent / MARKER
    if path.name != MARKER and marker.is_file():
        with marker.open("a") as handle:
            handle.write(path.name + "\n")


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; return ``path``.

    >>> import tempfile
    >>> write_text(Path(tempfile.mkdtemp()) / "b.txt", "x").read_text()
    'x'
    """
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return path


def save_figure(ax, out: Path, stem: str) -> list[Path]:
    """Save the figure of ``ax`` as PNG and PDF (atomically), close it, return both paths."""
    import matplotlib.pyplot as plt

    fig = ax.figure
    try:
        fig.tight_layout()
        paths = [out / f"{stem}.png", out / f"{stem}.pdf"]
        for path in paths:
            with atomic_path(path) as tmp:
                # a fixed creation date keeps the PDF byte-for-byte reproducible
                fig.savefig(
                    tmp,
                    format=path.suffix[1:],
                    dpi=150,
                    metadata={"CreationDate": None} if path.suffix == ".pdf" else None,
                )
    finally:
        plt.close(fig)
    return paths


def write_csv(path: Path, header: list[str], rows) -> Path:
    """Write ``rows`` of numbers under ``header``, each with 17 significant digits."""
    return write_records(path, header, [[f"{v:.17g}" for v in row] for row in rows])


def write_records(path: Path, header: list[str], rows) -> Path:
    """Write ``rows`` (sequences, or dicts keyed by ``header``) as CSV, atomically."""
    path = Path(path)
    with atomic_path(path) as tmp, tmp.open("w", newline="") as handle:
        rows = list(rows)
        if rows and isinstance(rows[0], dict):
            writer = csv.DictWriter(handle, fieldnames=header)
            writer.writeheader()
        else:
            writer = csv.writer(handle)
            writer.writerow(header)
        writer.writerows(rows)
    return path
