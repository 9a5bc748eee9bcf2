"""Figures of the engine bridge (:mod:`impactsym.plotting.engines`): they draw the
surveys of :mod:`impactsym.engines.survey` they are given."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from impactsym.plotting.engines import plot_stick_map, plot_textbook_error

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
