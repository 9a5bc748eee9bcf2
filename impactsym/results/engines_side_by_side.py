"""The four engines side by side, for ``impactsym reproduce``: for a grid of wanted
restitutions (one contact time, a 0.1 kg sphere at 1 m/s, gravity off and on), what MuJoCo,
LAMMPS, Drake and PyBullet deliver with their native recipes
(:mod:`impactsym.engines.recipes`) and with impactsym's designs at each engine's default
step, predicted by the engine models and measured in the engines that are installed
(:mod:`impactsym.engines.side_by_side`).

Files: ``engines_side_by_side.csv`` (one row per engine, recipe, gravity and target),
one figure per gravity (``engines_side_by_side_g0``, ``engines_side_by_side_g9.81``;
quick runs: gravity off only; PyBullet twice: textbook ``contactStiffness``/``contactDamping``
and its own velocity ``restitution``) and :data:`RUNS` (the engines' versions, ``null`` where not
installed, then nothing of that engine was run).
"""

from __future__ import annotations

import importlib.metadata
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from impactsym.engines import side_by_side as sbs
from impactsym.engines.survey import touch_phases
from impactsym.results.files import save_figure, write_records, write_text

RUNS = "engines_side_by_side_runs.json"
TABLE = "engines_side_by_side.csv"

#: The request: contact time (s), mass (kg), approach speed (m/s).
CONTACT_TIME, MASS, SPEED = 0.05, 0.1, 1.0
#: Wanted restitutions (quick, full), gravities (m/s^2) and touch phases per design.
TARGETS = ((0.5,), (0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9))
GRAVITIES = ((0.0,), (0.0, 9.81))
PHASES = (4, 8)
#: Points of the native recipes' predicted curves (quick, full).
CURVE = (12, 60)
#: Points of PyBullet's velocity-restitution curve (quick, full): its phase mean costs
#: about half a second a point (one exact phase summary per pair restitution).
RESTITUTION_CURVE = (5, 18)

#: The package whose version names each engine (``importlib.metadata``).
PACKAGES = {"MuJoCo": "mujoco", "LAMMPS": "lammps", "Drake": "drake", "PyBullet": "pybullet"}

HEADER = [
    "engine",
    "recipe",
    "gravity_m_per_s2",
    "timestep_s",
    "e_wanted",
    "parameters",
    "e_predicted_mean",
    "e_predicted_min",
    "e_predicted_max",
    "tc_predicted_s",
    "e_measured_mean",
    "e_measured_min",
    "e_measured_max",
    "tc_measured_mean_s",
    "max_abs_measured_minus_predicted",
    "note",
]

FIGURE = (
    "Restitution delivered against the one wanted ({gravity}; contact time 50 ms, "
    "0.1 kg at 1 m/s), at each engine's default step (MuJoCo 2 ms Euler, LAMMPS t_{{c}}/50, "
    "Drake 1 ms lagged, PyBullet 1/240 s). Dashed lines and bands: the native recipes "
    "(MuJoCo solref (0.02, textbook dampratio); LAMMPS damping coeff_restitution; Drake "
    "Hunt–Crossley 1975 d = 3(1 − e)/(2 v_{{0}}); PyBullet textbook contactStiffness and "
    "contactDamping) predicted by impactsym's engine models, phase mean and range over "
    "touch phases; dotted: PyBullet's velocity restitution (changeDynamics restitution = e "
    "on the ball, 1 on the plane, rigid default contact; predict_rigid), whose phase "
    "mean counts the phases at which the ball sticks as 0. Diagonal: impactsym's designs "
    "(solref_for, hooke_for, point_contact_for, contact_for at the step), whose predicted "
    "phase mean is the wanted e."
)

CAPTIONS = {
    TABLE: "Per engine, recipe (native or impactsym), gravity and wanted e: the parameters "
    "pasted, the restitution predicted by impactsym's engine model (phase mean, min, max) "
    "and contact time, the restitution measured in the engine (mean, min, max over evenly "
    "spaced touch phases; empty where the engine was not installed) and the largest "
    "|measured − predicted| per phase; note: why a design is out of reach at the step.",
    RUNS: "The engines run when this was reproduced (version, or null: not installed, "
    "so not run) and the touch phases each design was run at.",
}


def engine_versions() -> dict[str, str | None]:
    """The installed version of each engine of :data:`impactsym.engines.side_by_side.ENGINES`
    that can be imported here, else ``None``."""
    versions: dict[str, str | None] = dict.fromkeys(sbs.ENGINES)
    for engine, package in PACKAGES.items():
        try:
            if engine == "LAMMPS":
                from impactsym.engines.drivers import load_mpi

                load_mpi()
            importlib.import_module("pydrake" if engine == "Drake" else package)
            versions[engine] = importlib.metadata.version(package)
        except (ImportError, OSError, importlib.metadata.PackageNotFoundError):
            pass
    return versions


def _stems(gravities) -> list[str]:
    return [f"engines_side_by_side_g{g:g}" for g in gravities]


def survey(
    *, quick: bool, versions: dict[str, str | None], progress: Callable[[str], None] = str
) -> dict[str, Any]:
    """The side-by-side grid: per gravity, the cases, their predictions (phase mean and
    per measured phase), the engines' measurements (installed engines only) and the
    native recipes' predicted curves."""
    level = 0 if quick else 1
    targets = np.array(TARGETS[level])
    phases = touch_phases(PHASES[level])
    curve = np.linspace(0.1, 0.95, CURVE[level])
    rigid_curve = np.linspace(0.1, 0.95, RESTITUTION_CURVE[level])
    out: dict[str, Any] = {"phases": phases, "curve": curve, "rigid_curve": rigid_curve,
                           "gravities": {}}  # fmt: skip
    for g in GRAVITIES[level]:
        progress(f"designs and predictions, gravity {g:g} m/s^2")
        cases = sbs.cases(restitution=targets, contact_time=CONTACT_TIME, gravity=g, mass=MASS,
                          speed=SPEED)  # fmt: skip
        natives = [c for c in cases if c.recipe == "native"]
        curves = sbs.cases(restitution=curve, contact_time=CONTACT_TIME, gravity=g, mass=MASS,
                           speed=SPEED, engines=tuple(c.engine for c in natives),
                           recipes=("native",))  # fmt: skip
        rigid = sbs.cases(restitution=rigid_curve, contact_time=CONTACT_TIME, gravity=g,
                          mass=MASS, speed=SPEED, engines=("PyBullet",),
                          recipes=("native-restitution",))  # fmt: skip
        ran = [c for c in cases if versions.get(c.engine)]
        if ran:
            progress(f"engine runs, gravity {g:g} m/s^2: {len(ran)} cases")
        out["gravities"][g] = {
            "cases": cases,
            "mean": sbs.predict_cases(cases),
            "per_phase": sbs.predict_cases(ran, phases=phases),
            "measured": sbs.measure_cases(ran, phases=phases),
            "ran": ran,
            "curves": dict(zip((c.engine for c in curves), sbs.predict_cases(curves), strict=True)),
            "rigid_curve": sbs.predict_cases(rigid)[0],
        }
    return out


def _rows(result: dict[str, Any]) -> list[dict[str, Any]]:
    rows = []
    for g, block in result["gravities"].items():
        pairs = zip(block["per_phase"], block["measured"], strict=True)
        measured = {id(c): pm for c, pm in zip(block["ran"], pairs, strict=True)}
        for case, pred in zip(block["cases"], block["mean"], strict=True):
            for i, e in enumerate(case.targets):
                params = " ".join(f"{k}={v[i]:.6g}" for k, v in case.parameters.items())
                row = {
                    "engine": case.engine,
                    "recipe": case.recipe,
                    "gravity_m_per_s2": f"{g:g}",
                    "timestep_s": f"{case.timestep:.6g}",
                    "e_wanted": f"{e:g}",
                    "parameters": params if case.reachable[i] else "",
                    "e_predicted_mean": f"{pred['restitution'][i]:.6g}",
                    "e_predicted_min": f"{pred['min'][i]:.6g}",
                    "e_predicted_max": f"{pred['max'][i]:.6g}",
                    "tc_predicted_s": f"{pred['contact_time'][i]:.6g}",
                    "note": "" if case.reachable[i] else case.reasons[i],
                }
                row |= dict.fromkeys(HEADER[10:15], "")
                if id(case) in measured and case.reachable[i]:
                    p, m = measured[id(case)]
                    em, tm = m["restitution"][i], m["contact_time"][i]
                    worst = np.abs(em - p["restitution"][i]).max()
                    row |= {
                        "e_measured_mean": f"{em.mean():.6g}",
                        "e_measured_min": f"{em.min():.6g}",
                        "e_measured_max": f"{em.max():.6g}",
                        "tc_measured_mean_s": f"{tm.mean():.6g}",
                        "max_abs_measured_minus_predicted": f"{worst:.2g}",
                    }
                rows.append(row)
    return rows


def captions(out: Path) -> dict[str, str]:
    """The captions of this step's files in ``out``: which engines were measured (with
    their versions, from :data:`RUNS`) and which points are predictions."""
    try:
        record = json.loads((Path(out) / RUNS).read_text(encoding="utf-8"))
    except FileNotFoundError:
        record = {"engines": dict.fromkeys(sbs.ENGINES), "gravities": [0.0], "phases": []}
    versions = record["engines"]
    ran = [f"{name} {v}" for name, v in versions.items() if v]
    missing = [name for name, v in versions.items() if not v]
    if ran:
        how = (
            f"Markers: measured in {', '.join(ran)} (impactsym.engines.side_by_side."
            f"measure_cases, the mean over {len(record['phases'])} evenly spaced touch "
            "phases); open: native recipe (triangles: PyBullet restitution), filled: "
            "impactsym design."
        )
    else:
        how = "No marker: no engine was installed when this was reproduced, so none was run."
    if missing and ran:
        how += f" Not installed, so predicted only: {', '.join(missing)}."
    out_captions = dict(CAPTIONS)
    for g, stem in zip(record["gravities"], _stems(record["gravities"]), strict=True):
        gravity = "no gravity" if g == 0 else f"gravity {g:g} m/s^{{2}}"
        text = FIGURE.format(gravity=gravity) + " " + how
        if g:
            text += " LAMMPS is left out under gravity (hooke_for designs without it)."
        out_captions[stem] = text
    return out_captions


#: The data files behind each figure (for the report's links).
DATA = dict.fromkeys(_stems(GRAVITIES[1]), (TABLE, RUNS))


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the side-by-side table, figures and engine record into ``out``."""
    from impactsym.plotting.side_by_side import plot_side_by_side

    versions = engine_versions()
    ran = [f"{name} {v}" for name, v in versions.items() if v]
    progress(f"engines installed: {', '.join(ran)}" if ran else "no engine installed: none run")
    result = survey(quick=quick, versions=versions, progress=progress)
    files = [write_records(out / TABLE, HEADER, _rows(result))]
    for g, stem in zip(result["gravities"], _stems(result["gravities"]), strict=True):
        block = result["gravities"][g]
        curves = {
            engine: {"mean": c["restitution"], "min": c["min"], "max": c["max"]}
            for engine, c in block["curves"].items()
        }
        rigid = block["rigid_curve"]
        curves["PyBullet restitution"] = {
            "targets": result["rigid_curve"],
            "mean": rigid["restitution"],
            "min": rigid["min"],
            "max": rigid["max"],
        }
        measured = {
            (case.engine, case.recipe): {
                "targets": case.targets[case.reachable],
                "mean": m["restitution"][case.reachable].mean(1),
            }
            for case, m in zip(block["ran"], block["measured"], strict=True)
        }
        ax = plot_side_by_side(
            result["curve"],
            curves,
            measured,
            title="no gravity" if g == 0 else f"gravity {g:g} m/s²",
        )
        files += save_figure(ax, out, stem)
    record = {
        "engines": versions,
        "gravities": list(result["gravities"]),
        "phases": result["phases"].tolist(),
    }
    path = out / RUNS
    write_text(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
    files.append(path)
    return files
