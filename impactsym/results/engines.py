"""Engine-bridge results for ``impactsym reproduce`` (predictions only; no engine needed).

The engines themselves check these predictions in ``tests/test_engines_*.py``,
``benchmarks/bench_engines.py`` and ``notebooks/04_engine_parameters.ipynb``.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.engines import lammps, mujoco
from impactsym.engines.survey import stick_map, textbook_restitution
from impactsym.results.files import save_figure, write_csv, write_text

CAPTIONS = {
    "engines_textbook_error": "Restitution MuJoCo (timeconst 0.02 s, 1 m/s) and LAMMPS "
    "(coeff_restitution with limit_damping) give with the textbook damping "
    "e = exp(-pi D / sqrt(1 - D^2)); the diagonal is what the impactsym designs give.",
    "engines_mujoco_stick_map": "Under gravity (9.81 m/s^2, flat solimp 0.9): where MuJoCo's "
    "body sticks (grey), releases when the force vanishes (blue) or loses contact while "
    "still pressed (orange), over approach speed and dampratio; contours of e.",
    "engines_textbook_error.csv": "Wanted e and the textbook-damping restitution of MuJoCo "
    "(flat and default solimp) and LAMMPS (limit_damping).",
    "engines_designs.json": "Worked designs: MuJoCo solref for e = 0.5 at 1 m/s with and "
    "without gravity and with a 10 ms contact; LAMMPS kn, eta_n for e = 0.5, t_c = 1 ms, "
    "and the coeff_restitution value that gives e = 0.5 under limit_damping.",
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the engine-bridge figures, table and designs into ``out``.

    >>> import tempfile, matplotlib
    >>> matplotlib.use("Agg")
    >>> sorted(p.name for p in write(Path(tempfile.mkdtemp()), quick=True, progress=str))[:2]
    ['engines_designs.json', 'engines_mujoco_stick_map.pdf']
    """
    from impactsym.plotting import engines as plots

    files: list[Path] = []
    progress("textbook against exact restitution")
    curve = np.linspace(0.02, 0.98, 30 if quick else 120)
    files += save_figure(
        plots.plot_textbook_error(curve, textbook_restitution(curve)), out, "engines_textbook_error"
    )
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
    return files
