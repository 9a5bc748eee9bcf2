"""Figures of the engine bridge (:mod:`impactsym.plotting.engines`): they draw the
surveys of :mod:`impactsym.engines.survey` they are given."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from impactsym.plotting.engines import (
    plot_at_timestep,
    plot_stick_map,
    plot_textbook_error,
    plot_timestep_advice,
    plot_timestep_restitution,
)

matplotlib.use("Agg")


def test_textbook_error_draws_one_curve_per_engine_and_the_diagonal():
    targets = np.array([0.2, 0.5, 0.8])
    achieved = {"A": targets * 0.9, "B": targets * 1.1}
    ax = plot_textbook_error(targets, achieved)
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels == ["textbook: A", "textbook: B", "impactsym design (all engines)"]
    assert np.array_equal(ax.get_lines()[1].get_ydata(), achieved["B"])
    plt.close(ax.figure)


def test_stick_map_is_a_rasterized_mesh_of_the_verdicts():
    speed, dampratio = np.geomspace(0.01, 3.0, 6), np.geomspace(0.05, 2.0, 5)
    verdict = np.tile([0, 1, 2, 1, 1, 2], (5, 1))
    restitution = np.where(verdict > 0, 0.4, 0.0)
    ax = plot_stick_map(speed, dampratio, verdict, restitution, gravity=3.0)
    mesh = ax.collections[0]
    assert mesh.get_rasterized()
    assert np.array_equal(np.asarray(mesh.get_array()).reshape(5, 6), verdict)
    assert ax.get_title().startswith("MuJoCo, g = 3 m/s")
    plt.close(ax.figure)


def _band(x, mean):
    return {"mean": mean + 0 * x, "min": mean - 0.01 + 0 * x, "max": mean + 0.02 + 0 * x}


def test_timestep_restitution_draws_bands_lines_points_and_the_default_timestep():
    dt = np.geomspace(1e-4, 4e-3, 6)
    curves = {"A": _band(dt, 0.5), "B": _band(dt, 0.45)}
    points = {"timestep": np.array([5e-4, 2e-3]), "mean": np.array([0.5, 0.47])}
    points |= {"min": points["mean"] - 0.03, "max": points["mean"] + 0.01}
    ax = plot_timestep_restitution(dt, curves, {"B": points}, target=0.5, default_timestep=0.002)
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert np.array_equal(lines["A: predicted mean, phase band"].get_ydata(), curves["A"]["mean"])
    assert np.array_equal(lines["B: predicted mean, phase band"].get_xdata(), dt)
    bands = [
        c
        for c in ax.collections
        if type(c).__name__ in ("PolyCollection", "FillBetweenPolyCollection")
    ]
    assert len(bands) == 2
    top = bands[1].get_paths()[0].vertices[:, 1]
    assert top.max() == pytest.approx(0.47)
    assert top.min() == pytest.approx(0.44)
    (errorbar,) = ax.containers
    assert np.array_equal(errorbar.lines[0].get_xdata(), points["timestep"])
    assert np.array_equal(errorbar.lines[0].get_ydata(), points["mean"])
    segments = errorbar.lines[2][0].get_segments()
    ends = np.array([s[:, 1] for s in segments])
    assert ends == pytest.approx(np.array([[0.47, 0.51], [0.44, 0.48]]))
    assert lines["default timestep 0.002 s"].get_xdata()[0] == 0.002
    assert lines["target e = 0.5"].get_ydata()[0] == 0.5
    plt.close(ax.figure)


def test_timestep_advice_draws_one_log_curve_per_engine():
    e = np.linspace(0.1, 0.9, 5)
    ax = plot_timestep_advice(e, {"X": 1e-3 * e, "Y": 2e-3 * e}, default_timestep=None)
    assert [line.get_label() for line in ax.get_lines()] == ["X", "Y"]
    assert np.array_equal(ax.get_lines()[1].get_ydata(), 2e-3 * e)
    assert ax.get_yscale() == "log"
    plt.close(ax.figure)


def test_at_timestep_draws_ratio_bands_and_measured_points():
    e = np.linspace(0.1, 0.9, 5)
    points = {"targets": np.array([0.5]), "mean": [1.0], "min": [0.99], "max": [1.02]}
    ax = plot_at_timestep(e, {"c": _band(e, 1.0)}, {"c": points}, title="T")
    assert ax.get_title() == "T"
    assert np.array_equal(ax.get_lines()[0].get_ydata(), np.ones(5))
    (errorbar,) = ax.containers
    assert errorbar.lines[0].get_xdata().tolist() == [0.5]
    plt.close(ax.figure)
