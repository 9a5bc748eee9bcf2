"""Results for ``impactsym reproduce``: what the usual damping design formulas deliver.

For targets ``e = 0.05, 0.10, ..., 0.95`` the restitution that the Lankarani–Nikravesh,
Hunt–Crossley 1975, Flores, Gonthier and Hu–Guo formulas (Hunt–Crossley law) and the DEM
Tsuji formula (tensile force kept, and cut) really deliver, computed with the exact
:func:`~impactsym.contact.nonlinear.impact` by
:func:`~impactsym.contact.lawformulas.formula_table` (``docs/physics.md``, "What the
usual formulas deliver"). The table does not depend on ``quick``: it is small.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from impactsym.contact.lawformulas import LABELS, formula_table
from impactsym.results.files import save_figure, write_csv

CAPTIONS = {
    "formula_restitution": "What the usual damping design formulas deliver, computed "
    "with the exact impact of their law: Hunt–Crossley force k d^{3/2}(1 + λ d′) with the "
    "Lankarani–Nikravesh, Hunt–Crossley 1975, Flores, Gonthier and Hu–Guo λ; Hertz with "
    "Tsuji damping and the DEM formula γ_{n} = −2√(5/6) β √(S_{n} m), exact where the "
    "tensile force is kept (position condition), off where it is cut (force condition). "
    "Black: the exact design (damping_for).",
    "formula_restitution.csv": "Target restitution and the restitution each formula "
    "delivers (one column per formula).",
}

#: The data files behind each figure (for the report's links).
DATA = {"formula_restitution": ("formula_restitution.csv",)}

#: CSV column of each formula.
COLUMNS = {
    "lankarani-nikravesh": "lankarani_nikravesh",
    "hunt-crossley-1975": "hunt_crossley_1975",
    "flores": "flores",
    "gonthier": "gonthier",
    "hu-guo": "hu_guo",
    "tsuji-kept": "tsuji_tensile_kept",
    "tsuji-cut": "tsuji_tensile_cut",
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the formula table (CSV) and its figure into ``out``."""
    from impactsym.plotting import lawformulas as plots

    progress("what the usual damping design formulas deliver")
    table = formula_table()
    files = save_figure(
        plots.plot_formula_errors(
            table.target, table.delivered, [LABELS[f] for f in table.formulas]
        ),
        out,
        "formula_restitution",
    )
    files.append(
        write_csv(
            out / "formula_restitution.csv",
            ["target", *(COLUMNS[f] for f in table.formulas)],
            zip(table.target, *table.delivered, strict=True),
        )
    )
    return files
