"""The command line: reproduce (quick), latex, export; clear errors and exit codes."""

from __future__ import annotations

import hashlib
import math
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from conftest import CODE
from references.hooke import hooke_contact

from impactsym.cli import main
from impactsym.engines import mujoco
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
    # MuJoCo's default timestep and integrator unless told: says so, prints the phase range
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no raw RuntimeWarning after a result
        assert main(["mujoco", "--restitution", "0.5", "--speed", "1", "--gravity", "9.81"]) == 0
    out = capsys.readouterr().out
    first = out.splitlines()[0]
    assert first.startswith('solref="0.02 ')
    assert first.endswith('solimp="0.9 0.95 0.001 0.5 2"')
    assert "timestep 0.002 s (MuJoCo's default" in out
    assert "integrator Euler (MuJoCo's default" in out
    line = next(x for x in out.splitlines() if x.startswith("predicted restitution:"))
    assert line.startswith("predicted restitution:  0.5 (phase mean at dt = 0.002 s, Euler; ")
    low, high = (float(v) for v in line.split("; ")[1].split(" over")[0].split(" .. "))
    assert low < 0.5 < high
    assert "textbook dampratio 0.215454 would give" in out
    # the design is the phase mean of MuJoCo's default step, not the continuous one
    solref = tuple(float(v) for v in first.split('"')[1].split())
    design = mujoco.solref_for(restitution=0.5, speed=1.0, gravity=9.81, timestep=0.002)
    assert solref == pytest.approx(design.solref, rel=1e-9)


def test_mujoco_continuous_flag_and_timestep_zero_give_the_continuous_design(capsys):
    argv = ["mujoco", "--restitution", "0.5", "--speed", "1", "--gravity", "9.81"]
    assert main([*argv, "--continuous"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0] == 'solref="0.02 0.2540490447" solimp="0.9 0.95 0.001 0.5 2"'
    assert "continuous limit (timestep -> 0)" in out
    assert "predicted restitution:  0.5\n" in out
    assert main([*argv, "--timestep", "0"]) == 0
    assert capsys.readouterr().out == out
    assert main([*argv, "--continuous", "--timestep", "0.001"]) == 2
    assert "contradict" in capsys.readouterr().err


def test_mujoco_designs_at_the_given_timestep_and_integrator(capsys):
    argv = ["mujoco", "--restitution", "0.3", "--speed", "1", "--contact-time", "0.01"]
    assert main([*argv, "--timestep", "0.001", "--integrator", "implicitfast"]) == 0
    out = capsys.readouterr().out
    assert "designed for timestep 0.001 s, integrator implicitfast:" in out
    assert "(phase mean at dt = 0.001 s, implicitfast; " in out
    assert "predicted contact time: 0.01 s (phase mean; " in out


def test_mujoco_refuses_an_unreachable_target_with_exit_code_2(capsys):
    argv = ["mujoco", "--restitution", "0.1", "--speed", "1", "--gravity", "9.81"]
    assert main([*argv, "--solimp", "0.9", "0.9", "0.001", "0.5", "2"]) == 2
    assert "cannot be reached" in capsys.readouterr().err


def _lammps_design(capsys, *args):
    """Run ``impactsym lammps`` and return its output and the ``kn``, ``eta_n`` it printed."""
    assert main(["lammps", *args]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0] == "pair_style granular"
    words = lines[1].split()
    assert words[:4] == ["pair_coeff", "*", "*", "hooke"]
    return out, float(words[4]), float(words[5])


@pytest.mark.parametrize("limit", [True, False])
def test_lammps_prints_a_pasteable_hooke_line_and_predictions(capsys, limit):
    flag = [] if limit else ["--no-limit-damping"]
    args = ["--restitution", "0.4", "--contact-time", "2e-3", "--mass", "0.5", *flag]
    out, kn, eta = _lammps_design(capsys, *args)
    assert out.splitlines()[1].endswith("damping velocity limit_damping" if limit else "velocity")
    assert "predicted restitution:  0.4\n" in out
    assert "predicted contact time: 0.002 s\n" in out
    # the printed kn, eta_n in LAMMPS's law m x'' = -kn x - eta_n x', SciPy's events:
    # the force kn x + eta_n x' (limit_damping) or the overlap ends the contact
    sol = hooke_contact(kn, eta, 0.5, 1.0, limit_damping=limit)
    assert -sol.y[1, -1] == pytest.approx(0.4, rel=1e-8)  # 10 digits printed
    assert sol.t[-1] == pytest.approx(2e-3, rel=1e-8)
    if limit:
        # LAMMPS's coeff_restitution sets the textbook D; under limit_damping the force
        # ends the contact first (SciPy's events on z'' + 2 D z' + z = 0)
        log_e = math.log(0.4)
        D = -log_e / math.sqrt(math.pi**2 + log_e**2)

        ref = hooke_contact(1.0, 2 * D, 1.0, 1.0, t_max=10.0)  # z'' + 2 D z' + z = 0
        naive = out.split("'damping coeff_restitution 0.4' would give restitution ")[1]
        assert float(naive.split()[0]) == pytest.approx(-ref.y[1, -1], rel=1e-5)


def test_lammps_overlap_design_and_gravity_prediction(capsys):
    args = ["--restitution", "0.3", "--max-penetration", "1e-4", "--speed", "2", "--mass", "1"]
    out, _, _ = _lammps_design(capsys, *args)
    assert "max overlap:            0.0001 m (at 2 m/s)" in out
    assert "predicted restitution:  0.3\n" in out
    out, _, _ = _lammps_design(capsys, *args, "--gravity", "9.81")
    assert "predicted restitution:  0.29" in out  # the design has no load; gravity lowers e
    assert "s (gravity 9.81 m/s^2)" in out
    out, _, _ = _lammps_design(
        capsys,
        "--restitution",
        "0.5",
        "--contact-time",
        "1e-3",
        "--mass",
        "1",
        "--speed",
        "0.001",
        "--gravity",
        "1e4",
    )
    assert "predicted: the particle sticks (gravity 10000 m/s^2)" in out


def test_lammps_refuses_unreachable_and_needs_one_target(capsys):
    args = ["lammps", "--restitution", "0.5", "--contact-time", "1e-3", "--mass", "1e305"]
    assert main(args) == 2
    assert "mass = 1e+305" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["lammps", "--restitution", "0.5", "--mass", "1"])
    with pytest.raises(SystemExit):
        main(
            [
                "lammps",
                "--restitution",
                "0.5",
                "--mass",
                "1",
                "--contact-time",
                "1",
                "--max-penetration",
                "1",
            ]
        )


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
