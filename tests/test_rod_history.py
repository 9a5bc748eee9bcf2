"""Sampled rod time histories (:mod:`impactsym.rod.history`) against closed forms
written out here and SciPy quadrature and root finding."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from impactsym.rod.history import time_history


def force_before_4(t, alpha):
    """Rigid contact, f = 0: the impact wave, and from t = 2 its reflection (t < 4)."""
    n = np.exp(-t / alpha)
    later = t >= 2
    u = np.where(later, t - 2, 0.0)
    return n + np.where(later, 2 * np.exp(-u / alpha) * (1 - u / alpha), 0.0)


@pytest.mark.parametrize("alpha", [0.3, 0.5, 0.8])
def test_rigid_history_is_the_wave_solution_and_its_zeros(alpha):
    h = time_history(alpha, 0.0, t_max=3.9, n_points=400)
    assert h.t[0] == 0.0
    assert h.t[-1] < 3.9
    assert np.any(np.isclose(h.t, 2.0 - 1e-12, rtol=0, atol=1e-15))  # left limit kept
    early = h.t < 2
    assert h.contact_force[early] == pytest.approx(np.exp(-h.t[early] / alpha), abs=1e-15)
    assert h.displacement[early] == pytest.approx(
        alpha * (1 - np.exp(-h.t[early] / alpha)), abs=1e-15
    )
    assert h.contact_force == pytest.approx(force_before_4(h.t, alpha), abs=1e-13)

    # the striker: alpha y'' = -N, y(0) = 0, y'(0) = 1
    def y(t):
        return t - quad(lambda s: (t - s) * force_before_4(s, alpha), 0, t, points=[2.0])[0] / alpha

    t_force = brentq(lambda t: force_before_4(t, alpha), 2.0, 3.9, xtol=1e-15)
    t_position = brentq(y, 2.0, 3.9, xtol=1e-14)
    assert h.contact_time_force == pytest.approx(t_force, rel=1e-12)
    assert h.contact_time_position == pytest.approx(t_position, rel=1e-9)


def test_a_contact_that_outlasts_the_horizon_has_no_contact_time():
    h = time_history(20.0, 0.2, t_max=1.5, n_points=10)
    assert h.contact_time_force == np.inf
    assert h.contact_time_position == np.inf
    assert (h.alpha, h.f, h.kappa, h.t_max) == (20.0, 0.2, np.inf, 1.5)


def test_finite_stiffness_starts_from_rest_and_plots_itself():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h = time_history(1.0, 0.2, kappa=50.0, t_max=3.0, n_points=60)
    # the contact spring is relaxed at first touch
    assert h.contact_force[0] == pytest.approx(0.0, abs=1e-15)
    assert h.displacement[0] == pytest.approx(0.0, abs=1e-15)
    ax = h.plot("y")
    (line,) = [line for line in ax.lines if line.get_label().startswith("$")]
    assert np.array_equal(line.get_ydata(), h.displacement)
    plt.close(ax.figure)


@pytest.mark.parametrize(
    ("kwargs", "error", "pattern"),
    [
        ({"alpha": "x"}, TypeError, "^alpha must be a real number"),
        ({"alpha": [1.0, 2.0]}, TypeError, "^alpha must be a single number"),
        ({"f": -1.0}, ValueError, "^f must be >= 0"),
        ({"kappa": "x"}, TypeError, "^kappa "),
        ({"t_max": -1.0}, ValueError, "^t_max must be > 0"),
        ({"t_max": "3"}, TypeError, "^t_max must be a real number"),
        ({"n_points": 1}, ValueError, "^n_points must be an integer >= 2"),
        ({"n_points": 2.5}, ValueError, "^n_points must be an integer >= 2"),
    ],
)
def test_bad_input_is_refused_by_name(kwargs, error, pattern):
    args = {"alpha": 1.0, "f": 0.1, **kwargs}
    alpha, f = args.pop("alpha"), args.pop("f")
    with pytest.raises(error, match=pattern):
        time_history(alpha, f, **args)
