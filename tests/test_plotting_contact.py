"""Figures of the spring-damper contact (:mod:`impactsym.plotting.contact`): they draw
the arrays they are given; full-resolution maps are small PDFs."""

from __future__ import annotations

import math

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from impactsym.contact import stick_boundary
from impactsym.plotting.contact import (
    plot_contact_surface,
    plot_contact_time_map,
    plot_restitution_map,
    plot_stick_boundary,
)
from impactsym.results import contact as results
from impactsym.results.files import save_figure

matplotlib.use("Agg")

MEGABYTE = 1_000_000


@pytest.mark.parametrize("quantity", ["contact_time", "restitution"])
def test_maps_at_full_reproduce_resolution_are_small_vector_files(tmp_path, quantity):
    # 400 x 400 cells, as `impactsym reproduce` draws them: the cells are rasterized, the
    # PDF stays under 1 MB (5.8 MB as vector quads) and keeps its text as text
    D, f, tau_c, e = results.map_grid(condition="force", n_points=400)
    if quantity == "contact_time":
        ax = plot_contact_time_map(D, f, tau_c, condition="force")
    else:
        ax = plot_restitution_map(D, f, e, sticks=tau_c == math.inf, condition="force")
    paths = {p.suffix: p for p in save_figure(ax, tmp_path, "map")}
    pdf, png = paths[".pdf"], paths[".png"]
    assert pdf.stat().st_size < MEGABYTE
    assert b"/Subtype /Image" in pdf.read_bytes()
    assert png.stat().st_size > 0


def test_boundaries_are_drawn_as_given():
    f = np.geomspace(1e-3, 10.0, 40)
    curves = {c: stick_boundary(f, condition=c) for c in ("position", "force")}
    ax = plot_stick_boundary(f, curves)
    position, force = ax.get_lines()[:2]
    assert np.array_equal(position.get_xdata(), curves["position"])
    assert np.array_equal(force.get_ydata(), f)
    assert ax.get_ylim() == pytest.approx((1e-3, 10.0))
    plt.close(ax.figure)


def test_a_map_greys_exactly_the_sticking_cells():
    D, f, tau_c, _ = results.map_grid(condition="force", n_points=12)
    ax = plot_contact_time_map(D, f, tau_c, condition="force")
    colour, grey = ax.collections[:2]
    assert np.array_equal(np.ma.getmaskarray(colour.get_array()), np.isinf(tau_c))
    assert np.array_equal(~np.ma.getmaskarray(grey.get_array()), np.isinf(tau_c))
    plt.close(ax.figure)


def test_the_surface_ends_on_the_fold():
    D, f, first, second, (d_fold, f_fold, tau_fold) = results.surface_grid(
        condition="force", n_points=8
    )
    assert d_fold == pytest.approx(stick_boundary(f_fold, condition="force"))
    ax = plot_contact_surface(D, f, first, second, (d_fold, f_fold, tau_fold), condition="force")
    assert ax.get_title() == "Contact-time surface, force condition"
    plt.close(ax.figure)
