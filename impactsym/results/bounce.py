"""Bounce-sequence results for ``impactsym reproduce``: sequences, D-f maps, tables."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.contact.bounce import bounce_map, bounce_sequence
from impactsym.results.contact import boundary_curve
from impactsym.results.files import save_figure, write_csv

CONDITIONS = ("position", "force")

#: (D, f) of the sequences shown side by side: many bounces; a re-contact in which the
#: relaxing element catches the body from behind (force condition, near its fold)
SEQUENCES = ((0.1, 0.2), (0.4297, 0.2))

CAPTIONS = {
    "bounce_sequence": "Bounce sequences until rest under the position and the force "
    "condition side by side, computed (normalized on the first impact; shaded: contacts; "
    "dashed: the massless element relaxing after a force-condition release).",
    "bounce_contacts_map": "Number of contacts until the body rests (the sticking contact "
    "included) over the D–f plane, computed; black line: the first contact sticks to its "
    "right; grey: not at rest within 100 contacts.",
    "bounce_time_to_rest_map": "Time to rest (start of the sticking contact, in units of "
    "1/ω_{0}) over the D–f plane, computed; white: the first contact sticks.",
    "bounce_sequence.csv": "Every contact of the sequences shown: start, end, arrival "
    "velocity, departure speed, element deflection at the start.",
    "bounce_map.csv": "Number of contacts and time to rest on a 25 × 21 grid of (D, f) (a "
    "coarser grid than the maps).",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "bounce_sequence": ("bounce_sequence.csv",),
    "bounce_contacts_map": ("bounce_map.csv",),
    "bounce_time_to_rest_map": ("bounce_map.csv",),
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the bounce-sequence figures and tables into ``out``."""
    from impactsym.plotting import bounce as plots

    n_D, n_f = (40, 30) if quick else (300, 240)
    files: list[Path] = []

    progress("bounce sequences, both conditions side by side")
    rows = []
    for i, (D, f) in enumerate(SEQUENCES):
        sequences = [bounce_sequence(D, f, condition=c) for c in CONDITIONS]
        axes = plots.plot_bounce_sequences(sequences)
        files += save_figure(axes[0], out, f"bounce_sequence_{i + 1}")
        for condition, seq in zip(CONDITIONS, sequences, strict=True):
            rows += [
                (D, f, CONDITIONS.index(condition), n, *values)
                for n, values in enumerate(
                    zip(
                        seq.start,
                        seq.end,
                        seq.arrival_velocity,
                        seq.departure_speed,
                        seq.element_deflection,
                        strict=True,
                    )
                )
            ]
    files.append(
        write_csv(
            out / "bounce_sequence.csv",
            [
                "D",
                "f",
                "condition (0 position, 1 force)",
                "contact",
                "start",
                "end",
                "arrival_velocity",
                "departure_speed",
                "element_deflection",
            ],
            rows,
        )
    )

    D, f = np.meshgrid(np.linspace(0.0, 1.2, n_D), np.geomspace(1e-3, 1.0, n_f))
    for condition in CONDITIONS:
        progress(f"number of contacts and time to rest over D-f ({condition} condition)")
        result = bounce_map(D, f, condition=condition)
        line = boundary_curve(condition=condition, f_max=float(f.max()))
        files += save_figure(
            plots.plot_bounce_map(result, quantity="n_contacts", boundary=line),
            out,
            f"bounce_contacts_map_{condition}",
        )
        files += save_figure(
            plots.plot_bounce_map(result, quantity="time_to_rest", boundary=line),
            out,
            f"bounce_time_to_rest_map_{condition}",
        )

    grid_D, grid_f = np.meshgrid(np.linspace(0.0, 1.2, 25), np.linspace(0.0, 1.0, 21))
    maps = {c: bounce_map(grid_D, grid_f, condition=c) for c in CONDITIONS}
    files.append(
        write_csv(
            out / "bounce_map.csv",
            ["D", "f", "n_position", "rest_position", "n_force", "rest_force"],
            zip(
                grid_D.ravel(),
                grid_f.ravel(),
                maps["position"].n_contacts.ravel(),
                maps["position"].time_to_rest.ravel(),
                maps["force"].n_contacts.ravel(),
                maps["force"].time_to_rest.ravel(),
                strict=True,
            ),
        )
    )
    return files
