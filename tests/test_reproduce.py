"""``impactsym reproduce`` never deletes what it did not write and leaves no partial file.

Every test works under ``tmp_path`` with ``HOME`` and the current directory moved there,
so that a failure can never touch the real home directory or the checkout.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from impactsym.cli import main
from impactsym.reproduce import check_output, prepare_output
from impactsym.results import files
from impactsym.results.files import MARKER, PARTIAL, atomic_path, recording, write_text

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def sandbox(tmp_path, monkeypatch):
    """A fake home with a user's file, and the current directory inside it."""
    home = tmp_path / "home"
    work = home / "work"
    work.mkdir(parents=True)
    (home / "notes.txt").write_text("the user's notes")
    (work / "thesis.tex").write_text("the user's thesis")
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(work)
    return home, work


def _snapshot(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


@pytest.mark.parametrize("out", ["", ".", "~", "./", "..", "~/.."])
def test_protected_output_directories_are_refused_even_with_force(sandbox, capsys, out):
    home, _ = sandbox
    before = _snapshot(home.parent)
    assert main(["reproduce", "--quick", "--force", "--out", out]) == 2
    err = capsys.readouterr().err
    assert "impactsym: error:" in err
    assert "refusing" in err or "must be named" in err
    assert _snapshot(home.parent) == before


def test_root_and_package_directories_are_refused(sandbox):
    import impactsym

    package = Path(impactsym.__file__).resolve().parent
    for out in ("/", package, package.parent, package / "contact"):
        with pytest.raises(ValueError, match="refusing"):
            check_output(out)


def test_a_users_directory_with_files_is_never_emptied(sandbox, capsys):
    home, _ = sandbox
    user_dir = home / "results"
    user_dir.mkdir()
    (user_dir / "data.csv").write_text("1,2,3")
    before = _snapshot(home)
    assert main(["reproduce", "--quick", "--force", "--out", str(user_dir)]) == 2
    assert "was not written by impactsym reproduce" in capsys.readouterr().err
    assert _snapshot(home) == before


def test_force_deletes_only_the_files_a_former_run_recorded(sandbox):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    with recording(out):
        write_text(out / "figure.csv", "old result")
    (out / "added_by_user.txt").write_text("keep me")
    (out / f".figure.csv.1234.0123abcd{PARTIAL}").write_text("left by a killed run")
    assert (out / MARKER).read_text().splitlines()[1:] == ["figure.csv"]
    prepare_output(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "added_by_user.txt"]
    assert (out / "added_by_user.txt").read_text() == "keep me"


def test_force_keeps_a_users_files_that_merely_end_in_partial(sandbox):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    with recording(out):
        write_text(out / "a.txt", "ours")
    (out / f".draft{PARTIAL}").write_text("the user's draft")
    (out / f".cache{PARTIAL}").mkdir()
    (out / f".cache{PARTIAL}" / "x").write_text("the user's cache")
    (out / f".b.txt.12.0123abcd{PARTIAL}").mkdir()  # our pattern, but a directory
    (out / f".c.txt.12.0123abcd{PARTIAL}").symlink_to(home / "notes.txt")
    prepare_output(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [
            MARKER,
            f".draft{PARTIAL}",
            f".cache{PARTIAL}",
            f".b.txt.12.0123abcd{PARTIAL}",
            f".c.txt.12.0123abcd{PARTIAL}",
        ]
    )
    assert (out / f".draft{PARTIAL}").read_text() == "the user's draft"
    assert (out / f".cache{PARTIAL}" / "x").read_text() == "the user's cache"
    assert (home / "notes.txt").read_text() == "the user's notes"


def test_a_real_temporary_name_matches_the_pattern_force_deletes(tmp_path):
    seen = []
    with atomic_path(tmp_path / "table.csv") as tmp:
        tmp.write_text("x")
        seen.append(files.is_partial(tmp))
    assert seen == [True]


def test_an_exported_file_in_a_reproduce_directory_is_not_recorded_or_deleted(sandbox):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    with recording(out):
        write_text(out / "figure.csv", "old result")
    assert main(["export", "python", str(out / "mine.py")]) == 0
    assert main(["export", "latex", str(out / "mine.tex")]) == 0
    assert (out / MARKER).read_text().splitlines()[1:] == ["figure.csv"]
    prepare_output(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "mine.py", "mine.tex"]


def test_recording_covers_only_its_own_directory(tmp_path):
    out, other = prepare_output(tmp_path / "out", force=False), tmp_path / "other"
    other.mkdir()
    write_text(other / MARKER, "# a marker of another run\n")
    with recording(out):
        write_text(other / "x.txt", "x")
    assert (other / MARKER).read_text() == "# a marker of another run\n"


def test_a_marker_that_is_not_text_is_refused_before_anything_is_deleted(sandbox, capsys):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    with recording(out):
        write_text(out / "figure.csv", "old result")
    (out / MARKER).write_bytes((out / MARKER).read_bytes() + b"\xff\xfe\n")
    before = _snapshot(out)
    assert main(["reproduce", "--quick", "--force", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("impactsym: error: the marker file")
    assert "not UTF-8 text" in err
    assert _snapshot(out) == before


def test_marker_lines_are_whole_even_after_a_torn_one(sandbox, monkeypatch):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    (out / MARKER).write_text((out / MARKER).read_text() + "torn")  # no final newline
    with recording(out):
        write_text(out / "a.txt", "a")
    assert (out / MARKER).read_text().splitlines()[1:] == ["torn", "a.txt"]
    # the marker is replaced whole: an interrupt while it is rewritten leaves it as it was
    before = (out / MARKER).read_bytes()
    real = Path.write_bytes

    def interrupted(self, data):
        real(self, data[: len(data) // 2])
        raise KeyboardInterrupt

    monkeypatch.setattr(Path, "write_bytes", interrupted)
    with pytest.raises(KeyboardInterrupt), recording(out):
        write_text(out / "b.txt", "b")
    assert (out / MARKER).read_bytes() == before
    assert not [p for p in out.iterdir() if p.name.endswith(PARTIAL)]


def test_a_marker_cannot_name_files_outside_the_directory(sandbox):
    home, _ = sandbox
    out = prepare_output(home / "out", force=False)
    with (out / MARKER).open("a") as handle:
        handle.write("../notes.txt\n..\n/etc/passwd\n")
    prepare_output(out, force=True)
    assert (home / "notes.txt").read_text() == "the user's notes"


def test_a_failed_write_leaves_no_file_under_a_temporary_or_final_name(tmp_path):
    target = tmp_path / "table.csv"
    target.write_text("previous complete version")

    def write_half():
        with atomic_path(target) as tmp:
            tmp.write_text("half of the new")
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_half()
    assert target.read_text() == "previous complete version"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]


def test_an_interrupted_run_exits_130_with_one_line_and_no_partial_file(
    sandbox, monkeypatch, capsys
):
    home, _ = sandbox
    calls = []
    real_savefig = files.save_figure

    def interrupted(ax, out, stem):
        calls.append(stem)
        if len(calls) == 2:  # in the middle of writing the second figure
            fig = ax.figure
            with atomic_path(out / f"{stem}.pdf") as tmp:
                fig.savefig(tmp, format="pdf")
                raise KeyboardInterrupt
        return real_savefig(ax, out, stem)

    import impactsym.results.rod as rod_results

    monkeypatch.setattr(rod_results, "save_figure", interrupted)
    out = home / "out"
    assert main(["reproduce", "--quick", "--out", str(out)]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["impactsym: interrupted; files completed so far are kept"]
    names = sorted(p.name for p in out.iterdir())
    assert not [n for n in names if n.endswith(PARTIAL)]
    assert f"{calls[1]}.pdf" not in names
    recorded = (out / MARKER).read_text().splitlines()[1:]
    assert sorted(recorded) == sorted(n for n in names if n != MARKER)


def test_an_interrupt_that_a_library_turns_into_another_error_is_still_the_interrupt(
    sandbox, monkeypatch, capsys
):
    # Ctrl-C inside Matplotlib's PDF writer: its cleanup of a half-made stream raised
    # AttributeError, which the command reported as an internal error (exit 3)
    home, _ = sandbox

    def cleanup_fails(ax, out, stem):
        try:
            os.kill(os.getpid(), signal.SIGINT)  # the handler raises KeyboardInterrupt here
            time.sleep(1.0)
        except KeyboardInterrupt:
            raise AttributeError("'Stream' object has no attribute 'pos'") from None

    import impactsym.results.rod as rod_results

    monkeypatch.setattr(rod_results, "save_figure", cleanup_fails)
    assert main(["reproduce", "--quick", "--out", str(home / "out")]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["impactsym: interrupted; files completed so far are kept"]


@pytest.mark.slow
def test_sigint_during_a_run_prints_one_line_and_leaves_only_complete_files(tmp_path):
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "HOME": str(tmp_path)}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    proc = subprocess.Popen(
        [sys.executable, "-m", "impactsym", "reproduce", "--quick", "--out", str(out)],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        for line in proc.stdout:  # wait until the first figure is being written
            if "time histories" in line:
                break
        time.sleep(1.0)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert err.strip().splitlines() == ["impactsym: interrupted; files completed so far are kept"]
    names = [p.name for p in out.iterdir()]
    assert not [n for n in names if n.endswith(PARTIAL)]
    recorded = (out / MARKER).read_text().splitlines()[1:]
    assert sorted(recorded) == sorted(n for n in names if n != MARKER)
    for pdf in out.glob("*.pdf"):  # every PDF under its final name is complete
        assert pdf.read_bytes().rstrip().endswith(b"%%EOF")
