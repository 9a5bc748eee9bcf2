"""Section-2 results for ``impactsym reproduce``: Fig. 1a/1b, maps, tables, formulas.

The grids the figures draw (:func:`boundary_curve`, :func:`surface_grid`,
:func:`map_grid`) are computed here with :mod:`impactsym.contact`, so that
:mod:`impactsym.plotting.contact` only draws; notebooks use them too.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from impactsym.contact import contact_surface, contact_time, restitution, stick_boundary
from impactsym.contact.derivation import latex_formulas
from impactsym.results.files import save_figure, write_csv, write_text

CONDITIONS = ("position", "force")

CAPTIONS = {
    "fig1a_contact_surface_force": "Paper Fig. 1a, computed: the implicit surface "
    "g(τ, D, f) = 0 of the force condition; lower sheet = contact time, upper sheet = g "
    "rising through zero again; they meet along the fold ∂g/∂τ = 0, beyond which the "
    "body sticks.",
    "fig1a_contact_surface_position": "Fig. 1a for the position condition (contact while "
    "z > 0), computed.",
    "fig1a_contact_surface_force.csv": "The grid of Fig. 1a (force condition): D, f and "
    "both sheets τ (nan where a sheet does not exist).",
    "fig1a_contact_surface_position.csv": "The grid of Fig. 1a for the position condition.",
    "fig1b_stick_boundary": "Paper Fig. 1b, computed: the stick/release boundaries D*(f) "
    "of both conditions; the body releases to the left of a curve and sticks to the right.",
    "contact_time_map": "Normalized contact time τ_{c} over the D–f plane, computed; grey "
    "where the body sticks, black line: stick boundary.",
    "restitution_map": "Coefficient of restitution e = −z′(τ_{c}) over the D–f plane, "
    "computed; grey where the body sticks.",
    "stick_boundary.csv": "D*(f) for both conditions (f = 0 first: D* = 1 and inf).",
    "contact_times": "Contact time and restitution on a 31 × 21 grid of (D, f) (a coarser "
    "grid than the maps).",
    "spring_damper_formulas.json": "LaTeX of the section-2 formulas with labels and captions.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "fig1a_contact_surface_force": ("fig1a_contact_surface_force.csv",),
    "fig1a_contact_surface_position": ("fig1a_contact_surface_position.csv",),
    "fig1b_stick_boundary": ("stick_boundary.csv",),
    "contact_time_map_force": ("contact_times_force.csv",),
    "contact_time_map_position": ("contact_times_position.csv",),
    "restitution_map_force": ("contact_times_force.csv",),
    "restitution_map_position": ("contact_times_position.csv",),
}


def boundary_curve(
    *, condition: str, f_max: float = 2.0, n_points: int = 400
) -> tuple[np.ndarray, np.ndarray]:
    """``(D*, f)`` along the stick boundary for ``0 < f <= f_max`` (log-spaced).

    >>> d_star, f = boundary_curve(condition="position", f_max=1.0, n_points=3)
    >>> f.tolist(), bool(d_star[0] > d_star[-1])
    ([0.0001, 0.01, 1.0], True)
    """
    f = np.geomspace(f_max * 1e-4, f_max, n_points)
    return stick_boundary(f, condition=condition), f


def surface_grid(
    *, condition: str, D_max: float = 1.5, f_max: float = 1.0, n_points: int = 60
) -> tuple[np.ndarray, ...]:
    r"""The sheets of :math:`g(\tau, D, f) = 0` on a grid that ends on the fold.

    Returns ``D, f, first, second, (D_fold, f_fold, tau_fold)`` for
    :func:`impactsym.plotting.contact.plot_contact_surface`: the grid is
    ``D = s min(D*(f), D_max)``, ``0 <= s < 1``, so that both sheets
    (:func:`impactsym.contact.contact_surface`) end exactly on the fold.

    >>> D, f, first, second, fold = surface_grid(condition="force", n_points=4)
    >>> D.shape, len(fold)
    ((4, 4), 3)
    """
    n = n_points
    f_line = np.linspace(f_max / n, f_max, n)
    reach = np.minimum(stick_boundary(f_line, condition=condition), D_max)
    s = np.linspace(0.0, 1.0 - 1e-9, n)[:, None]
    D, f = s * reach, np.broadcast_to(f_line, (n, n))
    first, second, _ = contact_surface(D, f, condition=condition)
    on_fold = reach < D_max
    _, _, ridge = contact_surface(reach[on_fold], f_line[on_fold], condition=condition)
    return D, f, first, second, (reach[on_fold], f_line[on_fold], ridge)


def map_grid(
    *, condition: str, D_max: float = 1.5, f_max: float = 1.0, n_points: int = 300
) -> tuple[np.ndarray, ...]:
    """``D, f, tau_c, e`` on an ``n_points x n_points`` grid of ``[0, D_max] x [0, f_max]``.

    >>> D, f, tau_c, e = map_grid(condition="force", n_points=3)
    >>> tau_c.shape
    (3, 3)
    """
    D, f = np.meshgrid(np.linspace(0, D_max, n_points), np.linspace(0, f_max, n_points))
    return (
        D,
        f,
        contact_time(D, f, condition=condition),
        restitution(D, f, condition=condition),
    )


def write(out: Path, *, quick: bool, progress: Callable[[str], None]) -> list[Path]:
    """Write the spring-damper figures, tables and formulas into ``out``."""
    from impactsym.plotting import contact as plots

    n_map, n_surface, n_boundary = (60, 25, 60) if quick else (400, 70, 400)
    files: list[Path] = []

    progress("Fig. 1a: contact-time surface (force condition)")
    for condition in ("force", "position"):
        grid = surface_grid(condition=condition, n_points=n_surface)
        stem = f"fig1a_contact_surface_{condition}"
        files += save_figure(plots.plot_contact_surface(*grid, condition=condition), out, stem)
        D, fg, first, second = (np.ravel(v) for v in grid[:4])
        files.append(
            write_csv(
                out / f"{stem}.csv",
                ["D", "f", "tau_lower_sheet", "tau_upper_sheet"],
                zip(D, fg, first, second, strict=True),
            )
        )

    progress("Fig. 1b: stick/release boundaries")
    f_line = np.geomspace(1e-3, 10.0, 400)
    curves = {c: stick_boundary(f_line, condition=c) for c in CONDITIONS}
    files += save_figure(plots.plot_stick_boundary(f_line, curves), out, "fig1b_stick_boundary")
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
        D, fg, tau_c, e = map_grid(condition=condition, n_points=n_map)
        line = boundary_curve(condition=condition, f_max=1.0)
        files += save_figure(
            plots.plot_contact_time_map(D, fg, tau_c, condition=condition, boundary=line),
            out,
            f"contact_time_map_{condition}",
        )
        files += save_figure(
            plots.plot_restitution_map(
                D, fg, e, sticks=np.isinf(tau_c), condition=condition, boundary=line
            ),
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
