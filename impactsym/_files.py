"""Atomic, recorded file writing for everything impactsym writes to disk.

Every file is written to a temporary name in its target directory (``.NAME.XXXX.partial``)
and renamed with :func:`os.replace` once it is complete, so that an interrupted run
never leaves a truncated file under a final name. A directory created by
``impactsym reproduce`` holds the marker file :data:`MARKER`; each file completed in it
inside :func:`recording` is recorded there, and a later ``--force`` run deletes only the
recorded files and its own temporary files (see :mod:`impactsym.reproduce` and
``docs/security.md``). Files written outside :func:`recording` (``impactsym export``
into the same directory, say) are never recorded.

This module sits on the ground floor so that both :mod:`impactsym.export` and
:mod:`impactsym.results` write through it.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
import secrets
from collections.abc import Iterator
from pathlib import Path

#: Name of the marker file ``impactsym reproduce`` keeps in its output directory.
MARKER = ".impactsym-reproduce"
#: First line of the marker file; the following lines name the files it wrote.
MARKER_HEADER = "# written by impactsym reproduce; --force deletes only the files listed here"
#: Suffix of temporary files (removed on failure or interrupt).
PARTIAL = ".partial"
#: The names :func:`atomic_path` gives its temporary files, ``.NAME.<pid>.<8 hex>.partial``.
PARTIAL_NAME = re.compile(r"\..+\.[0-9]+\.[0-9a-f]{8}" + re.escape(PARTIAL), re.DOTALL)

#: The directory whose marker records completed files (set by :func:`recording` only).
_RECORDING: contextvars.ContextVar[Path | None] = contextvars.ContextVar(
    "impactsym_recording", default=None
)


def is_partial(path: str | Path) -> bool:
    """Whether ``path`` is a temporary file :func:`atomic_path` left: a regular file (not
    a symbolic link or directory) under a name of the form :data:`PARTIAL_NAME`.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> ours, users = folder / ".a.txt.123.0123abcd.partial", folder / ".draft.partial"
    >>> _ = ours.write_text(""), users.write_text("")
    >>> is_partial(ours), is_partial(users)
    (True, False)
    """
    path = Path(path)
    return PARTIAL_NAME.fullmatch(path.name) is not None and (
        path.is_file() and not path.is_symlink()
    )


@contextlib.contextmanager
def recording(out: str | Path) -> Iterator[None]:
    """Within this block, files completed in directory ``out`` are recorded in its marker.

    Only ``impactsym reproduce`` opens this block; files written elsewhere, or outside
    the block, are never recorded (so ``--force`` never deletes them).

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp())
    >>> _ = write_text(out / MARKER, MARKER_HEADER + "\\n")
    >>> _ = write_text(out / "not_recorded.txt", "x")
    >>> with recording(out):
    ...     _ = write_text(out / "recorded.txt", "x")
    >>> (out / MARKER).read_text().splitlines()[1:]
    ['recorded.txt']
    """
    token = _RECORDING.set(Path(out).resolve())
    try:
        yield
    finally:
        _RECORDING.reset(token)


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
    """Add ``path`` to the marker of its directory if :func:`recording` that directory.

    The marker is rewritten whole under a temporary name and renamed, so that it never
    holds a torn line; a name that cannot be one line is not recorded (and so never
    deleted).
    """
    directory = _RECORDING.get()
    marker = path.parent / MARKER
    if (
        directory is None
        or path.name == MARKER
        or "\n" in path.name
        or "\r" in path.name
        or not marker.is_file()
        or path.parent.resolve() != directory
    ):
        return
    try:
        line = path.name.encode("utf-8") + b"\n"
    except UnicodeEncodeError:  # a name that is not text: never recorded, never deleted
        return
    old = marker.read_bytes()
    if old and not old.endswith(b"\n"):
        old += b"\n"
    with atomic_path(marker) as tmp:
        tmp.write_bytes(old + line)


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; return ``path``.

    >>> import tempfile
    >>> write_text(Path(tempfile.mkdtemp()) / "b.txt", "x").read_text()
    'x'
    """
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path
