"""``impactsym reproduce``: regenerate every result of the package from nothing."""

from __future__ import annotations

import importlib
import os
import stat
import time
from collections.abc import Callable
from pathlib import Path

from impactsym.results.files import (
    MARKER,
    MARKER_HEADER,
    UnsafeTargetError,
    describe,
    is_partial,
    read_marker,
    recording,
    write_text,
)

Progress = Callable[[str], None]

#: Analyses in the order they are reproduced: (name, module with a ``write`` function).
STEPS: tuple[tuple[str, str], ...] = (
    ("rod impact (paper section 1)", "impactsym.results.rod"),
    ("spring-damper contact (paper section 2)", "impactsym.results.contact"),
    ("multibody penalty contact (paper section 3)", "impactsym.results.multibody"),
    ("bounce sequences until rest", "impactsym.results.bounce"),
    ("nonlinear contact laws: stick boundaries, restitution", "impactsym.results.laws"),
    ("what the usual damping design formulas deliver", "impactsym.results.lawformulas"),
    (
        "rod impact until rest (contacts, flights, fixed-end stress)",
        "impactsym.results.rod_sequence",
    ),
    ("engine parameters (MuJoCo, LAMMPS)", "impactsym.results.engines"),
    (
        "the engines side by side (MuJoCo, LAMMPS, Drake, PyBullet)",
        "impactsym.results.engines_side_by_side",
    ),
    ("formulas and exported functions", "impactsym.results.documents"),
)


class OutputExistsError(FileExistsError):
    """The output directory is not empty and ``force`` was not given."""


class UnsafeOutputError(ValueError):
    """The output directory is one that ``reproduce`` must never write into or empty."""


def check_output(out: str | Path) -> Path:
    """The absolute output directory, or :class:`UnsafeOutputError` for a protected one.

    Refused: an empty name, the current directory and its parents, the home directory
    and its parents, the file system root, and the directory of the ``impactsym``
    package, its parents and anything inside it. Nothing is created or deleted here.

    >>> check_output("")
    Traceback (most recent call last):
        ...
    impactsym.reproduce.UnsafeOutputError: the output directory must be named, got ''
    >>> check_output(".")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    impactsym.reproduce.UnsafeOutputError: refusing to use ... it is the current directory; ...
    """
    if not isinstance(out, (str, os.PathLike)):
        raise TypeError(f"out must be a path, got {out!r}")
    if not str(out).strip():
        raise UnsafeOutputError(f"the output directory must be named, got {str(out)!r}")
    path = Path(out).expanduser().resolve()
    cwd = Path.cwd().resolve()
    home = Path.home().expanduser().resolve()
    package = Path(__file__).resolve().parent
    reasons = (
        (path == Path(path.anchor), "the file system root"),
        (path == cwd, "the current directory"),
        (path in cwd.parents, "a parent of the current directory"),
        (path == home or path in home.parents, "the home directory or one of its parents"),
        (path in package.parents, "a parent of the impactsym package"),
        (path == package or package in path.parents, "inside the impactsym package"),
    )
    for refused, reason in reasons:
        if refused:
            raise UnsafeOutputError(
                f"refusing to use {str(path)!r} as output directory: it is {reason}; "
                "name a new or former reproduce output directory"
            )
    return path


def _recorded(out: Path) -> list[str]:
    """Names of the files a former run recorded in the marker of ``out``.

    Only plain names inside ``out`` count; a marker that is not UTF-8 text, not a regular
    file or larger than :data:`impactsym.results.files.MARKER_MAX_BYTES` was not written
    by ``reproduce`` (or is damaged) and is refused before anything is deleted.
    """
    try:
        lines = read_marker(out).decode("utf-8").splitlines()
    except UnsafeTargetError as exc:
        raise OutputExistsError(str(exc)) from None
    except UnicodeDecodeError:
        raise OutputExistsError(
            f"the marker file {str(out / MARKER)!r} is not UTF-8 text: it was not written "
            "by impactsym reproduce or is damaged; nothing was deleted, choose a new "
            "directory"
        ) from None
    return [n for n in lines[1:] if n and "/" not in n and "\\" not in n and n not in (".", "..")]


def prepare_output(out: str | Path, *, force: bool) -> Path:
    """Check ``out`` (:func:`check_output`), create it and its marker file.

    A non-empty ``out`` is refused unless it holds the marker :data:`MARKER` of a
    former run and ``force`` is given; then the files that run recorded (and its
    temporary files, named as :data:`impactsym.results.files.PARTIAL_NAME`) are deleted,
    nothing else. Nothing is followed or replaced that is not a regular file: ``out``
    must be a directory (not a symbolic link to one), the marker a regular file, and
    every recorded name that still exists a regular file; otherwise nothing is deleted.

    >>> import tempfile
    >>> out = prepare_output(Path(tempfile.mkdtemp()) / "new", force=False)
    >>> with recording(out):
    ...     _ = write_text(out / "x.txt", "1")
    >>> prepare_output(out, force=False)
    Traceback (most recent call last):
        ...
    impactsym.reproduce.OutputExistsError: output directory ... is not empty; pass --force ...
    >>> sorted(p.name for p in prepare_output(out, force=True).iterdir())
    ['.impactsym-reproduce']
    >>> user = Path(tempfile.mkdtemp())
    >>> _ = (user / "thesis.tex").write_text("mine")
    >>> prepare_output(user, force=True)
    Traceback (most recent call last):
        ...
    impactsym.reproduce.OutputExistsError: ... was not written by impactsym reproduce ...
    """
    given, out = Path(out).expanduser(), check_output(out)
    if given.is_symlink():
        raise OutputExistsError(
            f"output path {str(given)!r} is a symbolic link (to {str(out)!r}); reproduce "
            "never follows one: name the directory itself"
        )
    if out.exists() and not out.is_dir():
        raise OutputExistsError(
            f"output path {str(out)!r} exists and is {describe(os.lstat(out).st_mode)}, "
            "not a directory"
        )
    if out.is_dir() and any(out.iterdir()):
        try:
            marker = os.lstat(out / MARKER).st_mode
        except FileNotFoundError:
            raise OutputExistsError(
                f"output directory {str(out)!r} is not empty and was not written by "
                f"impactsym reproduce (no {MARKER} file); it is never overwritten, not even "
                "with --force: choose a new directory"
            ) from None
        if not stat.S_ISREG(marker):
            raise OutputExistsError(
                f"the marker file {str(out / MARKER)!r} is {describe(marker)}, not a regular "
                "file: it was not written by impactsym reproduce; nothing was deleted, "
                "choose a new directory"
            )
        if not force:
            raise OutputExistsError(
                f"output directory {str(out)!r} is not empty; pass --force to overwrite it"
            )
        # everything is checked before anything is deleted: recorded regular files and
        # reproduce's own temporary files only
        doomed = [path for path in map(out.joinpath, _recorded(out)) if _regular(path)]
        doomed += [path for path in out.iterdir() if is_partial(path)]
        for path in dict.fromkeys(doomed):
            path.unlink(missing_ok=True)
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / MARKER, MARKER_HEADER + "\n")
    return out


def _regular(path: Path) -> bool:
    """Whether ``path`` is a regular file (``False`` if absent); refuse anything else."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return False
    if not stat.S_ISREG(mode):
        raise OutputExistsError(
            f"{str(path)!r}, recorded as written by impactsym reproduce, is now "
            f"{describe(mode)}; reproduce never follows or replaces one: remove it yourself "
            "or choose a new directory (nothing was deleted)"
        )
    return True


def reproduce(
    out: str | Path, *, quick: bool = False, force: bool = False, progress: Progress = print
) -> list[Path]:
    """Write all figures, tables and formulas of the package into ``out``.

    Returns the list of written files. ``quick`` uses coarser grids (for tests).
    ``out`` is checked by :func:`prepare_output` before anything is written or deleted;
    every file is written under a temporary name and renamed when complete.
    """
    import matplotlib

    matplotlib.use("Agg")
    out = prepare_output(out, force=force)
    with recording(out):
        return _reproduce_into(out, quick=quick, progress=progress)


def _reproduce_into(out: Path, *, quick: bool, progress: Progress) -> list[Path]:
    """The steps of :func:`reproduce` into the prepared directory ``out``.

    Each step's module gives the captions of its files (``captions(out)`` after it wrote
    them, for captions that depend on what was run, else ``CAPTIONS``) and the data
    files behind each figure (``DATA``) for the report.
    """
    written: list[Path] = []
    captions: dict[str, str] = {}
    data: dict[str, tuple[str, ...]] = {}
    sections: list[tuple[str, list[Path]]] = []
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
        sections.append((title, list(files)))
        if hasattr(module, "captions"):
            captions.update(module.captions(out))
        else:
            captions.update(getattr(module, "CAPTIONS", {}))
        data.update(getattr(module, "DATA", {}))
        progress(f"{prefix}: {len(files)} files in {time.perf_counter() - step_start:.1f} s")
    written += write_report(out, written, captions, sections=sections, data=data)
    progress(
        f"wrote {len(written)} files to {out.resolve()} in {time.perf_counter() - start:.1f} s"
    )
    return written


def write_report(
    out: Path,
    files: list[Path],
    captions: dict[str, str],
    *,
    sections: list[tuple[str, list[Path]]] | None = None,
    data: dict[str, tuple[str, ...]] | None = None,
) -> list[Path]:
    """``report.md`` and ``index.html``: every figure shown with its sentence and links to
    its PDF and data, every table rendered, every other file listed with its sentence (no
    timings or dates: reruns are identical); see :mod:`impactsym.results.report`."""
    from impactsym.results import report

    return report.write_report(out, files, captions, sections=sections, data=data)
