r"""Results for ``impactsym reproduce``: the paper's questions for every contact law.

For each law of :mod:`impactsym.contact.laws` (``docs/nonlinear_contact.md``):

* the stick/release boundary :math:`f^*(\delta)` in the plane of its damping number
  :math:`\delta` and pressing number ``f``, under the position and the force condition
  (the analogue of the paper's Fig. 1b), by
  :func:`~impactsym.contact.lawstick.law_stick_boundary`;
* the restitution and contact time against the damping number without pressing force,
  both conditions, by :func:`~impactsym.contact.lawgrid.law_contact_map`;

and one contact-time map over (damping number, ``f``): the Tsuji law under the force
condition, the Hertz contact of the DEM codes with its tensile force cut. Every number is
computed here by the package's exact impact (closed forms where they hold, the order-8
integration elsewhere); the figures only draw them. ``quick`` (for tests) takes two moderate
damping numbers per boundary, short curves and a coarse map, at the same ``rtol`` of the
boundary. A boundary costs about one vectorized integration per pass of
:func:`~impactsym.contact.lawstick.law_stick_boundary`, hardly more for more points, so a
quick run still costs about ten such searches; small damping numbers (large ``f^*``,
slow to decide) are left to the full run.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.contact.lawgrid import law_contact_map
from impactsym.contact.laws import LAWS
from impactsym.contact.lawstick import law_stick_boundary
from impactsym.results.files import save_figure, write_csv, write_records

CONDITIONS = ("position", "force")

#: Largest damping number shown for each law (the smallest is 1/40 of it for the
#: boundaries, 0 for the restitution): D = 1.5 (the linear contact sticks without
#: pressing force from D = 1 on), s = 4, alpha = 3 (zeta = alpha/sqrt(5) = 1 at
#: alpha = 2.236), beta = 1.5.
DAMPING_MAX = {
    "linear": 1.5,
    "hertz-linear": 1.5,
    "hunt-crossley": 4.0,
    "tsuji": 3.0,
    "viscoelastic": 1.5,
}
#: Damping numbers of the quick boundaries, as fractions of DAMPING_MAX: moderate ones,
#: whose sticking verdicts are decided in few steps.
QUICK_FRACTIONS = (0.25, 0.6)
#: Relative width of the bracket around each f* (as the solve_ivp check of the tests).
RTOL = 1e-5
#: The law and condition of the contact-time map, and its range of f.
MAP_LAW, MAP_CONDITION, MAP_F = "tsuji", "force", (1e-3, 10.0)

CAPTIONS = {
    "law_stick_boundaries": "Stick/release boundaries of every contact law, computed: the "
    "pressing number f^{*} at which the body starts to stick, against the law's damping "
    "number (D, s = λv_{0}, α, β = 3A/(2T)), under the position and the force condition; "
    "the body releases below each line and sticks above it (for Hunt–Crossley the two "
    "lines coincide). A line ends where the body sticks already without pressing force.",
    "law_stick_boundary.csv": "The stick boundary f^{*} of each law at each damping number, "
    "both conditions (0: sticks without pressing force).",
    "law_restitution": "Restitution of every contact law against its damping number "
    "without pressing force, computed, under the position (solid) and the force condition "
    "(dashed); 0 where the body sticks. Hunt–Crossley: the Lambert-W closed form; Tsuji: "
    "the linear contact at ζ = α/√5; the others integrated.",
    "law_restitution.csv": "Restitution and normalized contact time t_{c}/T (inf: sticks) "
    "of each law at each damping number without pressing force, both conditions.",
    "law_contact_map": "Contact time t_{c}/T of the Hertz contact with Tsuji damping "
    "under the force condition (the tensile force cut, as in the DEM codes) over its "
    "damping number α and pressing number f, computed; grey: the body sticks; black: the "
    "stick boundary f^{*}.",
    "law_contact_map.csv": "Contact time t_{c}/T (inf: sticks) and restitution of the "
    "Tsuji law, force condition, on the grid of the map.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "law_stick_boundaries": ("law_stick_boundary.csv",),
    "law_restitution": ("law_restitution.csv",),
    "law_contact_map": ("law_contact_map.csv", "law_stick_boundary.csv"),
}


def boundary_damping(law: str, *, quick: bool) -> np.ndarray:
    """The damping numbers of the boundary of ``law``: 41 evenly spaced from 1/40 of
    :data:`DAMPING_MAX` to it, or the :data:`QUICK_FRACTIONS` of it.

    >>> boundary_damping("tsuji", quick=True).tolist()
    [0.75, 1.7999999999999998]
    >>> boundary_damping("tsuji", quick=False)[[0, -1]].tolist()
    [0.07500000000000001, 3.0]
    """
    fractions = np.asarray(QUICK_FRACTIONS) if quick else np.linspace(1 / 40, 1.0, 41)
    return DAMPING_MAX[law] * fractions


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the boundaries, the restitution curves and the contact-time map into ``out``."""
    from impactsym.plotting import laws as plots

    n_curve, (n_d, n_f) = (8, (8, 6)) if quick else (201, (120, 100))
    files: list[Path] = []

    damping, boundaries = {}, {}
    for law in LAWS:
        progress(f"{law}: stick/release boundaries, both conditions")
        damping[law] = boundary_damping(law, quick=quick)
        boundaries[law] = {
            c: np.asarray(law_stick_boundary(law, damping[law], condition=c, rtol=RTOL))
            for c in CONDITIONS
        }
    files += save_figure(
        plots.plot_law_stick_boundaries(damping, boundaries)[0], out, "law_stick_boundaries"
    )
    files.append(
        write_records(
            out / "law_stick_boundary.csv",
            ["law", "damping_number", "f_star_position", "f_star_force"],
            [
                [law, *(f"{v:.17g}" for v in row)]
                for law in LAWS
                for row in zip(damping[law], *(boundaries[law][c] for c in CONDITIONS), strict=True)
            ],
        )
    )

    curves, results = {}, {}
    for law in LAWS:
        progress(f"{law}: restitution against the damping number without pressing force")
        curves[law] = np.linspace(0.0, DAMPING_MAX[law], n_curve)
        results[law] = {c: law_contact_map(law, curves[law], 0.0, condition=c) for c in CONDITIONS}
    files += save_figure(
        plots.plot_law_restitution(
            curves, {law: {c: r.restitution for c, r in results[law].items()} for law in LAWS}
        )[0],
        out,
        "law_restitution",
    )
    files.append(
        write_records(
            out / "law_restitution.csv",
            [
                "law",
                "damping_number",
                "restitution_position",
                "restitution_force",
                "contact_time_position",
                "contact_time_force",
            ],
            [
                [law, *(f"{v:.17g}" for v in row)]
                for law in LAWS
                for row in zip(
                    curves[law],
                    *(results[law][c].restitution for c in CONDITIONS),
                    *(results[law][c].contact_time for c in CONDITIONS),
                    strict=True,
                )
            ],
        )
    )

    progress(f"{MAP_LAW}: contact-time map ({MAP_CONDITION} condition)")
    alpha, f = np.meshgrid(np.linspace(0.0, DAMPING_MAX[MAP_LAW], n_d), np.geomspace(*MAP_F, n_f))
    grid = law_contact_map(MAP_LAW, alpha, f, condition=MAP_CONDITION)
    line = boundaries[MAP_LAW][MAP_CONDITION]
    inside = (line >= MAP_F[0]) & (line <= MAP_F[1])
    files += save_figure(
        plots.plot_law_map(grid, boundary=(damping[MAP_LAW][inside], line[inside])),
        out,
        "law_contact_map",
    )
    files.append(
        write_csv(
            out / "law_contact_map.csv",
            ["damping_number", "f", "contact_time", "restitution"],
            zip(
                alpha.ravel(),
                f.ravel(),
                np.ravel(grid.contact_time),
                np.ravel(grid.restitution),
                strict=True,
            ),
        )
    )
    return files
