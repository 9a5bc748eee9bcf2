"""The command line: reproduce (quick), latex, export; clear errors and exit codes."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CODE

from impactsym.cli import main
from impactsym.export import formula, formula_names


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce") / "out"
    assert main(["reproduce", "--out", str(out), "--quick"]) == 0
    return out


def test_quick_reproduce_writes_every_kind_of_result(quick_run):
    names = {p.name for p in quick_run.iterdir()}
    for expected in (
        "fig1a_contact_surface_force.png",
        "fig1b_stick_boundary.pdf",
        "stick_boundary.csv",
        "formulas.tex",
        "impactsym_numpy.py",
        "report.md",
        "index.html",
    ):
        assert expected in names
    assert any(n.startswith("rod") and n.endswith(".png") for n in names)
    report = (quick_run / "report.md").read_text()
    assert "![fig1b_stick_boundary](fig1b_stick_boundary.png)" in report
    assert "Paper Fig. 1b" in report


def test_reproduce_is_deterministic(quick_run, tmp_path):
    again = tmp_path / "again"
    assert main(["reproduce", "--out", str(again), "--quick"]) == 0

    def digest(path):
        return hashlib.sha256(path.read_bytes()).hexdigest()

    first = {p.name: digest(p) for p in quick_run.iterdir()}
    second = {p.name: digest(p) for p in again.iterdir()}
    assert first.keys() == second.keys()
    differing = sorted(n for n in first if first[n] != second[n])
    assert differing == []


def test_reproduce_refuses_to_clobber_without_force(tmp_path, capsys):
    (tmp_path / "keep.txt").write_text("mine")
    assert main(["reproduce", "--out", str(tmp_path), "--quick"]) == 2
    assert "not written by impactsym reproduce" in capsys.readouterr().err
    assert (tmp_path / "keep.txt").exists()


def test_latex_prints_one_formula_and_rejects_unknown_names(capsys):
    assert main(["latex", "sd-ridge-force-critical"]) == 0
    # prints exactly the registry's formula (its content is derived anew in test_export)
    assert capsys.readouterr().out.strip() == formula("sd-ridge-force-critical")
    assert main(["latex", "--list"]) == 0
    assert "rod-eq2" in capsys.readouterr().out.split()
    assert main(["latex", "no-such-formula"]) == 2
    assert "no formula named" in capsys.readouterr().err


def test_export_python_writes_an_importable_module(tmp_path):
    target = tmp_path / "exported.py"
    assert main(["export", "python", str(target)]) == 0
    assert "def contact_function_force" in target.read_text()
    assert main(["export", "python", str(tmp_path / "missing" / "x.py")]) == 2


def test_python_dash_m_entry_point(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "impactsym", "latex", "sd-ode"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0
    assert run.stdout.startswith("z''")


def test_mujoco_prints_mjcf_attributes_and_predictions(capsys):
    assert main(["mujoco", "--restitution", "0.5", "--speed", "1", "--gravity", "9.81"]) == 0
    out = capsys.readouterr().out
    first = out.splitlines()[0]
    assert first.startswith('solref="0.02 ')
    assert first.endswith('solimp="0.9 0.95 0.001 0.5 2"')
    assert "predicted restitution:  0.5\n" in out
    assert "textbook dampratio 0.215454 would give" in out


def test_mujoco_refuses_an_unreachable_target_with_exit_code_2(capsys):
    argv = ["mujoco", "--restitution", "0.1", "--speed", "1", "--gravity", "9.81"]
    assert main([*argv, "--solimp", "0.9", "0.9", "0.001", "0.5", "2"]) == 2
    assert "cannot be reached" in capsys.readouterr().err


# -- hostile input --------------------------------------------------------------------------


def test_cli_latex_with_code_as_a_name_is_an_unknown_formula(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["latex", CODE]) == 2
    assert "no formula named" in capsys.readouterr().err
    assert not (tmp_path / "PWNED").exists()


def test_cli_export_into_a_directory_fails_cleanly(tmp_path, capsys):
    target = tmp_path / "a_directory"
    target.mkdir()
    (target / "keep.txt").write_text("mine")
    assert main(["export", "python", str(target)]) == 2
    assert capsys.readouterr().err.startswith("impactsym: error:")
    assert (target / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in Path(tmp_path).iterdir()) == ["a_directory"]


def test_cli_export_writes_atomically(tmp_path):
    target = tmp_path / "m.py"
    assert main(["export", "python", str(target)]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["m.py"]
    assert "def boundary_force" in target.read_text()


def test_version_matches_the_installed_distribution(capsys):
    import re

    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    pyproject = (Path(__file__).parents[1] / "pyproject.toml").read_text()
    version = re.search(r'^version = "([^"]+)"', pyproject, re.M).group(1)
    assert capsys.readouterr().out.strip() == f"impactsym {version}"


def test_latex_list_gives_every_label_with_a_one_line_description(capsys):
    assert main(["latex", "--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == formula_names()
    for line in lines:
        description = line.split(maxsplit=1)[1]
        assert len(description) > 15, line  # a phrase, not a bare label
        assert "$" not in description, line
        assert "\\" not in description, line
    assert "Ridge time tau_r(D, f) of the force condition, over-damped contact (D > 1)" in (
        "\n".join(lines)
    )
