"""Results of the rod impact continued past separation for ``impactsym reproduce``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.results.files import save_figure, write_csv

#: (alpha, f, kappa) of the sequences drawn; the last one with a finite contact spring.
CASES = ((1.0, 0.0, np.inf), (20.0, 0.0, np.inf), (1.0, 0.5, np.inf), (1.0, 0.5, 10.0))

CAPTIONS = {
    "rod_sequence": "Rod impact continued past separation, computed (rigid contact, and in "
    "the last panel a contact spring κ = 10): energy of the striker, of the rod (elastic + "
    "kinetic), of the contact spring and work of the pressing force over time; grey: "
    "contact. f = 0: the striker leaves, part of its energy stays in the rod as "
    "vibration; f > 0: it returns and chatters on the vibrating rod end.",
    "rod_sequence_stress": "Largest compressive stress at the fixed end up to t = 40 over "
    "the mass ratio (f = 0), computed, with the light-striker value 2(1 + e^{−2/α}) and "
    "the massless-spring estimate √α.",
    "rod_restitution": "Coefficient of restitution of Saint-Venant's problem (f = 0) over "
    "the mass ratio, computed: exact, all contacts, against e = 1 of the rigid-body theory "
    "and the single-contact light-striker value 2 exp(−1 − e^{−2/α}/2).",
    "rod_sequence_contacts.csv": "The contact intervals (grey bands) of the sequences "
    "drawn: α, f, κ (inf: rigid), start and end of every contact up to t = 40.",
    "rod_sequence_stress.csv": "α and the largest fixed-end stress up to t = 40 (f = 0), as drawn.",
    "rod_restitution.csv": "α, number of contacts, restitution and largest fixed-end "
    "stress (f = 0, t ≤ 60).",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "rod_sequence": ("rod_sequence_contacts.csv",),
    "rod_sequence_stress": ("rod_sequence_stress.csv",),
    "rod_restitution": ("rod_restitution.csv",),
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the continued rod impact figures (PNG and PDF) and the restitution table."""
    import matplotlib.pyplot as plt

    from impactsym.plotting import rod_sequence as plots
    from impactsym.rod import impact_sequence

    files: list[Path] = []
    progress("rod impact sequences with energy split")
    axes = plt.figure(figsize=(8, 10.5)).subplots(len(CASES), 1)
    contacts = []
    for ax, (alpha, f, kappa) in zip(axes, CASES, strict=True):
        seq = impact_sequence(alpha, f, kappa=kappa, t_max=40.0)
        plots.plot_sequence(seq, ax=ax, n_points=801 if quick else 8001)
        contacts += [(alpha, f, kappa, start, end) for start, end in seq.contacts]
    files += save_figure(axes[0], out, "rod_sequence")
    files.append(
        write_csv(
            out / "rod_sequence_contacts.csv", ["alpha", "f", "kappa", "start", "end"], contacts
        )
    )

    alpha = np.geomspace(0.05, 50.0, 9 if quick else 61)
    progress("fixed-end stress over alpha")
    stress = [impact_sequence(a, 0.0, t_max=40.0) for a in alpha]
    files += save_figure(plots.plot_fixed_end_stress(stress), out, "rod_sequence_stress")
    files.append(
        write_csv(
            out / "rod_sequence_stress.csv",
            ["alpha", "max_fixed_end_stress"],
            [(a, seq.max_fixed_end_stress) for a, seq in zip(alpha, stress, strict=True)],
        )
    )
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
