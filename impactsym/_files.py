"""Atomic, recorded file writing for everything impactsym writes to disk.

Every file is written to a temporary name in its target directory (``.NAME.XXXX.partial``)
and renamed with :func:`os.replace` once it is complete, so that an interrupted run
never leaves a truncated file under a final name. A directory created by
``impactsym reproduce`` holds the marker file :data:`MARKER`; each file completed in it
inside :func:`recording` is recorded there, and a later ``--force`` run deletes only the
recorded files and its own temporary files (see :mod:`impactsym.reproduce` and
``docs/security.md``). Files written outside :func:`recording` (``impactsym export``
into the same directory, say) are never recorded.

Only regular files are ever replaced: a target that is a symbolic link, a directory, a
device, a FIFO or a socket is refused (:class:`UnsafeTargetError`), never followed or
replaced, and so is a read-only file; an existing file's permission bits are kept. The
marker is read with a bound (:data:`MARKER_MAX_BYTES`), so that no file planted under its
name can make a run slow.

This module sits on the ground floor so that both :mod:`impactsym.export` and
:mod:`impactsym.results` write through it.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
import secrets
import stat
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

#: Largest marker file :func:`read_marker` accepts, in bytes. A run records about a hundred
#: names of at most 255 bytes each (the longest file name most file systems allow); a
#: megabyte holds 4096 such names, a wide margin over any real marker.
MARKER_MAX_BYTES = 1 << 20

#: The directory whose marker records completed files (set by :func:`recording` only).
_RECORDING: contextvars.ContextVar[Path | None] = contextvars.ContextVar(
    "impactsym_recording", default=None
)


class UnsafeTargetError(OSError):
    """A file is not written (or a marker not read) because of what is at its path: a
    symbolic link, directory, device, FIFO or socket where a regular file belongs, a
    read-only file, or a marker larger than any that ``impactsym reproduce`` writes."""


def describe(mode: int) -> str:
    """What a file of mode ``mode`` (``os.lstat(path).st_mode``) is, in words.

    >>> describe(os.lstat(os.devnull).st_mode)
    'a character device'
    """
    kinds = (
        (stat.S_ISREG, "a regular file"),
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    return next((word for test, word in kinds if test(mode)), "not a regular file")


def check_target(path: str | Path) -> os.stat_result | None:
    """The status of the existing regular file ``path`` (``None`` if nothing is there), or
    :class:`UnsafeTargetError` if what is there must not be replaced.

    Refused: anything but a regular file (a symbolic link is looked at, never followed),
    and a regular file without any write permission or that the caller may not write
    (``os.access``), so that ``chmod 0400`` protects a file as it does against a shell's
    ``>`` (also for root, who could write it).

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> check_target(folder / "new.txt") is None
    True
    >>> check_target(folder)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    impactsym._files.UnsafeTargetError: refusing to write '...': it is a directory, ...
    """
    path = Path(path)
    try:
        status = os.lstat(path)
    except FileNotFoundError:
        return None
    if not stat.S_ISREG(status.st_mode):
        raise UnsafeTargetError(
            f"refusing to write {str(path)!r}: it is {describe(status.st_mode)}, not a "
            "regular file; impactsym replaces only regular files and never follows or "
            "replaces links, directories, devices or pipes: choose another file name"
        )
    if not status.st_mode & 0o222 or not os.access(path, os.W_OK):
        raise UnsafeTargetError(
            f"refusing to write {str(path)!r}: it is read-only (mode "
            f"{stat.S_IMODE(status.st_mode):04o}); make it writable or remove it first"
        )
    return status


def read_marker(directory: str | Path) -> bytes:
    """The bytes of the marker :data:`MARKER` in ``directory``, read with a bound.

    Raises ``FileNotFoundError`` if there is none, and :class:`UnsafeTargetError` naming
    the marker if it is not a regular file (a link is not followed, a FIFO not opened
    for a blocking read) or holds more than :data:`MARKER_MAX_BYTES` (no more than that
    is ever read).

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp())
    >>> _ = write_text(out / MARKER, MARKER_HEADER + "\\n")
    >>> read_marker(out).startswith(b"# written by impactsym reproduce")
    True
    """
    marker = Path(directory) / MARKER
    status = os.lstat(marker)
    if not stat.S_ISREG(status.st_mode):
        raise UnsafeTargetError(
            f"the marker file {str(marker)!r} is {describe(status.st_mode)}, not a regular "
            "file: it was not written by impactsym reproduce; nothing was deleted, choose a "
            "new directory"
        )
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    with os.fdopen(os.open(marker, flags), "rb") as handle:
        if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):  # swapped since lstat
            raise UnsafeTargetError(f"the marker file {str(marker)!r} is not a regular file")
        data = handle.read(MARKER_MAX_BYTES + 1)
    if len(data) > MARKER_MAX_BYTES:
        raise UnsafeTargetError(
            f"the marker file {str(marker)!r} holds more than {MARKER_MAX_BYTES} bytes, more "
            "than any impactsym reproduce writes: it was not written by impactsym reproduce "
            "or is damaged; nothing was deleted, choose a new directory"
        )
    return data


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
    removed and ``path`` is left as it was. ``path`` is checked by :func:`check_target`
    before the temporary file is made and again just before the rename: only a missing
    or a writable regular file is replaced, and the new file gets the permission bits
    (``rwx`` for owner, group, others) of the one it replaces; as root, also its owner.

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
    before = check_target(path)
    # a fresh name, created here (exclusively: nothing planted under it is followed) with
    # the usual permissions, or with those of the file it will replace
    tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}{PARTIAL}"
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    try:
        _copy_permissions(before, tmp)
        yield tmp
        now = check_target(path)
        if now is not None and (before is None or now.st_mode != before.st_mode):
            _copy_permissions(now, tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _record(path)


def _copy_permissions(status: os.stat_result | None, tmp: Path) -> None:
    """Give ``tmp`` the permission bits (and, as root, the owner) of ``status``."""
    if status is None:
        return
    os.chmod(tmp, stat.S_IMODE(status.st_mode) & 0o777)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        os.chown(tmp, status.st_uid, status.st_gid)


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
        or path.parent.resolve() != directory
    ):
        return
    try:
        line = path.name.encode("utf-8") + b"\n"
    except UnicodeEncodeError:  # a name that is not text: never recorded, never deleted
        return
    try:
        old = read_marker(path.parent)
    except FileNotFoundError:
        return
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
