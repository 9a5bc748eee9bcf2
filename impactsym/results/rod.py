"""Section-1 results for ``impactsym reproduce``: rod impact figures, maps, tables, formulas."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.results.files import save_figure, write_csv, write_text

CASES = ((0.3, 0.0), (2.0, 0.5), (20.0, 0.2))

CAPTIONS = {
    "rod_time_histories": "Rod impact, rigid contact, computed from the closed forms: "
    "striker displacement y(t) and contact force N(t) of the persistent-contact solution "
    "for three (α, f); dotted lines: a reflected wave returns to the struck end "
    "(t = 2, 4, …), N jumps by 2 there; dots: first zero (contact time, position resp. "
    "force condition).",
    "rod_finite_stiffness": "Contact force with a contact spring κ = 10, 100 and rigid "
    "(α = 1, f = 0.2), computed: the spring smooths the jumps; when a reflection returns "
    "the spring force first dips, for a time of order 1/κ, before it rises.",
    "rod_contact_time_maps": "Paper section 1 parameter study, rigid contact, computed: "
    "atlases of the contact time of the force and the position condition over the α–f "
    "plane (certified first sign changes; black: contours of t_{c}; white: the regions "
    "where the first contact ends on the 1st, 2nd, 3rd… reflection interval; grey: the "
    "striker sticks up to t = 100) and their ratio position / force (grey: sticks under "
    "one, dark grey: both).",
    "rod_time_histories.csv": "The time histories drawn: t and, for each (α, f), y and N "
    "(every k-th time point of the figure, at most about 1200 rows).",
    "rod_finite_stiffness.csv": "The contact forces drawn: t and N for κ = 10, 100 and "
    "rigid (every k-th time point of the figure).",
    "rod_contact_times.csv": "Contact times of both conditions and their ratio on the "
    "α–f grid of the atlases, every point up to 100 × 100 points, else every k-th α "
    "and f so that about 100 × 100 remain (inf: sticks up to t = 100; ratio nan where one "
    "sticks).",
    "rod_formulas.json": "LaTeX of eq. (1), the closed forms of W, Y, N (rigid and finite "
    "κ), eq. (2), the contact force series and the first inverted terms, with labels "
    "and captions.",
    "rod_formulas.tex": "The same formulas as LaTeX snippets, one display each.",
    "rod_series.txt": "The first terms of the delay series of Y (eq. (2)) and of the contact "
    "force N, and their inverse transforms, in plain text.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "rod_time_histories": ("rod_time_histories.csv",),
    "rod_finite_stiffness": ("rod_finite_stiffness.csv",),
    "rod_contact_time_maps": ("rod_contact_times.csv",),
}

#: Largest number of time points written per history table.
TABLE_POINTS = 1200


def _history_table(path: Path, runs, columns: list[tuple[str, str]]) -> Path:
    """Write ``t`` and, per run and ``(attribute, column name)``, its values (every k-th
    point so that at most about :data:`TABLE_POINTS` rows remain)."""
    t = runs[0].t
    for run in runs[1:]:
        if not np.array_equal(run.t, t):
            raise ValueError("the histories of one table must share their time points")
    step = max(1, -(-t.size // TABLE_POINTS))
    values = [getattr(run, attribute)[::step] for run in runs for attribute, _ in columns]
    header = ["t"] + [f"{name} ({_label(run)})" for run in runs for _, name in columns]
    return write_csv(path, header, zip(t[::step], *values, strict=True))


def _label(run) -> str:
    """``alpha=..., f=..., kappa=...`` of a time history."""
    kappa = "inf" if np.isinf(run.kappa) else f"{run.kappa:g}"
    return f"alpha={run.alpha:g}, f={run.f:g}, kappa={kappa}"


def contact_time_map_rows(study, step: int) -> list[tuple[float, ...]]:
    """The rows of ``study`` on every ``step``-th alpha and f."""
    return [
        row
        for i, row in enumerate(study.rows())
        if (i // study.alpha.size) % step == 0 and (i % study.alpha.size) % step == 0
    ]


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the rod figures (PNG and PDF), the contact-time table and the formulas."""
    import matplotlib.pyplot as plt

    from impactsym.plotting import rod as plots
    from impactsym.rod import RodImpact, contact_time_map, latex_formulas
    from impactsym.rod.history import time_history

    files: list[Path] = []

    progress("time histories with reflection times")
    axes = plt.figure(figsize=(8, 7.5)).subplots(2, 1, sharex=True)
    n_points = 801 if quick else 6001
    histories = [time_history(alpha, f, n_points=n_points) for alpha, f in CASES]
    plots.plot_time_history(histories, "y", ax=axes[0])
    plots.plot_time_history(histories, "N", ax=axes[1])
    axes[0].set_xlabel("")
    files += save_figure(axes[0], out, "rod_time_histories")
    columns = [("displacement", "y"), ("contact_force", "N")]
    files.append(_history_table(out / "rod_time_histories.csv", histories, columns))

    progress("finite contact stiffness")
    runs = [
        time_history(1.0, 0.2, kappa=kappa, t_max=8.0, n_points=8001)
        for kappa in (10.0, 100.0, np.inf)
    ]
    ax = plots.plot_stiffness_comparison(runs, "N")
    files += save_figure(ax, out, "rod_finite_stiffness")
    columns = [("contact_force", "N")]
    files.append(_history_table(out / "rod_finite_stiffness.csv", runs, columns))

    progress("contact-time atlases (force and position condition)")
    n = 9 if quick else 500
    alpha = np.geomspace(0.05, 10.0, n)
    f = np.linspace(0.0, 2.0, 7 if quick else n)
    study = contact_time_map(alpha, f)
    files += save_figure(plots.plot_contact_time_atlases(study)[0], out, "rod_contact_time_maps")
    step = max(1, -(-n // 100))
    coarse = contact_time_map_rows(study, step)
    files.append(
        write_csv(
            out / "rod_contact_times.csv",
            ["alpha", "f", "t_force", "t_position", "ratio_position_force"],
            coarse,
        )
    )

    progress("formulas")
    formulas = latex_formulas(3)
    path = out / "rod_formulas.json"
    records = [{"label": k, "caption": c, "latex": b} for k, c, b in formulas]
    write_text(path, json.dumps(records, indent=1))
    files.append(path)
    path = out / "rod_formulas.tex"
    write_text(
        path,
        "".join(f"% {label}: {caption}\n\\[\n{body}\n\\]\n\n" for label, caption, body in formulas),
    )
    files.append(path)
    path = out / "rod_series.txt"
    rod = RodImpact()
    lines = []
    for name in ("Y", "N"):
        lines.append(f"{name}(s) = sum of coefficient * exp(-delay * s), rigid contact:")
        lines += [f"  delay {d}: {c}" for d, c in rod.series(name, 4)]
        lines.append(
            f"{name.lower() if name == 'Y' else name}(t) = sum of g(t - delay) over arrived terms:"
        )
        lines += [f"  delay {d}: {g}" for d, g in rod.time_terms(name, 4)]
        lines.append("")
    write_text(path, "\n".join(lines))
    files.append(path)
    return files
