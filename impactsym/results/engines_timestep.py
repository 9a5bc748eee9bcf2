"""The engines at their timestep, for ``impactsym reproduce``: MuJoCo's achieved
restitution against its timestep and its timestep advisor; LAMMPS at ``t_c / 50`` and its
timestep advisor.

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
    FLAT,
    lammps_advice,
    lammps_at_timestep,
    lammps_measured,
    mujoco_advice,
    mujoco_at_timesteps,
    mujoco_measured,
)
from impactsym.results.files import save_figure, write_csv, write_text

RUNS = "engines_timestep_runs.json"

#: MuJoCo's default timestep (s), at which the discrete designs are made.
DEFAULT_TIMESTEP = 0.002

#: The MuJoCo cases: name, target restitution, contact time (s; None: timeconst 0.02 s);
#: all at 1 m/s under gravity 9.81 m/s^2 with the default solimp, integrator Euler.
MUJOCO_CASES = (("e0.5", 0.5, None), ("e0.3_tc10ms", 0.3, 0.01))
SPEED, GRAVITY = 1.0, 9.81

#: Timesteps (s) of the predicted curves: points (quick, full) on a geometric grid.
MUJOCO_CURVE = (1e-4, 4e-3, (25, 49))

#: Timesteps at which MuJoCo is run (quick, full) and touch phases per timestep.
MUJOCO_STEPS = ((5e-4, 2e-3), (2.5e-4, 5e-4, 1e-3, 2e-3, 4e-3))
MUJOCO_PHASES = (8, 16)

#: The advisor's targets (quick, full): flat solimp (a linear spring-damper), 1 m/s,
#: gravity 9.81, Euler, 1 % (each advice costs many phase-exact predictions).
ADVICE_TARGETS = ((0.2, 0.5, 0.8), tuple(np.round(np.linspace(0.2, 0.9, 15), 2)))
ADVICE_TOLERANCE = 0.01

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
    record: dict[str, Any] = {"engines": versions, "mujoco": {}, "lammps": {}}
    files = _mujoco(out, quick=quick, progress=progress, versions=versions, record=record)
    files += _mujoco_advice(out, quick=quick, progress=progress)
    files += _lammps(out, quick=quick, progress=progress, versions=versions, record=record)
    path = out / RUNS
    write_text(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
    files.append(path)
    return files


def mujoco_designs(restitution: float, *, contact_time: float | None = None) -> dict[str, tuple]:
    """The solrefs compared for one target at 1 m/s under gravity 9.81 (default solimp).

    ``"textbook"`` (only without a contact time): timeconst 0.02 s with the textbook
    dampratio; ``"continuous"``: :func:`impactsym.engines.mujoco.solref_for` without a
    timestep (exact as the timestep goes to 0); ``"discrete"``: ``solref_for`` at
    :data:`DEFAULT_TIMESTEP` with Euler (its phase mean hits the target there).
    """
    kwargs: dict[str, Any] = {"restitution": restitution, "speed": SPEED, "gravity": GRAVITY}
    if contact_time is not None:
        kwargs["contact_time"] = contact_time
    designs: dict[str, tuple] = {}
    if contact_time is None:
        dampratio = float(lammps.textbook_damping_ratio(restitution))
        designs["textbook"] = (mujoco.DEFAULT_TIMECONST, dampratio)
    for name, step in (("continuous", None), ("discrete", DEFAULT_TIMESTEP)):
        design = mujoco.solref_for(**kwargs, timestep=step, integrator="euler")
        designs[name] = tuple(float(v) for v in design.solref)
    return designs


def mujoco_curves(designs: dict[str, tuple], timesteps: np.ndarray) -> dict[str, dict]:
    """Predicted phase mean and range of each design's restitution at ``timesteps``
    (:func:`impactsym.engines.survey.mujoco_at_timesteps`, Euler, default solimp)."""
    return {
        name: mujoco_at_timesteps(
            solref=solref,
            solimp=mujoco.DEFAULT_SOLIMP,
            speed=SPEED,
            gravity=GRAVITY,
            timesteps=timesteps,
        )
        for name, solref in designs.items()
    }


def mujoco_points(designs: dict[str, tuple], timesteps, *, phases: int) -> dict[str, dict]:
    """MuJoCo's own restitution for each design at ``timesteps`` over ``phases`` touch
    phases (:func:`impactsym.engines.survey.mujoco_measured`; needs MuJoCo)."""
    return {
        name: mujoco_measured(
            solref=solref,
            solimp=mujoco.DEFAULT_SOLIMP,
            speed=SPEED,
            gravity=GRAVITY,
            timesteps=timesteps,
            phases=phases,
        )
        for name, solref in designs.items()
    }


LABELS = {
    "textbook": "textbook solref",
    "continuous": "continuous design",
    "discrete": f"discrete design at {DEFAULT_TIMESTEP:g} s",
}


def _mujoco(
    out: Path,
    *,
    quick: bool,
    progress: Callable[[str], None],
    versions: dict[str, str | None],
    record: dict[str, Any],
) -> list[Path]:
    """MuJoCo's achieved restitution against the timestep, per case of :data:`MUJOCO_CASES`."""
    import matplotlib.pyplot as plt

    from impactsym.plotting import engines as plots

    level = 0 if quick else 1
    low, high, counts = MUJOCO_CURVE
    timesteps = np.geomspace(low, high, counts[level])
    _, axes = plt.subplots(1, len(MUJOCO_CASES), figsize=(11, 6))
    header, columns = ["timestep_s"], [timesteps]
    for ax, (case, restitution, contact_time) in zip(axes, MUJOCO_CASES, strict=True):
        progress(f"MuJoCo at its timestep: {case}")
        designs = mujoco_designs(restitution, contact_time=contact_time)
        curves = mujoco_curves(designs, timesteps)
        measured = {}
        if versions.get("MuJoCo"):
            measured = mujoco_points(designs, MUJOCO_STEPS[level], phases=MUJOCO_PHASES[level])
        plots.plot_timestep_restitution(
            timesteps,
            {LABELS[n]: c for n, c in curves.items()},
            {LABELS[n]: m for n, m in measured.items()},
            target=restitution,
            default_timestep=DEFAULT_TIMESTEP,
            legend="below",
            ax=ax,
        )
        how = "timeconst 0.02 s" if contact_time is None else f"t_c = {contact_time * 1e3:g} ms"
        ax.set_title(
            f"MuJoCo Euler, e = {restitution:g}, {how}: "
            + ("bands predicted, points measured" if measured else "predicted (no engine run)"),
            fontsize=9,
        )
        for name, curve in curves.items():
            for key in ("mean", "min", "max", "tc_mean"):
                header.append(f"{case}_{name}_{key}")
                columns.append(curve[key])
        record["mujoco"][case] = {
            "restitution": restitution,
            "contact_time": contact_time,
            "solref": {name: list(solref) for name, solref in designs.items()},
            "phases": MUJOCO_PHASES[level] if measured else 0,
            "measured": {
                name: {k: np.asarray(v).tolist() for k, v in m.items()}
                for name, m in measured.items()
            },
        }
    files = save_figure(axes[0], out, "engines_mujoco_timestep")
    files.append(write_csv(out / "engines_mujoco_timestep.csv", header, zip(*columns, strict=True)))
    return files


def _mujoco_advice(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """The MuJoCo timestep advisor's curve, with the ``omega0 dt`` rule of thumb beside it."""
    from impactsym.plotting import engines as plots

    progress("MuJoCo timestep advisor")
    targets = np.asarray(ADVICE_TARGETS[0 if quick else 1])
    advice = mujoco_advice(
        targets, speed=SPEED, gravity=GRAVITY, solimp=FLAT, tolerance=ADVICE_TOLERANCE
    )
    ax = plots.plot_timestep_advice(
        targets,
        {
            "advisor (timestep_for), every phase within 1 %": advice["timestep"],
            r"rule of thumb $\omega_0 \Delta t = 0.03$": advice["rule_of_thumb"],
        },
        default_timestep=DEFAULT_TIMESTEP,
        ylabel="timestep [s]",
        legend="below",
    )
    ax.set_title(
        "MuJoCo Euler, continuous design, flat solimp, 1 m/s, g = 9.81 (predicted)", fontsize=9
    )
    files = save_figure(ax, out, "engines_mujoco_advice")
    keys = ("targets", "timeconst", "dampratio", "timestep", "error", "rule_of_thumb")
    header = ["e_target", "timeconst_s", "dampratio", "advised_timestep_s", "error_there",
              "rule_of_thumb_timestep_s"]  # fmt: skip
    rows = zip(*(advice[k] for k in keys), strict=True)
    files.append(write_csv(out / "engines_mujoco_advice.csv", header, rows))
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
        record = {"engines": {}, "mujoco": {}, "lammps": {}}
    versions = record["engines"]
    ran = any(case["measured"] for case in record.get("mujoco", {}).values())
    mj = versions.get("MuJoCo") if ran else None
    phases = max((case.get("phases", 0) for case in record.get("mujoco", {}).values()), default=0)
    mj_points = (
        f"Points with bars: measured in MuJoCo {mj} (a sphere on a slide joint dropped on a "
        "plane, impactsym.engines.drivers.mujoco_phases), mean and range over "
        f"{phases} evenly spaced touch phases."
        if mj
        else "No MuJoCo point: MuJoCo was not installed when this was reproduced, so it was "
        "not run; every curve and band is a prediction."
    )
    lmp = versions.get("LAMMPS") if record["lammps"] else None
    lmp_points = (
        f"Points with bars: measured in LAMMPS {lmp} (a sphere dropped on a granular wall, "
        "impactsym.engines.drivers.lammps_drop), mean and range over touch phases."
        if lmp
        else "No LAMMPS point: LAMMPS was not installed when this was reproduced, so it was "
        "not run; every curve and band is a prediction."
    )
    return {
        "engines_mujoco_timestep": "Achieved restitution against MuJoCo's timestep (Euler, "
        "default solimp, 1 m/s, gravity 9.81 m/s^{2}). Left, target e = 0.5: the textbook "
        "solref (timeconst 0.02 s, textbook dampratio), impactsym's continuous design "
        "(solref_for without a timestep, exact as the timestep goes to 0) and its discrete "
        "design (solref_for(timestep=0.002), whose phase mean hits the target at the "
        "default timestep 0.002 s, dotted). Right, target e = 0.3 with a 10 ms contact: the "
        "continuous and the discrete design. Lines and bands: the mean and the range over "
        "touch phases predicted by impactsym.engines.mujoco.predict(timestep=...), not "
        "engine output. " + mj_points,
        "engines_mujoco_advice": "MuJoCo's timestep advisor (impactsym.engines.mujoco."
        "timestep_for, a prediction): the largest timestep at which the restitution stays "
        "within 1 % of the continuous value at every touch phase, for the continuous design "
        "of each target e (flat solimp 0.9, 1 m/s, gravity 9.81 m/s^{2}, Euler); dashed: "
        "the one-parameter rule of thumb ω_{0}Δt = 0.03 with ω_{0} = 1/(timeconst·dampratio), "
        "which is too loose for strongly damped designs (small e) and too strict for weakly "
        "damped ones; dotted: the default timestep 0.002 s.",
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
    "engines_mujoco_timestep.csv": "Per timestep (s), for each case (e0.5: target 0.5, "
    "timeconst 0.02 s; e0.3_tc10ms: target 0.3, 10 ms contact) and design (textbook, "
    "continuous, discrete; their solref in engines_timestep_runs.json): the predicted "
    "phase mean, min and max of MuJoCo's restitution and the mean contact time (s): "
    "predictions, not engine output.",
    "engines_mujoco_advice.csv": "Per target e: the continuous design's timeconst and "
    "dampratio, the advisor's timestep (s) and the worst relative deviation over touch "
    "phases there (impactsym.engines.mujoco.timestep_for), and the rule-of-thumb "
    "timestep 0.03·timeconst·dampratio: predictions.",
    "engines_lammps_timestep.csv": "Per target e: the designs' kn and eta_n and the "
    "predicted phase mean, min, max of e and mean contact time at t_c/50: predictions.",
    "engines_lammps_advice.csv": "Steps per contact time LAMMPS needs to keep e within "
    "1 % at every phase (impactsym.engines.lammps.timestep_for): predictions.",
    RUNS: "The engines' versions (null: not installed, not run); per MuJoCo case the "
    "designs' solref and MuJoCo's measured restitution (mean, min, max over touch phases "
    "per timestep); every LAMMPS run of the timestep figure (target e, touch phases): the "
    "measured restitution per touch phase next to impactsym's predicted phase mean, min "
    "and max.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "engines_mujoco_timestep": ("engines_mujoco_timestep.csv", RUNS),
    "engines_mujoco_advice": ("engines_mujoco_advice.csv",),
    "engines_lammps_timestep": (
        "engines_lammps_timestep.csv",
        "engines_lammps_advice.csv",
        RUNS,
    ),
}

__all__ = [
    "DATA",
    "DATA_CAPTIONS",
    "LABELS",
    "MUJOCO_CASES",
    "RUNS",
    "captions",
    "mujoco_curves",
    "mujoco_designs",
    "mujoco_points",
    "write",
]
