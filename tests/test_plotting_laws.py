"""Figures of the laws: they draw what they are given, with the law's own labels."""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from impactsym.plotting.laws import plot_law_map, plot_law_stick_boundary

matplotlib.use("Agg")


def _result(law="hunt-crossley", f=(0.1, 1.0, 10.0)):
    d, ff = np.meshgrid([0.1, 0.5, 1.0], f)
    t = np.where(ff * d > 2.0, np.inf, 3.0 + d)
    return SimpleNamespace(law=law, condition="position", damping_number=d, f=ff,
                           contact_time=t, restitution=np.where(np.isinf(t), 0.0, 0.5),
                           sticks=np.isinf(t))  # fmt: skip


def test_boundary_draws_the_given_lines_and_leaves_out_zeros():
    d = np.array([0.1, 0.5, 1.0])
    ax = plot_law_stick_boundary(d, {"position": np.array([2.0, 0.3, 0.0])}, law="tsuji")
    y = ax.get_lines()[0].get_ydata()
    assert y[:2].tolist() == [2.0, 0.3]
    assert np.isnan(y[2])
    assert ax.get_yscale() == "log"
    assert "alpha" in ax.get_xlabel()
    plt.close(ax.figure)


def test_map_labels_and_scale():
    ax = plot_law_map(_result(), quantity="restitution", boundary=([0.2, 1.0], [10.0, 2.0]))
    assert ax.get_title() == "Coefficient of restitution, hunt-crossley law, position condition"
    assert r"s = \lambda v_0" in ax.get_xlabel()
    assert ax.get_yscale() == "log"
    plt.close(ax.figure)
    ax = plot_law_map(_result(f=(0.0, 1.0, 10.0)))
    assert ax.get_yscale() == "linear"
    plt.close(ax.figure)


def test_bad_choices_are_refused():
    with pytest.raises(ValueError, match="quantity must be one of"):
        plot_law_map(_result(), quantity="peak_force")
    with pytest.raises(ValueError, match="law must be one of"):
        plot_law_map(_result(law="hertz"))
    with pytest.raises(ValueError, match="condition must be"):
        plot_law_stick_boundary([0.1], {"both": [1.0]}, law="tsuji")
