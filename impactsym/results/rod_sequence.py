"""Results of the rod impact continued past separation for ``impactsym reproduce``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.results.files import save_figure, write_csv

#: (alpha, f, kappa) of the sequences drawn; the last one with a finite contact spring.
CASES = ((1.0, 0.0, np.inf), (20.0, 0.0, np.inf), (1.0, 0.5, np.inf), (1.0, 0.5, 10.0))

CAPTIONS = {
    "rod_sequence": "Rod impact continued past separation (rigid contact, and in the last "
    "panel a contact spring kappa = 10): energy of the striker, of the rod (elastic + "
    "kinetic), of the contact spring and work of the pressing force over time; grey: "
    "contact. f = 0: the striker leaves, part of its energy stays in the rod as "
    "vibration; f > 0: it returns and chatters on the vibrating rod end.",
    "rod_sequence_stress": "Largest compressive stress at the fixed end up to t = 40 over "
    "the mass ratio (f = 0), with the light-striker value 2 (1 + exp(-2/alpha)) and the "
    "massless-spring estimate sqrt(alpha).",
    "rod_restitution": "Coefficient of restitution of Saint-Venant's problem (f = 0) over "
    "the mass ratio: exact, all contacts, against e = 1 of the rigid-body theory and the "
    "single-contact light-striker value 2 exp(-1 - exp(-2/alpha)/2).",
    "rod_restitution.csv": "alpha, number of contacts, restitution and largest fixed-end "
    "stress (f = 0, t <= 60).",
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the continued rod impact figures (PNG and PDF) and the restitution table."""
    import matplotlib.pyplot as plt

    from impactsym.plotting import rod_sequence as plots
    from impactsym.rod import impact_sequence

    files: list[Path] = []
    progress("rod impact sequences with energy split")
    axes = plt.figure(figsize=(8, 10.5)).subplots(len(CASES), 1)
    for ax, (alpha, f, kappa) in zip(axes, CASES, strict=True):
        plots.plot_sequence(
            impact_sequence(alpha, f, kappa=kappa, t_max=40.0),
            ax=ax,
            n_points=801 if quick else 8001,
        )
    files += save_figure(axes[0], out, "rod_sequence")

    alpha = np.geomspace(0.05, 50.0, 9 if quick else 61)
    progress("fixed-end stress over alpha")
    stress = [impact_sequence(a, 0.0, t_max=40.0) for a in alpha]
    files += save_figure(plots.plot_fixed_end_stress(stress), out, "rod_sequence_stress")
    progress("restitution over alpha")
    sequences = [impact_sequence(a, 0.0, t_max=60.0) for a in alpha]
    files += save_figure(plots.plot_restitution(sequences), out, "rod_restitution")
    rows = [
        [a, len(seq.contacts), seq.restitution, seq.max_fixed_end_stress]
        for a, seq in zip(alpha, sequences, strict=True)
    ]
    files.append(
        write_csv(
            out / "rod_restitution.csv",
            ["alpha", "n_contacts", "restitution", "max_fixed_end_stress"],
            rows,
        )
    )
    return files
