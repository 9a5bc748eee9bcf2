"""Section-2 results for ``impactsym reproduce``: Fig. 1a/1b, maps, tables, formulas."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.contact import contact_time, restitution, stick_boundary
from impactsym.contact.derivation import latex_formulas
from impactsym.results.files import save_figure, write_csv, write_text

CONDITIONS = ("position", "force")

CAPTIONS = {
    "fig1a_contact_surface_force": "Paper Fig. 1a: the implicit surface g(tau, D, f) = 0 of the "
    "force condition; lower sheet = contact time, upper sheet = g rising through zero again; "
    "they meet along the fold dg/dtau = 0, beyond which the body sticks.",
    "fig1a_contact_surface_position": "Fig. 1a for the position condition (contact while z > 0).",
    "fig1b_stick_boundary": "Paper Fig. 1b: the stick/release boundaries D*(f) of both "
    "conditions; the body releases to the left of a curve and sticks to the right.",
    "contact_time_map": "Normalized contact time tau_c over the D-f plane; grey where the "
    "body sticks, black line: stick boundary.",
    "restitution_map": "Coefficient of restitution e = -z'(tau_c) over the D-f plane; grey "
    "where the body sticks.",
    "stick_boundary.csv": "D*(f) for both conditions (f = 0 first: D* = 1 and inf).",
    "contact_times": "Contact time and restitution on a 31 x 21 grid of (D, f).",
    "spring_damper_formulas.json": "LaTeX of the section-2 formulas with labels and captions.",
}


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the spring-damper figures, tables and formulas into ``out``."""
    from impactsym.plotting import contact as plots

    n_map, n_surface, n_boundary = (60, 25, 60) if quick else (400, 70, 400)
    files: list[Path] = []

    progress("Fig. 1a: contact-time surface (force condition)")
    files += save_figure(
        plots.plot_contact_surface(condition="force", n_points=n_surface),
        out,
        "fig1a_contact_surface_force",
    )
    files += save_figure(
        plots.plot_contact_surface(condition="position", n_points=n_surface),
        out,
        "fig1a_contact_surface_position",
    )

    progress("Fig. 1b: stick/release boundaries")
    files += save_figure(plots.plot_stick_boundary(), out, "fig1b_stick_boundary")
    f = np.concatenate([[0.0], np.geomspace(1e-4, 10.0, n_boundary)])
    boundary = {c: stick_boundary(f, condition=c) for c in CONDITIONS}
    files.append(
        write_csv(
            out / "stick_boundary.csv",
            ["f", "D_star_position", "D_star_force"],
            zip(f, boundary["position"], boundary["force"], strict=True),
        )
    )

    for condition in CONDITIONS:
        progress(f"contact-time and restitution maps ({condition} condition)")
        files += save_figure(
            plots.plot_contact_time_map(condition=condition, n_points=n_map),
            out,
            f"contact_time_map_{condition}",
        )
        files += save_figure(
            plots.plot_restitution_map(condition=condition, n_points=n_map),
            out,
            f"restitution_map_{condition}",
        )
        D, fg = np.meshgrid(np.linspace(0, 1.5, 31), np.linspace(0, 1.0, 21))
        tau_c, e = contact_time(D, fg, condition=condition), restitution(D, fg, condition=condition)
        files.append(
            write_csv(
                out / f"contact_times_{condition}.csv",
                ["D", "f", "tau_c", "e"],
                zip(D.ravel(), fg.ravel(), tau_c.ravel(), e.ravel(), strict=True),
            )
        )

    progress("formulas")
    path = out / "spring_damper_formulas.json"
    write_text(
        path,
        json.dumps(
            [
                {"label": label, "caption": caption, "latex": body}
                for label, caption, body in latex_formulas()
            ],
            indent=1,
        ),
    )
    files.append(path)
    return files
