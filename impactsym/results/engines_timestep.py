"""The engines at their timestep, for ``impactsym reproduce``: LAMMPS at ``t_c / 50``
and its timestep advisor.

Curves and bands are predictions of impactsym's discrete model of LAMMPS
(:func:`impactsym.engines.lammps.predict` with a timestep: the phase mean and the range
over touch phases). Points with bars are engine output, measured where LAMMPS is
installed (:func:`impactsym.engines.survey.lammps_measured`) and recorded with its
version in :data:`RUNS`. Called by :func:`impactsym.results.engines.write`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from impactsym.engines.survey import lammps_advice, lammps_at_timestep, lammps_measured
from impactsym.results.files import save_figure, write_csv, write_text

RUNS = "engines_timestep_runs.json"

#: The LAMMPS steps per contact time shown.
STEPS_PER_CONTACT = 50

#: Targets LAMMPS is run for (quick, full) and touch phases per target.
LAMMPS_TARGETS = ((0.5,), (0.2, 0.5, 0.8))
LAMMPS_PHASES = (3, 4)


def write(
    out: Path, *, quick: bool, progress: Callable[[str], None], versions: dict[str, str | None]
) -> list[Path]:
    """Write the timestep figures, their CSV files and :data:`RUNS` into ``out``.

    ``versions`` (:func:`impactsym.results.engines.engine_versions`) says which engines
    are run for the measured points.
    """
    record: dict[str, Any] = {"engines": versions, "lammps": {}}
    files = _lammps(out, quick=quick, progress=progress, versions=versions, record=record)
    path = out / RUNS
    write_text(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
    files.append(path)
    return files


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
        record = {"engines": {}, "lammps": {}}
    versions = record["engines"]
    lmp = versions.get("LAMMPS") if record["lammps"] else None
    lmp_points = (
        f"Points with bars: measured in LAMMPS {lmp} (a sphere dropped on a granular wall, "
        "impactsym.engines.drivers.lammps_drop), mean and range over touch phases."
        if lmp
        else "No LAMMPS point: LAMMPS was not installed when this was reproduced, so it was "
        "not run; every curve and band is a prediction."
    )
    return {
        "engines_lammps_timestep": "LAMMPS (Hooke, limit_damping, no gravity, 10 ms contact) "
        f"at timestep t_c/{STEPS_PER_CONTACT}: achieved over target restitution for the "
        "continuous design (hooke_for without a timestep) and the discrete design "
        "(hooke_for(timestep=t_c/50)); lines and bands are the phase mean and range "
        "predicted by impactsym.engines.lammps.predict(timestep=...), not engine output. "
        + lmp_points
        + " Right: the steps per contact time t_c/Δt that keep e within 1 % of the "
        "continuous value at every touch phase for the continuous design "
        "(impactsym.engines.lammps.timestep_for, a prediction); dotted: t_c/50.",
        **DATA_CAPTIONS,
    }


#: The captions of the data files (they do not depend on which engines ran).
DATA_CAPTIONS = {
    "engines_lammps_timestep.csv": "Per target e: the designs' kn and eta_n and the "
    "predicted phase mean, min, max of e and mean contact time at t_c/50: predictions.",
    "engines_lammps_advice.csv": "Steps per contact time LAMMPS needs to keep e within "
    "1 % at every phase (impactsym.engines.lammps.timestep_for): predictions.",
    RUNS: "The engines' versions (null: not installed, not run) and every LAMMPS run "
    "of the timestep figure (target e, touch phases): the measured restitution per "
    "touch phase next to impactsym's predicted phase mean, min and max.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "engines_lammps_timestep": (
        "engines_lammps_timestep.csv",
        "engines_lammps_advice.csv",
        RUNS,
    ),
}

__all__ = ["DATA", "DATA_CAPTIONS", "RUNS", "captions", "write"]
