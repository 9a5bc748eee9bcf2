"""Figures of the bounce sequence (:mod:`impactsym.plotting.bounce`): they draw the
sequences and maps they are given, and a full-resolution map stays a small PDF."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from impactsym.contact.bounce import BounceMap, bounce_map, bounce_sequence
from impactsym.contact.lawstick import law_stick_boundary
from impactsym.plotting.bounce import plot_bounce_map, plot_bounce_sequence, plot_bounce_sequences
from impactsym.results.files import save_figure

matplotlib.use("Agg")

MEGABYTE = 1_000_000


def test_map_plot_refuses_what_it_cannot_show():
    from impactsym.contact.bounce import bounce_map

    with pytest.raises(ValueError, match="quantity"):
        plot_bounce_map(bounce_map(np.ones((2, 2)), 0.1, condition="force"), quantity="speed")
    with pytest.raises(ValueError, match="2-D"):
        plot_bounce_map(bounce_map([0.1, 0.2], 0.1, condition="force"))


def test_sequences_share_one_time_axis_and_tau_max_is_t_max():
    pair = [bounce_sequence(0.1, 0.2, condition=c) for c in ("position", "force")]
    left, right = plot_bounce_sequences(pair)
    assert left.get_xlim() == right.get_xlim()
    assert left.get_xlim()[1] > max(s.start[-1] for s in pair)
    plt.close(left.figure)
    a = plot_bounce_sequence(pair[1], t_max=7.5)
    b = plot_bounce_sequence(pair[1], tau_max=7.5)
    assert a.get_xlim() == b.get_xlim() == (0.0, 7.5)
    assert np.array_equal(a.lines[0].get_ydata(), b.lines[0].get_ydata())
    plt.close("all")


def test_map_draws_the_boundary_it_is_given_and_nothing_else():
    D, f = np.meshgrid(np.linspace(0.05, 1.5, 6), np.linspace(0.05, 1, 5))
    result = bounce_map(D, f, condition="force")
    assert plot_bounce_map(result).get_lines() == []
    line = (np.array([1.0, 0.5]), np.array([0.1, 1.0]))
    (drawn,) = plot_bounce_map(result, boundary=line).get_lines()
    assert np.array_equal(drawn.get_xdata(), line[0])
    plt.close("all")


@pytest.mark.parametrize("quantity", ["n_contacts", "time_to_rest"])
def test_a_full_resolution_map_is_a_small_pdf(tmp_path, quantity):
    # the 300 x 240 grid of `impactsym reproduce`, as vector quads 2.7-4.3 MB
    D, f = np.meshgrid(np.linspace(0.0, 1.2, 300), np.geomspace(1e-3, 1.0, 240))
    rng = np.random.default_rng(1)
    n = rng.integers(1, 60, D.shape)
    sticks = rng.random(D.shape) > 0.1
    rest = np.where(sticks, rng.random(D.shape) * 100, np.inf)
    rest[::7, ::5] = 0.0  # the first contact sticks: white cells of their own
    result = BounceMap(D, f, n, rest, sticks, "force")
    pdf = save_figure(plot_bounce_map(result, quantity=quantity), tmp_path, "map")[1]
    assert pdf.stat().st_size < MEGABYTE
    assert b"/Subtype /Image" in pdf.read_bytes()


def test_a_law_map_draws_the_laws_own_stick_boundary():
    # the boundary line of a Tsuji map is law_stick_boundary over D, not the linear one
    D, f = np.meshgrid(np.linspace(0.1, 1.0, 4), np.linspace(0.05, 0.6, 3))
    for condition in ("clipped", "force"):
        result = bounce_map(D, f, condition=condition, law="tsuji", max_contacts=30)
        assert result.exponent == 1.5
        ax = result.plot()
        assert ax.get_title().endswith(f"{condition} condition")
        x, y = ax.get_lines()[0].get_data()
        expected = law_stick_boundary("tsuji", x, exponent=1.5, condition=condition)
        np.testing.assert_allclose(y, expected, rtol=1e-12)
