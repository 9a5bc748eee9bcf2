"""Figures of the rod impact (:mod:`impactsym.plotting.rod`): they draw the time histories
and maps they are given."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from impactsym.plotting.rod import plot_stiffness_comparison, plot_time_history
from impactsym.rod.history import time_history

matplotlib.use("Agg")


def test_time_history_draws_each_history_and_its_first_zero():
    runs = [time_history(0.5, 0.0, t_max=4.0, n_points=80), time_history(2.0, 0.5, t_max=6.0)]
    ax = plot_time_history(runs, "N")
    curves = [line for line in ax.lines if line.get_label().startswith("$")]
    assert len(curves) == 2
    for curve, run in zip(curves, runs, strict=True):
        assert np.array_equal(curve.get_ydata(), run.contact_force)
    dots = [line for line in ax.lines if line.get_marker() == "o"]
    assert dots[0].get_xdata()[0] == runs[0].contact_time_force
    assert ax.get_xlim() == (0.0, 6.0)  # the longest horizon
    plt.close(ax.figure)


def test_stiffness_comparison_labels_each_stiffness():
    runs = [time_history(1.0, 0.2, kappa=k, t_max=3.0, n_points=50) for k in (50.0, np.inf)]
    ax = plot_stiffness_comparison(runs, "y")
    labels = [line.get_label() for line in ax.lines if not line.get_label().startswith("_")]
    assert labels == ["$\\kappa = 50$", "rigid"]
    assert np.array_equal(ax.lines[-1].get_ydata(), runs[1].displacement)
    plt.close(ax.figure)


def test_an_unknown_quantity_is_refused():
    with pytest.raises(ValueError, match="quantity must be 'y' or 'N'"):
        plot_time_history([time_history(1.0, 0.0, t_max=2.0, n_points=5)], "v")
