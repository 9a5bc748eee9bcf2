"""Figures of the continued rod impact (:mod:`impactsym.plotting.rod_sequence`): they draw
the sequences they are given."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from impactsym.plotting.rod_sequence import plot_fixed_end_stress, plot_restitution
from impactsym.rod import impact_sequence

matplotlib.use("Agg")


def test_alpha_plots_take_their_points_from_the_sequences():
    sequences = [impact_sequence(a, 0.0, t_max=12.0) for a in (0.3, 1.0, 3.0)]
    ax = plot_restitution(sequences)
    assert np.array_equal(ax.lines[0].get_xdata(), [0.3, 1.0, 3.0])
    assert np.array_equal(ax.lines[0].get_ydata(), [s.restitution for s in sequences])
    plt.close(ax.figure)
    ax = plot_fixed_end_stress(sequences)
    assert np.array_equal(ax.lines[0].get_ydata(), [s.max_fixed_end_stress for s in sequences])
    assert "t \\leq 12" in ax.lines[0].get_label()
    plt.close(ax.figure)
