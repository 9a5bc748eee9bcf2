"""The engines at their timestep, for ``impactsym reproduce``: achieved restitution
against MuJoCo's timestep, the timestep advisor, LAMMPS at ``t_c / 50``.

Curves and bands are predictions of impactsym's discrete models of the engines
(:func:`impactsym.engines.mujoco.predict` and :func:`impactsym.engines.lammps.predict`
with a timestep: the phase mean and the range over touch phases). Points with bars are
engine output, measured where the engine is installed
(:func:`impactsym.engines.survey.mujoco_measured`,
:func:`impactsym.engines.survey.lammps_measured`) and recorded with the engine's version
in :data:`RUNS`. Called by :func:`impactsym.results.engines.write`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import (
    lammps_advice,
    lammps_at_timestep,
    lammps_measured,
    mujoco_measured,
)
from impactsym.results.files import save_figure, write_csv, write_text

RUNS = "engines_timestep_runs.json"

#: MuJoCo's default timestep (s) and the LAMMPS steps per contact time shown.
DEFAULT_TIMESTEP = 0.002
STEPS_PER_CONTACT = 50

#: The MuJoCo cases: name, wanted restitution, contact time (None: timeconst 0.02 s);
#: speed 1 m/s, gravity 9.81 m/s^2, default solimp, integrator Euler.
CASES = (("e0.5", 0.5, None), ("e0.3_tc10ms", 0.3, 0.01))
SPEED, GRAVITY = 1.0, 9.81

#: Timesteps at which MuJoCo is run (quick, full) and touch phases per timestep.
MEASURED_STEPS = ((5e-4, 2e-3), (2.5e-4, 5e-4, 1e-3, 2e-3, 4e-3))
MUJOCO_PHASES = (8, 16)
#: Targets LAMMPS is run for (quick, full) and touch phases per target.
LAMMPS_TARGETS = ((0.5,), (0.2, 0.5, 0.8))
LAMMPS_PHASES = (3, 4)


def mujoco_designs(restitution: float, contact_time: float | None) -> dict[str, tuple]:
    """The solrefs compared: textbook (only without a contact time: timeconst 0.02 s and
    the textbook dampratio), the continuous design and the discrete design at
    :data:`DEFAULT_TIMESTEP` (Euler)."""
    kwargs: dict[str, Any] = {"restitution": restitution, "speed": SPEED, "gravity": GRAVITY}
    if contact_time is not None:
        kwargs["contact_time"] = contact_time
    designs = {}
    if contact_time is None:
        damping = float(lammps.textbook_damping_ratio(restitution))
        designs["textbook solref"] = (mujoco.DEFAULT_TIMECONST, damping)
    designs["continuous design"] = tuple(float(v) for v in mujoco.solref_for(**kwargs).solref)
    discrete = mujoco.solref_for(**kwargs, timestep=DEFAULT_TIMESTEP, integrator="euler")
    designs[f"discrete design at {DEFAULT_TIMESTEP:g} s"] = tuple(float(v) for v in discrete.solref)
    return designs


def mujoco_curves(solref: tuple, timesteps: np.ndarray) -> dict[str, np.ndarray]:
    """Predicted phase mean and range of MuJoCo's restitution (Euler) at ``timesteps``."""
    # predict takes one timestep: one call per timestep of the curve
    preds = [
        mujoco.predict(
            solref=solref,
            solimp=mujoco.DEFAULT_SOLIMP,
            speed=SPEED,
            gravity=GRAVITY,
            timestep=float(dt),
            integrator="euler",
        )
        for dt in timesteps
    ]
    return {
        "mean": np.array([float(p.restitution) for p in preds]),
        "min": np.array([float(p.restitution_range[0]) for p in preds]),
        "max": np.array([float(p.restitution_range[1]) for p in preds]),
    }


def write(
    out: Path, *, quick: bool, progress: Callable[[str], None], versions: dict[str, str | None]
) -> list[Path]:
    """Write the timestep figures, their CSV files and :data:`RUNS` into ``out``.

    ``versions`` (:func:`impactsym.results.engines.engine_versions`) says which engines
    are run for the measured points.
    """
    record: dict[str, Any] = {"engines": versions, "mujoco": {}, "lammps": {}}
    files = _lammps(out, quick=quick, progress=progress, versions=versions, record=record)
    path = out / RUNS
    write_text(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
    files.append(path)
    return files


def _mujoco(
    out: Path,
    *,
    quick: bool,
    progress: Callable[[str], None],
    versions: dict[str, str | None],
    record: dict[str, Any],
) -> list[Path]:
    """MuJoCo's achieved restitution against the timestep, and the advisor."""
    from impactsym.plotting import engines as plots

    files: list[Path] = []
    level = 0 if quick else 1
    timesteps = np.geomspace(1e-4, 4e-3, 25 if quick else 49)
    for case, restitution, contact_time in CASES:
        progress(f"MuJoCo at its timestep: {case}")
        designs = mujoco_designs(restitution, contact_time)
        curves = {name: mujoco_curves(solref, timesteps) for name, solref in designs.items()}
        measured = {}
        if versions.get("MuJoCo"):
            for name, solref in designs.items():
                measured[name] = mujoco_measured(
                    solref=solref,
                    solimp=mujoco.DEFAULT_SOLIMP,
                    speed=SPEED,
                    gravity=GRAVITY,
                    timesteps=MEASURED_STEPS[level],
                    phases=MUJOCO_PHASES[level],
                )
        ax = plots.plot_timestep_restitution(
            timesteps, curves, measured, target=restitution, default_timestep=DEFAULT_TIMESTEP
        )
        tc = "timeconst 0.02 s" if contact_time is None else f"contact time {contact_time:g} s"
        ax.set_title(
            f"MuJoCo Euler, e = {restitution:g}, {tc}, 1 m/s, g = 9.81: lines/bands "
            + ("predicted, points measured" if measured else "predicted (no engine run)"),
            fontsize=8,
        )
        files += save_figure(ax, out, f"engines_mujoco_timestep_{case}")
        names = list(designs)
        header = ["timestep_s"] + [
            f"{k}_{i}" for i in range(len(names)) for k in ("mean", "min", "max")
        ]
        columns = [timesteps] + [curves[n][k] for n in names for k in ("mean", "min", "max")]
        files.append(
            write_csv(
                out / f"engines_mujoco_timestep_{case}.csv", header, zip(*columns, strict=True)
            )
        )
        record["mujoco"][case] = {
            "designs": {
                f"{i}": {"name": n, "solref": list(designs[n])} for i, n in enumerate(names)
            },
            "measured": {
                n: {k: np.asarray(v).tolist() for k, v in m.items()} for n, m in measured.items()
            },
        }
    progress("MuJoCo timestep advisor")
    targets = np.linspace(0.1, 0.9, 9 if quick else 17)
    design = mujoco.solref_for(restitution=targets, speed=SPEED, gravity=GRAVITY)
    advice = {
        "MuJoCo Euler, continuous design (g = 9.81, 1 m/s)": np.asarray(
            _timestep(
                mujoco.timestep_for(
                    solref=design.solref, speed=SPEED, gravity=GRAVITY, tolerance=0.01
                )
            )
        )
    }
    ax = plots.plot_timestep_advice(targets, advice, default_timestep=DEFAULT_TIMESTEP)
    ax.set_title(
        "largest timestep keeping e within 1 % at every touch phase (predicted)", fontsize=8
    )
    files += save_figure(ax, out, "engines_timestep_advice")
    files.append(
        write_csv(
            out / "engines_timestep_advice.csv",
            ["e_target", "mujoco_timestep_s", "dampratio"],
            zip(
                targets,
                *advice.values(),
                np.broadcast_to(design.solref[1], targets.shape),
                strict=True,
            ),
        )
    )
    return files


def _timestep(advice: Any) -> Any:
    """The advisor's timestep: a number, or an object's ``.timestep``."""
    return getattr(advice, "timestep", advice)


def _lammps(
    out: Path,
    *,
    quick: bool,
    progress: Callable[[str], None],
    versions: dict[str, str | None],
    record: dict[str, Any],
) -> list[Path]:
    """LAMMPS at ``t_c / 50``: continuous against discrete design, and the advisor."""
    import matplotlib.pyplot as plt

    from impactsym.plotting import engines as plots

    level = 0 if quick else 1
    progress(f"LAMMPS at t_c/{STEPS_PER_CONTACT}")
    targets = np.linspace(0.1, 0.9, 9 if quick else 33)
    wanted = np.asarray(LAMMPS_TARGETS[level]) if versions.get("LAMMPS") else np.zeros(0)
    both = lammps_at_timestep(
        np.concatenate([targets, wanted]), steps_per_contact=STEPS_PER_CONTACT
    )
    survey = {k: v[: targets.size] for k, v in both.items()}
    runs = {k: v[targets.size :] for k, v in both.items()}
    names = ("continuous", "discrete")
    curves = {
        f"{n} design": {k: survey[f"{n}_{k}"] / targets for k in ("mean", "min", "max")}
        for n in names
    }
    measured = {}
    if wanted.size:
        for n in names:
            m = lammps_measured(
                kn=runs[f"{n}_kn"],
                damping=runs[f"{n}_damping"],
                speed=1.0,
                timestep=float(runs["timestep"][0]),
                phases=LAMMPS_PHASES[level],
            )
            measured[f"{n} design"] = {"targets": wanted} | {
                k: m[k] / wanted for k in ("mean", "min", "max")
            }
            record["lammps"][n] = {
                "targets": wanted.tolist(),
                "phase": m["phase"].tolist(),
                "restitution": m["restitution"].tolist(),
                "predicted_mean": runs[f"{n}_mean"].tolist(),
                "predicted_min": runs[f"{n}_min"].tolist(),
                "predicted_max": runs[f"{n}_max"].tolist(),
            }
    advice = lammps_advice(targets)
    _, (left, right) = plt.subplots(1, 2, figsize=(10, 5.5))
    plots.plot_at_timestep(
        targets,
        curves,
        measured,
        title=f"LAMMPS Hooke + limit_damping at t_c/{STEPS_PER_CONTACT}: "
        + ("bands predicted, points measured" if measured else "predicted (no engine run)"),
        legend="below",
        ax=left,
    )
    plots.plot_timestep_advice(
        targets,
        {"continuous design, 1 %": advice},
        default_timestep=None,
        ylabel="steps per contact time $t_c/\\Delta t$ [-]",
        legend="below",
        ax=right,
    )
    right.axhline(STEPS_PER_CONTACT, color="0.4", ls=":")
    right.set_title("LAMMPS timestep advisor (predicted)", fontsize=9)
    files = save_figure(left, out, "engines_lammps_timestep")
    header = ["e_target", "timestep_s"] + [
        f"{n}_{k}" for n in names for k in ("kn", "damping", "mean", "min", "max", "tc_mean")
    ]
    columns = [targets, survey["timestep"]] + [
        survey[f"{n}_{k}"]
        for n in names
        for k in ("kn", "damping", "mean", "min", "max", "tc_mean")
    ]
    files.append(write_csv(out / "engines_lammps_timestep.csv", header, zip(*columns, strict=True)))
    files.append(
        write_csv(
            out / "engines_lammps_advice.csv",
            ["e_target", "steps_per_contact_time"],
            zip(targets, advice, strict=True),
        )
    )
    return files


def captions(out: Path) -> dict[str, str]:
    """Captions of this part's files, saying which points were measured (from :data:`RUNS`)."""
    try:
        record = json.loads((Path(out) / RUNS).read_text(encoding="utf-8"))
    except FileNotFoundError:
        record = {"engines": {}, "mujoco": {}, "lammps": {}}
    versions = record["engines"]
    mj = versions.get("MuJoCo") if any(c["measured"] for c in record["mujoco"].values()) else None
    lmp = versions.get("LAMMPS") if record["lammps"] else None
    mj_points = (
        f"Points with bars: measured in MuJoCo {mj} (a sphere on a slide joint dropped on a "
        "plane, impactsym.engines.drivers.mujoco_phases): mean and range over evenly spaced "
        "touch phases."
        if mj
        else "No MuJoCo point: MuJoCo was not installed when this was reproduced, so it was "
        "not run; every curve and band is a prediction."
    )
    lmp_points = (
        f"Points with bars: measured in LAMMPS {lmp} (a sphere dropped on a granular wall, "
        "impactsym.engines.drivers.lammps_drop), mean and range over touch phases."
        if lmp
        else "No LAMMPS point: LAMMPS was not installed when this was reproduced, so it was "
        "not run; every curve and band is a prediction."
    )
    mujoco_caption = (
        "Achieved restitution against MuJoCo's timestep (Euler, default solimp, 1 m/s, "
        "gravity 9.81 m/s^{2}) for the textbook solref, impactsym's continuous design "
        "(exact as the timestep goes to 0) and its discrete design at the default "
        "timestep 0.002 s (dotted). Lines and bands: the mean and the range over touch "
        "phases predicted by impactsym.engines.mujoco.predict(timestep=...), not engine "
        "output. " + mj_points
    )
    return {
        "engines_mujoco_timestep": mujoco_caption,
        "engines_mujoco_timestep_e0.5.csv": "Predicted phase mean, min and max of MuJoCo's "
        "restitution against the timestep for each design of engines_timestep_runs.json "
        "(index 0, 1, ...): predictions, not engine output.",
        "engines_mujoco_timestep_e0.3_tc10ms.csv": "As engines_mujoco_timestep_e0.5.csv, for "
        "e = 0.3 with a 10 ms contact: predictions.",
        "engines_timestep_advice": "The timestep advisor (impactsym.engines.mujoco.timestep_for, "
        "a prediction): the largest timestep at which MuJoCo's restitution stays within 1 % "
        "of the continuous value at every touch phase, for the continuous design of each "
        "target e (1 m/s, gravity 9.81, default solimp, Euler); dotted: the default "
        "timestep 0.002 s.",
        "engines_timestep_advice.csv": "Target e, the advisor's timestep (s) and the design's "
        "dampratio: predictions.",
        "engines_lammps_timestep": "LAMMPS (Hooke, limit_damping, no gravity, 10 ms contact) "
        f"at timestep t_c/{STEPS_PER_CONTACT}: achieved over target restitution for the "
        "continuous design (hooke_for without a timestep) and the discrete design "
        "(hooke_for(timestep=t_c/50)); lines and bands are the phase mean and range "
        "predicted by impactsym.engines.lammps.predict(timestep=...). " + lmp_points,
        "engines_lammps_timestep.csv": "Per target e: the designs' kn and eta_n and the "
        "predicted phase mean, min, max of e and mean contact time at t_c/50: predictions.",
        "engines_lammps_advice.csv": "Steps per contact time LAMMPS needs to keep e within "
        "1 % at every phase (impactsym.engines.lammps.timestep_for): predictions.",
        RUNS: "The engines' versions (null: not installed, not run), the designs, and every "
        "engine run of the timestep figures: measured restitution per touch phase (mean, "
        "min, max) next to impactsym's prediction.",
    }


#: The data files behind each figure (for the report's links).
DATA = {
    "engines_mujoco_timestep_e0.5": ("engines_mujoco_timestep_e0.5.csv", RUNS),
    "engines_mujoco_timestep_e0.3_tc10ms": ("engines_mujoco_timestep_e0.3_tc10ms.csv", RUNS),
    "engines_timestep_advice": ("engines_timestep_advice.csv",),
    "engines_lammps_timestep": (
        "engines_lammps_timestep.csv",
        "engines_lammps_advice.csv",
        RUNS,
    ),
}

__all__ = ["CASES", "DATA", "RUNS", "captions", "mujoco_curves", "mujoco_designs", "write"]
