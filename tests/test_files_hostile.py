"""Hostile file-system probes of the writers (:mod:`impactsym._files`, ``impactsym export``,
``impactsym reproduce``): what is at a target path is never followed or replaced unless it
is a writable regular file, permissions are kept, and the marker is read with a bound.

Every probe builds its targets under ``tmp_path`` (FIFOs, symbolic links, read-only files,
a device node where ``mknod`` is allowed) and checks them afterwards with ``os.lstat``,
independently of the code under test.
"""

from __future__ import annotations

import os
import socket
import stat
import time
from pathlib import Path

import pytest

import impactsym.export
from impactsym._files import (
    MARKER,
    MARKER_HEADER,
    MARKER_MAX_BYTES,
    PARTIAL,
    UnsafeTargetError,
    atomic_path,
    check_target,
    recording,
    write_text,
)
from impactsym.cli import main
from impactsym.reproduce import OutputExistsError, prepare_output


@pytest.fixture
def cheap_export(monkeypatch):
    """``impactsym export`` with a one-line module and document (the writer is under test)."""
    monkeypatch.setattr(impactsym.export, "python_module", lambda: "X = 1\n")
    monkeypatch.setattr(impactsym.export, "latex_document", lambda n_terms=3: "% tex\n")


def _mode(path: Path) -> int:
    return os.lstat(path).st_mode


def _leftovers(folder: Path) -> list[str]:
    return [p.name for p in folder.iterdir() if p.name.endswith(PARTIAL)]


@pytest.mark.parametrize("kind", ["python", "latex"])
def test_export_onto_a_fifo_is_refused_and_the_fifo_stays(tmp_path, capsys, cheap_export, kind):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    assert main(["export", kind, str(fifo)]) == 2
    err = capsys.readouterr().err
    assert str(fifo) in err
    assert "FIFO" in err
    assert "refusing" in err
    assert stat.S_ISFIFO(_mode(fifo))
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("kind", ["python", "latex"])
def test_export_onto_a_symlink_neither_follows_nor_replaces_it(
    tmp_path, capsys, cheap_export, kind
):
    precious = tmp_path / "precious.txt"
    precious.write_text("the user's data")
    link = tmp_path / "out.py"
    link.symlink_to(precious)
    dangling = tmp_path / "dangling.py"
    dangling.symlink_to(tmp_path / "nowhere")
    for target in (link, dangling):
        assert main(["export", kind, str(target)]) == 2
        err = capsys.readouterr().err
        assert str(target) in err
        assert "symbolic link" in err
        assert stat.S_ISLNK(_mode(target))
    assert os.readlink(link) == str(precious)
    assert precious.read_text() == "the user's data"
    assert not (tmp_path / "nowhere").exists()
    assert _leftovers(tmp_path) == []


def test_export_onto_a_read_only_file_is_refused_and_keeps_it(tmp_path, capsys, cheap_export):
    # refused for every user, root included (root could write it, but 0400 says: do not)
    target = tmp_path / "paper.tex"
    target.write_text("the author's final version")
    target.chmod(0o400)
    assert main(["export", "latex", str(target)]) == 2
    err = capsys.readouterr().err
    assert str(target) in err
    assert "read-only" in err
    assert "0400" in err
    assert stat.S_IMODE(_mode(target)) == 0o400
    assert target.read_text() == "the author's final version"
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("mode", [0o600, 0o640, 0o664, 0o700, 0o200])
def test_an_existing_files_permission_bits_are_kept(tmp_path, cheap_export, mode):
    target = tmp_path / "module.py"
    target.write_text("old")
    target.chmod(mode)
    assert main(["export", "python", str(target)]) == 0
    assert stat.S_ISREG(_mode(target))
    assert stat.S_IMODE(_mode(target)) == mode
    target.chmod(0o600)
    assert target.read_text() == "X = 1\n"


def test_setuid_bits_are_not_carried_over(tmp_path):
    target = tmp_path / "tool"
    target.write_text("old")
    target.chmod(0o4755)
    write_text(target, "new")
    assert stat.S_IMODE(_mode(target)) == 0o755


def test_a_new_file_gets_the_usual_permissions(tmp_path):
    umask = os.umask(0o027)
    try:
        write_text(tmp_path / "new.txt", "x")
    finally:
        os.umask(umask)
    assert stat.S_IMODE(_mode(tmp_path / "new.txt")) == 0o640


def test_a_directory_at_the_target_is_refused(tmp_path, capsys, cheap_export):
    folder = tmp_path / "formulas.tex"
    folder.mkdir()
    (folder / "inside").write_text("kept")
    assert main(["export", "latex", str(folder)]) == 2
    assert "is a directory" in capsys.readouterr().err
    assert (folder / "inside").read_text() == "kept"


def test_a_device_node_is_refused_and_stays(tmp_path):
    device = tmp_path / "null"
    try:
        os.mknod(device, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except (PermissionError, AttributeError):
        pytest.skip("creating a device node needs privileges here")
    with pytest.raises(UnsafeTargetError, match="character device"):
        write_text(device, "x")
    assert stat.S_ISCHR(_mode(device))
    assert os.major(os.lstat(device).st_rdev) == 1


def test_a_socket_is_refused_and_stays(tmp_path):
    path = tmp_path / "s"
    if len(str(path)) > 100:
        pytest.skip("tmp_path too long for a Unix socket name")
    server = socket.socket(socket.AF_UNIX)
    try:
        server.bind(str(path))
        with pytest.raises(UnsafeTargetError, match="socket"):
            write_text(path, "x")
        assert stat.S_ISSOCK(_mode(path))
    finally:
        server.close()


def test_a_fifo_swapped_in_while_writing_is_not_replaced(tmp_path):
    target = tmp_path / "table.csv"

    def write_while_a_fifo_appears():
        with atomic_path(target) as tmp:
            tmp.write_text("new")
            os.mkfifo(target)  # appears between the first check and the rename

    with pytest.raises(UnsafeTargetError, match="FIFO"):
        write_while_a_fifo_appears()
    assert stat.S_ISFIFO(_mode(target))
    assert _leftovers(tmp_path) == []


def test_a_link_planted_under_a_temporary_name_is_never_written_through(tmp_path, monkeypatch):
    import impactsym._files as files

    victim = tmp_path / "victim.txt"
    victim.write_text("untouched")
    monkeypatch.setattr(files.secrets, "token_hex", lambda n: "0123abcd")
    (tmp_path / f".a.txt.{os.getpid()}.0123abcd{PARTIAL}").symlink_to(victim)
    with pytest.raises(FileExistsError):
        write_text(tmp_path / "a.txt", "x")
    assert victim.read_text() == "untouched"


def test_check_target_accepts_only_missing_or_writable_regular_files(tmp_path):
    assert check_target(tmp_path / "absent") is None
    (tmp_path / "f").write_text("x")
    assert stat.S_ISREG(check_target(tmp_path / "f").st_mode)


# ---- reproduce: its output directory, its recorded files and its marker ----


def test_reproduce_refuses_an_output_directory_given_as_a_symlink(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "link"
    link.symlink_to(real)
    with pytest.raises(OutputExistsError, match="symbolic link"):
        prepare_output(link, force=True)
    assert list(real.iterdir()) == []


@pytest.mark.parametrize("kind", ["fifo", "file"])
def test_reproduce_refuses_an_output_path_that_is_not_a_directory(tmp_path, capsys, kind):
    out = tmp_path / "out"
    os.mkfifo(out) if kind == "fifo" else out.write_text("x")
    assert main(["reproduce", "--quick", "--force", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(out) in err
    assert "not a directory" in err
    assert ("FIFO" if kind == "fifo" else "regular file") in err


def _former_run(tmp_path: Path) -> Path:
    out = prepare_output(tmp_path / "out", force=False)
    with recording(out):
        write_text(out / "figure.csv", "old result")
        write_text(out / "table.csv", "old table")
    return out


def _snapshot(root: Path) -> dict[str, tuple[int, bytes | str | None]]:
    def content(p: Path):
        if p.is_symlink():
            return os.readlink(p)
        return p.read_bytes() if stat.S_ISREG(_mode(p)) else None

    return {p.name: (_mode(p), content(p)) for p in root.iterdir()}


def test_a_recorded_name_now_a_symlink_is_refused_before_anything_is_deleted(tmp_path):
    out = _former_run(tmp_path)
    precious = tmp_path / "precious.txt"
    precious.write_text("the user's data")
    (out / "table.csv").unlink()
    (out / "table.csv").symlink_to(precious)
    before = _snapshot(out)
    with pytest.raises(OutputExistsError, match="table.csv.*symbolic link"):
        prepare_output(out, force=True)
    assert _snapshot(out) == before
    assert precious.read_text() == "the user's data"


def test_a_recorded_name_now_a_fifo_is_refused_before_anything_is_deleted(tmp_path):
    out = _former_run(tmp_path)
    (out / "table.csv").unlink()
    os.mkfifo(out / "table.csv")
    before = _snapshot(out)
    with pytest.raises(OutputExistsError, match="FIFO"):
        prepare_output(out, force=True)
    assert _snapshot(out) == before


def test_an_output_named_symlink_stops_the_writer_and_is_kept(tmp_path):
    out = prepare_output(tmp_path / "out", force=False)
    precious = tmp_path / "precious.txt"
    precious.write_text("the user's data")
    (out / "figure.csv").symlink_to(precious)
    with recording(out), pytest.raises(UnsafeTargetError, match="symbolic link"):
        write_text(out / "figure.csv", "result")
    assert os.readlink(out / "figure.csv") == str(precious)
    assert precious.read_text() == "the user's data"
    assert (out / MARKER).read_text().splitlines()[1:] == []


@pytest.mark.parametrize("kind", ["fifo", "symlink", "directory"])
def test_a_marker_that_is_not_a_regular_file_is_refused_at_once(tmp_path, capsys, kind):
    out = _former_run(tmp_path)
    real_marker = tmp_path / "elsewhere"
    (out / MARKER).rename(real_marker)
    if kind == "fifo":  # opening it for reading would block forever
        os.mkfifo(out / MARKER)
    elif kind == "symlink":
        (out / MARKER).symlink_to(real_marker)
    else:
        (out / MARKER).mkdir()
    before = _snapshot(out)
    assert main(["reproduce", "--quick", "--force", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("impactsym: error: the marker file")
    assert str(out / MARKER) in err
    assert "not a regular file" in err
    assert _snapshot(out) == before


@pytest.mark.parametrize("size", [MARKER_MAX_BYTES + 1, 64 << 20])
def test_a_large_sparse_marker_is_refused_at_once_by_name(tmp_path, capsys, size):
    out = _former_run(tmp_path)
    with (out / MARKER).open("r+b") as handle:
        handle.truncate(size)  # sparse: takes no disk space, reads as zeros
    before = {name: mode for name, (mode, _) in _snapshot(out).items()}
    start = time.perf_counter()
    assert main(["reproduce", "--quick", "--force", "--out", str(out)]) == 2
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert str(out / MARKER) in err
    assert f"more than {MARKER_MAX_BYTES} bytes" in err
    assert {name: mode for name, (mode, _) in _snapshot(out).items()} == before
    assert (out / "figure.csv").read_text() == "old result"
    assert elapsed < 30.0  # generous: the refusal reads no more than the size limit


def test_a_marker_of_the_largest_size_a_run_can_write_is_read(tmp_path):
    out = _former_run(tmp_path)
    names = [f"{i:0250d}" for i in range(4000)]  # 4000 names of 250 bytes: below the bound
    text = MARKER_HEADER + "\n" + "figure.csv\n" + "".join(n + "\n" for n in names)
    assert len(text.encode()) <= MARKER_MAX_BYTES
    (out / MARKER).write_text(text)
    (out / "user.txt").write_text("kept")
    prepare_output(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "table.csv", "user.txt"]
