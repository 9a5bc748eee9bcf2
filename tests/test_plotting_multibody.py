"""Figures of the multibody analysis (:mod:`impactsym.plotting.multibody`)."""

from __future__ import annotations

import numpy as np

from impactsym.multibody.simulation import falling_bar


def test_figures_return_their_axes():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from impactsym.multibody.simulation import agreement_sweep
    from impactsym.plotting.multibody import plot_agreement, plot_convergence, plot_verdict_map

    agreement = agreement_sweep(
        falling_bar(),
        omegas=(300.0,),
        dampings=(0.1, 1.0),
        forces=(0.2, 2.0),
        steps=16,
        t_max=25.0,
    )
    for plot in (plot_agreement, plot_verdict_map):
        fig, ax = plt.subplots()
        assert plot(agreement, condition="force", ax=ax) is ax
        plt.close(fig)
    fig, ax = plt.subplots()
    assert plot_convergence([1.0, 10.0], {"impulse": [0.1, 0.01]}, ax=ax) is ax
    plt.close(fig)


def test_design_region_draws_the_curves_it_is_given():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from impactsym.plotting.multibody import plot_design_region

    k = np.geomspace(1e3, 1e5, 5)
    boundary, curve = 2 * np.sqrt(k), 0.5 * np.sqrt(k)
    ax = plot_design_region(
        k,
        {"force": boundary},
        restitution_curves={0.5: curve},
        design=(1e4, 60.0),
        restitution_condition="force",
    )
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels == ["stick boundary (force)", "$e = 0.5$ (force)", "design"]
    assert np.array_equal(ax.get_lines()[0].get_ydata(), boundary)
    plt.close(ax.figure)
