"""``impactsym reproduce`` step for paper section 3: multibody penalty contacts.

Two example systems whose effective mass differs clearly from every body mass, a
full nonlinear simulation of their penalty contact (a vectorized fixed-step RK4 with
event location, NumPy only, so that ``reproduce`` needs no SciPy; the tests check it
against ``scipy.integrate.solve_ivp``), the agreement sweep of the reduced model
against it, and the writer.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

from impactsym.multibody.reduction import PROJECTIONS, latex_formulas, reduce_contact
from impactsym.multibody.simulation import (
    MultibodyExample,
    agreement_sweep,
    convergence_study,
    examples,
    falling_bar,
    simulate_contact,
)
from impactsym.results.files import save_figure, write_records, write_text

Progress = Callable[[str], None]

CAPTIONS = {
    "multibody_agreement": "Reduced model against the full nonlinear penalty simulation "
    "(falling bar, double pendulum), both computed by impactsym: relative contact-time "
    "error over the reduced D for the impulse projection M^{−1} n_{0} and the paper's "
    "n_{0}/(n_{0}^{T} n_{0}); wrong stick/release verdicts on the top line.",
    "multibody_verdict_map": "Sweep points in the (f, D) plane of the reduced oscillator, "
    "marked by the full simulation's verdict, over the section-2 stick boundary D*(f); "
    "computed.",
    "multibody_convergence": "Contact-time error of both projections as the penalty "
    "stiffens (fixed D = 0.15, f = 0.3, position condition); computed.",
    "multibody_design": "Admissible penalty parameters of the falling bar at 0.5 m/s, "
    "computed: stick boundaries d*(k), iso-restitution curves and the design e = 0.5, "
    "t_{c} = 2 ms.",
    "multibody_agreement.csv": "Every sweep point: k, d, speed, reduced D, f, ω_{0}, full "
    "and reduced contact times per projection and condition (inf: sticks).",
    "multibody_summary.json": "Verdict hit rates and contact-time errors per system, "
    "projection and condition; convergence data; the worked penalty design and its check.",
    "multibody_reduced_equation.tex": "LaTeX of the reduced contact equation, the effective "
    "parameters, both projections and the falling bar's effective mass.",
}

#: The data files behind each figure (for the report's links).
DATA = {
    "multibody_agreement": ("multibody_agreement.csv", "multibody_summary.json"),
    "multibody_verdict_map": ("multibody_agreement.csv",),
    "multibody_convergence": ("multibody_summary.json",),
    "multibody_design": ("multibody_summary.json",),
}


def verdict_boundary(
    agreement: Any, *, condition: str, projection: str = "impulse", n_points: int = 200
) -> tuple[np.ndarray, np.ndarray]:
    """``(D*, f)``: the section-2 stick boundary over the pressing forces of
    ``agreement`` under ``projection`` (at least from 0.01 to 10), for
    :func:`impactsym.plotting.multibody.plot_verdict_map`.

    >>> agreement = agreement_sweep(
    ...     falling_bar(), omegas=(300.0,), dampings=(0.1,), forces=(0.2,), steps=16
    ... )
    >>> d_star, f = verdict_boundary(agreement, condition="force", n_points=3)
    >>> [round(float(v), 4) for v in f]
    [0.01, 0.3162, 10.0]
    """
    from impactsym.contact import stick_boundary

    f = np.asarray(agreement.f[projection], dtype=float)
    f_line = np.geomspace(min(f.min(), 1e-2), max(f.max(), 10.0), n_points)
    return stick_boundary(f_line, condition=condition), f_line


def _design_example(example: MultibodyExample | None = None) -> dict[str, Any]:
    """The worked penalty design: the bar at 0.5 m/s should release with ``e = 0.5``
    after 2 ms under the force condition; the full simulation checks the design."""
    from impactsym.multibody.design import penalty_for_targets, stick_damping

    example = falling_bar() if example is None else example
    speed, e_target, t_target, condition = 0.5, 0.5, 2e-3, "force"
    reduced = example.reduce(1.0, 0.0, speed)
    k, d = penalty_for_targets(
        reduced, restitution=e_target, contact_time=t_target, condition=condition
    )
    sim = simulate_contact(example, k, d, speed, condition=condition)
    return {
        "system": example.name,
        "speed": speed,
        "condition": condition,
        "target_restitution": e_target,
        "target_contact_time": t_target,
        "k": k,
        "d": d,
        "stick_damping_at_k": float(stick_damping(reduced, k, condition=condition)),
        "full_contact_time": float(sim.contact_time),
        "full_restitution": float(sim.restitution),
    }


def write(out: Path, *, quick: bool, progress: Progress) -> list[Path]:
    """Write the multibody figures, tables and formulas into ``out``; return the files."""
    import matplotlib.pyplot as plt

    from impactsym.multibody.design import damping_for_restitution, stick_damping
    from impactsym.plotting.multibody import (
        plot_agreement,
        plot_convergence,
        plot_design_region,
        plot_verdict_map,
    )

    out = Path(out)
    written: list[Path] = []
    if quick:
        grid = {
            "omegas": (300.0,),
            "dampings": (0.1, 0.4, 1.5),
            "forces": (0.1, 0.5, 2.0),
            "steps": 16,
            "t_max": 25.0,
        }
        omegas = (100.0, 1000.0)
    else:
        grid = {}
        omegas = tuple(np.geomspace(100.0, 3000.0, 6))
    agreements, convergence = [], {}
    for example in examples():
        progress(f"{example.title}: full simulations vs reduced model")
        agreements.append(agreement_sweep(example, **grid))
        convergence[example.name] = convergence_study(
            example, omegas, steps=20 if quick else 50, condition="position"
        )

    def save(fig: Any, stem: str) -> None:
        written.extend(save_figure(fig.axes[0], out, stem))

    fig, axes = plt.subplots(2, 2, figsize=(10, 9))
    for row, agreement in zip(axes, agreements, strict=True):
        for ax, condition in zip(row, ("position", "force"), strict=True):
            plot_agreement(agreement, condition=condition, ax=ax)
    save(fig, "multibody_agreement")
    fig, axes = plt.subplots(2, 2, figsize=(10, 9))
    for row, agreement in zip(axes, agreements, strict=True):
        for ax, condition in zip(row, ("position", "force"), strict=True):
            line = verdict_boundary(agreement, condition=condition)
            plot_verdict_map(agreement, condition=condition, boundary=line, ax=ax)
    save(fig, "multibody_verdict_map")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (name, conv) in zip(axes, convergence.items(), strict=True):
        plot_convergence(
            conv["omega"],
            {p: conv[p] for p in PROJECTIONS},
            ax=ax,
            title=f"{name}: position condition, D = 0.15, f = 0.3",
        )
    save(fig, "multibody_convergence")

    progress("penalty design example")
    design = _design_example()
    bar = falling_bar().reduce(1.0, 0.0, design["speed"])
    fig, ax = plt.subplots(figsize=(6, 4.5))
    k_line = design["k"] * np.geomspace(0.1, 10.0, 5 if quick else 40)
    conditions = ("force",) if quick else ("position", "force")
    restitutions = () if quick else (0.2, design["target_restitution"], 0.8)
    plot_design_region(
        k_line,
        {c: stick_damping(bar, k_line, condition=c) for c in conditions},
        ax=ax,
        restitution_curves={
            e: damping_for_restitution(bar, k_line, e, condition="force") for e in restitutions
        },
        design=(design["k"], design["d"]),
        restitution_condition="force",
    )
    ax.set_title("falling bar at 0.5 m/s: admissible penalty parameters")
    save(fig, "multibody_design")

    table = out / "multibody_agreement.csv"
    rows = [row for agreement in agreements for row in agreement.rows()]
    write_records(table, list(rows[0]), rows)
    written.append(table)
    summary = out / "multibody_summary.json"
    write_text(
        summary,
        json.dumps(
            {
                "agreement": [row for a in agreements for row in a.summary()],
                "convergence": {
                    name: {key: np.asarray(val).tolist() for key, val in conv.items()}
                    for name, conv in convergence.items()
                },
                "design": design,
            },
            indent=2,
        ),
    )
    written.append(summary)
    tex = out / "multibody_reduced_equation.tex"
    write_text(tex, _latex_snippet())
    written.append(tex)
    return written


def _latex_snippet() -> str:
    """The reduced equation, its parameters and the falling bar's reduction in LaTeX."""
    lines = ["% impactsym: multibody penalty contact reduced to section 2 (paper section 3)"]
    for label, caption, body in latex_formulas():
        lines += [f"% {label}", f"{caption}:", r"\[", body, r"\]", ""]
    m, L, theta = sp.symbols(r"m L \vartheta", positive=True)
    x, y, th, vx, vy, om = sp.symbols("x y theta v_x v_y omega")
    bar = reduce_contact(
        sp.diag(m, m, m * L**2 / 12),
        sp.zeros(3, 1),
        L / 2 * sp.sin(th) - y,
        (x, y, th),
        (vx, vy, om),
        {th: theta, y: L / 2 * sp.sin(theta)},
        sp.Symbol("k"),
        sp.Symbol("d"),
    )
    lines += [
        "% mb-bar",
        r"Rigid bar (mass $m$, length $L$) falling on its end at the angle $\vartheta$:",
        r"\[",
        r"\tilde m = " + sp.latex(bar.m_eff),
        r"\]",
        "",
    ]
    return "\n".join(lines)
