"""Every figure the package draws follows :mod:`impactsym.plotting.style`: a unit on every
axis label, legends outside the data, contour and region labels readable on any colour.

Each public ``plot_*`` function of :mod:`impactsym.plotting` is drawn once from small
inputs (synthetic arrays where the function only draws them), so the check is fast and
misses no figure: a new plotting function without a case here fails the first test.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from types import SimpleNamespace

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib import patheffects
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgb

import impactsym.plotting
from impactsym.plotting.style import UNITS, has_unit, legend_outside

matplotlib.use("Agg")


def _contact_maps():
    from impactsym.results.contact import map_grid

    D, f, tau_c, e = map_grid(condition="force", n_points=8)
    line = np.geomspace(1e-3, 1.0, 20)
    return D, f, tau_c, e, (np.linspace(0.5, 1.0, 20), line)


def _agreement():
    # what agreement_sweep returns, as arrays: plotting only draws them
    D = np.array([0.05, 0.2, 0.8, 1.5])
    f = np.array([0.1, 0.5, 1.0, 3.0])
    full = np.array([3.1, 3.4, np.inf, np.inf])
    return SimpleNamespace(
        example="falling bar",
        D={"impulse": D, "normal": D * 1.1},
        f={"impulse": f, "normal": f * 0.9},
        t_full={"position": full, "force": full},
        t_reduced={
            (p, c): full * (1.01 if p == "impulse" else 1.05)
            for p in ("impulse", "normal")
            for c in ("position", "force")
        },
    )


def _rod_study():
    from impactsym.rod import contact_time_map

    return contact_time_map([0.3, 1.0, 5.0], [0.0, 0.5, 1.5])


def _histories(kappas=(np.inf,)):
    from impactsym.rod.history import time_history

    return [time_history(1.0, 0.2, kappa=k, t_max=4.0, n_points=60) for k in kappas]


def _rod_sequences():
    from impactsym.rod import impact_sequence

    return [impact_sequence(a, 0.0, t_max=6.0) for a in (0.5, 2.0)]


def _bounce_map():
    from impactsym.contact.bounce import bounce_map

    D, f = np.meshgrid(np.linspace(0.05, 1.5, 6), np.linspace(0.05, 1, 5))
    return bounce_map(D, f, condition="force")


def _bounce_pair():
    from impactsym.contact.bounce import bounce_sequence

    return [bounce_sequence(0.1, 0.2, condition=c) for c in ("position", "force")]


def _surface():
    from impactsym.results.contact import surface_grid

    return surface_grid(condition="force", n_points=6)


def _stick_map():
    speed, dampratio = np.geomspace(0.01, 3.0, 12), np.geomspace(0.05, 2.0, 10)
    S, Z = np.meshgrid(speed, dampratio)
    verdict = np.where(Z > 1.0, 0, np.where(S > 0.1, 2, 1))
    restitution = np.where(verdict > 0, np.clip(1.0 - Z, 0, 1), 0.0)  # contours 0.1-0.5
    return speed, dampratio, verdict, restitution


def _f_line():
    from impactsym.contact import stick_boundary

    f = np.geomspace(1e-3, 10.0, 30)
    return f, {c: stick_boundary(f, condition=c) for c in ("position", "force")}


def _band(x, level):
    """A predicted or measured mean with its range over touch phases (small inputs)."""
    x = np.asarray(x, float)
    return {"mean": level + 0 * x, "min": 0.98 * level + 0 * x, "max": 1.02 * level + 0 * x}


def _law_map():
    from impactsym.contact import law_contact_map

    d, f = np.meshgrid(np.linspace(0.1, 1.2, 5), np.geomspace(0.01, 10.0, 4))
    return law_contact_map("linear", d, f, condition="force")


#: function name -> a call drawing it from small inputs
CASES = {
    "plot_contact_surface": lambda m: m.plot_contact_surface(*_surface(), condition="force"),
    "plot_stick_boundary": lambda m: m.plot_stick_boundary(*_f_line()),
    "plot_contact_time_map": lambda m: m.plot_contact_time_map(
        *_contact_maps()[:3], condition="force", boundary=_contact_maps()[4]
    ),
    "plot_restitution_map": lambda m: m.plot_restitution_map(
        *_contact_maps()[:2],
        _contact_maps()[3],
        sticks=np.isinf(_contact_maps()[2]),
        condition="force",
        boundary=_contact_maps()[4],
    ),
    "plot_law_stick_boundary": lambda m: m.plot_law_stick_boundary(
        np.array([0.1, 0.5, 0.9]),
        {"position": np.array([3.0, 0.4, 1e-3]), "force": np.array([4.0, 0.5, 0.03])},
        law="tsuji",
    ),
    "plot_law_stick_boundaries": lambda m: m.plot_law_stick_boundaries(
        {"hunt-crossley": np.array([0.1, 1.0]), "tsuji": np.array([0.1, 0.5, 2.0])},
        {
            "hunt-crossley": {"position": np.array([1.4, 0.3])},
            "tsuji": {"position": np.array([1.9, 0.3, 0.0]), "force": np.array([2.0, 0.3, 0.05])},
        },
    ),
    "plot_law_restitution": lambda m: m.plot_law_restitution(
        {"linear": np.array([0.0, 0.5, 1.0]), "viscoelastic": np.array([0.0, 0.2, 1.0])},
        {
            "linear": {"position": np.array([1.0, 0.16, 0.0]), "force": np.array([1, 0.2, 0.1])},
            "viscoelastic": {"position": np.array([1.0, 0.8, 0.4])},
        },
    ),
    "plot_law_map": lambda m: m.plot_law_map(
        _law_map(), quantity="restitution", boundary=(np.array([0.3, 0.9]), [5.0, 0.03])
    ),
    "plot_bounce_sequence": lambda m: m.plot_bounce_sequence(_bounce_pair()[1]),
    "plot_bounce_sequences": lambda m: m.plot_bounce_sequences(_bounce_pair()),
    "plot_bounce_map": lambda m: m.plot_bounce_map(
        _bounce_map(), quantity="time_to_rest", boundary=(np.array([1.0, 0.6]), [0.1, 1.0])
    ),
    "plot_textbook_error": lambda m: m.plot_textbook_error(
        np.array([0.2, 0.5, 0.8]), {"MuJoCo": np.array([0.3, 0.6, 0.85])}
    ),
    "plot_stick_map": lambda m: m.plot_stick_map(*_stick_map()),
    "plot_timestep_restitution": lambda m: m.plot_timestep_restitution(
        np.geomspace(1e-4, 4e-3, 5),
        {"design": _band(np.geomspace(1e-4, 4e-3, 5), 0.5)},
        {"design": {"timestep": np.array([1e-3, 2e-3]), **_band(np.ones(2), 0.5)}},
        target=0.5,
    ),
    "plot_timestep_advice": lambda m: m.plot_timestep_advice(
        np.linspace(0.1, 0.9, 5), {"MuJoCo": 1e-3 * np.linspace(0.1, 0.9, 5)}
    ),
    "plot_at_timestep": lambda m: m.plot_at_timestep(
        np.linspace(0.1, 0.9, 5),
        {"continuous": _band(np.linspace(0.1, 0.9, 5), 1.0)},
        {"continuous": {"targets": np.array([0.3, 0.5]), **_band(np.ones(2), 1.0)}},
    ),
    "plot_side_by_side": lambda m: m.plot_side_by_side(
        np.linspace(0.2, 0.9, 5),
        {"MuJoCo": _band(np.linspace(0.2, 0.9, 5), 1.0)},
        {("MuJoCo", "native"): {"targets": np.array([0.3, 0.5]), "mean": np.array([0.4, 0.6])}},
    ),
    "plot_agreement": lambda m: m.plot_agreement(_agreement(), condition="force"),
    "plot_verdict_map": lambda m: m.plot_verdict_map(
        _agreement(), condition="force", boundary=(np.array([1.0, 0.7]), np.array([0.1, 3.0]))
    ),
    "plot_convergence": lambda m: m.plot_convergence(
        [100.0, 1000.0], {"impulse": [1e-2, 1e-4], "normal": [1e-1, 1e-2]}, title="bar"
    ),
    "plot_design_region": lambda m: m.plot_design_region(
        np.geomspace(1e3, 1e5, 5),
        {"force": 2 * np.sqrt(np.geomspace(1e3, 1e5, 5))},
        restitution_curves={0.5: 0.5 * np.sqrt(np.geomspace(1e3, 1e5, 5))},
        design=(1e4, 60.0),
        restitution_condition="force",
    ),
    "plot_time_history": lambda m: m.plot_time_history(_histories(), "y"),
    "plot_stiffness_comparison": lambda m: m.plot_stiffness_comparison(
        _histories((50.0, np.inf)), "N"
    ),
    "plot_contact_time_atlas": lambda m: m.plot_contact_time_atlas(
        _rod_study(), condition="position"
    ),
    "plot_contact_time_ratio": lambda m: m.plot_contact_time_ratio(_rod_study()),
    "plot_contact_time_atlases": lambda m: m.plot_contact_time_atlases(_rod_study()),
    "plot_sequence": lambda m: m.plot_sequence(_rod_sequences()[0], n_points=60),
    "plot_fixed_end_stress": lambda m: m.plot_fixed_end_stress(_rod_sequences()),
    "plot_restitution": lambda m: m.plot_restitution(_rod_sequences()),
    "plot_formula_errors": lambda m: m.plot_formula_errors(
        np.array([0.2, 0.5, 0.8]), np.array([[0.6, 0.7, 0.9], [0.2, 0.5, 0.8]]), ["a", "b"]
    ),
}


def plotting_functions() -> list[tuple[str, str]]:
    """``(module, function)`` of every public ``plot_*`` function of the package."""
    found = []
    for info in pkgutil.iter_modules(impactsym.plotting.__path__):
        module = importlib.import_module(f"impactsym.plotting.{info.name}")
        for name, obj in inspect.getmembers(module, inspect.isfunction):
            if name.startswith("plot_") and obj.__module__ == module.__name__:
                found.append((module.__name__, name))
    return sorted(found)


FUNCTIONS = plotting_functions()


def test_every_plotting_function_has_a_case():
    assert len(FUNCTIONS) >= 20
    assert sorted(CASES) == sorted(name for _, name in FUNCTIONS)


def _is_colorbar(ax) -> bool:
    return ax.get_label() == "<colorbar>"


def _axis_labels(ax) -> list[str]:
    """The labels an axes must carry: x and y (and z in 3-D); the long one of a colour bar."""
    if _is_colorbar(ax):
        return [label for label in (ax.get_xlabel(), ax.get_ylabel()) if label]
    labels = [ax.get_xlabel(), ax.get_ylabel()]
    if hasattr(ax, "get_zlabel"):
        labels.append(ax.get_zlabel())
    return labels


def _readable(text) -> bool:
    """Black text, or text of any colour with a stroke around it."""
    black = np.allclose(to_rgb(text.get_color()), 0.0)
    return black or any(isinstance(e, patheffects.withStroke) for e in text.get_path_effects())


def _is_map(ax) -> bool:
    return any(isinstance(c, QuadMesh) for c in ax.collections)


@pytest.mark.parametrize(("module", "name"), FUNCTIONS)
def test_figure_has_units_outside_legends_and_readable_labels(module, name):
    drawn = CASES[name](importlib.import_module(module))
    axes = drawn if isinstance(drawn, list | tuple | np.ndarray) else [drawn]
    fig = axes[0].figure
    fig.tight_layout()  # as impactsym.results.files.save_figure lays a figure out
    fig.canvas.draw()
    try:
        for ax in fig.axes:
            labels = _axis_labels(ax)
            assert labels, f"{name}: an axes without labels"
            for label in labels:
                assert has_unit(label), f"{name}: axis label {label!r} has no [unit] of {UNITS}"
            legend = ax.get_legend()
            if legend is not None and ax.name != "3d":
                box = legend.get_window_extent()
                for other in fig.axes:
                    assert not box.overlaps(other.get_window_extent()), (
                        f"{name}: legend over the data of {other.get_title() or other}"
                    )
            if _is_map(ax):
                for text in ax.texts:
                    assert _readable(text), f"{name}: label {text.get_text()!r} on a colour map"
    finally:
        plt.close(fig)


def test_legend_outside_refuses_an_unknown_place():
    ax = plt.figure().add_subplot()
    with pytest.raises(ValueError, match="where must be one of"):
        legend_outside(ax=ax, where="inside")
    plt.close(ax.figure)


def test_a_label_without_brackets_or_with_an_unknown_unit_has_no_unit():
    assert not has_unit("dampratio")
    assert not has_unit("speed (m/s)")  # the convention is square brackets
    assert not has_unit("time [fortnights]")
    assert has_unit(r"time $t\,/\,(L/c)$ [-] (dotted: reflections return)")
    assert has_unit("penalty damping $d$ [N s/m]")
