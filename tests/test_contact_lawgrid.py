"""Contact-time and restitution maps of the laws, against closed forms and solve_ivp."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact import contact_time, law_contact_map, restitution


def test_linear_map_is_the_paper_contact():
    D, f = np.meshgrid([0.0, 0.1, 0.6, 1.2], [0.0, 0.3, 2.0])
    for condition in ("position", "force"):
        m = law_contact_map("linear", D, f, condition=condition)
        assert m.contact_time.shape == D.shape
        assert np.array_equal(m.contact_time, contact_time(D, f, condition=condition))
        assert np.array_equal(m.restitution, restitution(D, f, condition=condition))
        assert np.array_equal(m.sticks, np.isinf(m.contact_time))


def _ivp(delta, f, p=1.5):
    """Hertz-linear z'' = f - z^p - 2 delta z', position condition: (tau_c, e) by events."""

    def out(t, y):
        return y[0] if t > 1e-9 else 1.0

    out.terminal, out.direction = True, -1
    sol = solve_ivp(
        lambda t, y: [y[1], f - max(y[0], 0.0) ** p - 2 * delta * y[1]],
        (0, 100), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14, events=out,
    )  # fmt: skip
    return sol.t_events[0][0], -sol.y_events[0][0][1]


def test_hertz_linear_map_against_solve_ivp():
    delta, f = np.array([0.05, 0.2]), np.array([0.0, 0.1])
    m = law_contact_map("hertz-linear", delta[:, None], f, condition="position")
    for i, d in enumerate(delta):
        for j, fj in enumerate(f):
            tau, e = _ivp(d, fj)
            assert m.contact_time[i, j] == pytest.approx(tau, rel=1e-9)
            assert m.restitution[i, j] == pytest.approx(e, rel=1e-8)


def test_hunt_crossley_without_force_is_the_lambert_w_form():
    from scipy.special import lambertw

    s = np.array([0.1, 1.0, 4.0])
    m = law_contact_map("hunt-crossley", s, 0.0, exponent=2.0, condition="force")
    exact = (1 + np.real(lambertw(-(1 + s) * np.exp(-(1 + s))))) / s
    np.testing.assert_allclose(m.restitution, exact, rtol=1e-9)
    assert m.exponent.tolist() == [2.0, 2.0, 2.0]


def test_viscoelastic_ignores_the_exponent_and_large_force_sticks():
    a = law_contact_map("viscoelastic", 0.3, [0.1, 200.0], exponent=3.0, condition="force")
    b = law_contact_map("viscoelastic", 0.3, [0.1, 200.0], condition="force")
    assert np.array_equal(a.restitution, b.restitution)
    assert a.sticks.tolist() == [False, True]
    assert a.restitution[1] == 0.0


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="f must be >= 0"):
        law_contact_map("tsuji", 0.3, -1.0, condition="force")
    with pytest.raises(ValueError, match="cannot be broadcast"):
        law_contact_map("tsuji", np.ones(2), np.ones(3), condition="force")
    with pytest.raises(TypeError, match="condition"):
        law_contact_map("tsuji", 0.3, 0.1)


def test_the_map_draws_itself():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d, f = np.meshgrid([0.2, 0.6, 1.0], [0.01, 0.1, 1.0])
    m = law_contact_map("linear", d, f, condition="position")
    ax = m.plot(quantity="restitution")
    assert ax.get_title() == "Coefficient of restitution, linear law, position condition"
    plt.close(ax.figure)
