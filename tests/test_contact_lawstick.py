"""The stick/release boundary of every law, against the linear boundary and solve_ivp."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact import law_stick_boundary, stick_boundary


def _phi(law, delta, p=1.5):
    """The normalized contact force and its sign (reduced force), written out here."""
    if law == "hunt-crossley":
        return (lambda z, w: z**p * (1 + delta * w)), (lambda z, w: 1 + delta * w)
    if law == "tsuji":
        return (
            lambda z, w: z**p + delta * z ** ((p - 1) / 2) * w,
            lambda z, w: delta * w + z ** ((p + 1) / 2),
        )
    if law == "viscoelastic":
        return (lambda z, w: z**1.5 + delta * np.sqrt(z) * w), (lambda z, w: z + delta * w)
    return (lambda z, w: z**p + 2 * delta * w), (lambda z, w: z**p + 2 * delta * w)


def releases_ivp(law, delta, f, condition, t_max=40.0):
    """Whether the body of z'' = f - phi(z, z'), z(0) = 0, z'(0) = 1 leaves the contact:
    scipy's DOP853 with dense output, the contact function sampled finely (an event
    test at step ends would miss a dip below zero inside one step, near the boundary)."""
    phi, reduced = _phi(law, delta)

    def rhs(t, y):
        return [y[1], f - phi(max(y[0], 0.0), y[1])]

    sol = solve_ivp(rhs, (0, t_max), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    dense_output=True)  # fmt: skip
    t = np.linspace(1e-3, t_max, 400_001)
    z, w = sol.sol(t)
    g = z if condition == "position" else np.minimum(z, reduced(np.maximum(z, 0.0), w))
    return bool(g.min() < 0)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_linear_law_inverts_the_paper_boundary(condition):
    D = np.array([0.02, 0.3, 0.7, 0.95, 2.0, 8.0, 1e3])
    f_star = law_stick_boundary("linear", D, condition=condition)
    stuck_at_zero = (D >= 1) & (condition == "position")
    assert np.all(f_star[stuck_at_zero] == 0.0)
    back = stick_boundary(f_star[~stuck_at_zero], condition=condition)
    np.testing.assert_allclose(back, D[~stuck_at_zero], rtol=1e-9)


def test_scalar_in_scalar_out_and_no_damping_never_sticks():
    assert isinstance(law_stick_boundary("linear", 0.4, condition="force"), float)
    assert law_stick_boundary("hunt-crossley", 0.0, condition="force") == np.inf


@pytest.mark.parametrize(
    ("law", "delta", "condition", "width"),
    [("hunt-crossley", 0.5, "position", 1e-4), ("tsuji", 1.0, "position", 1e-4),
     ("tsuji", 1.0, "force", 1e-4), ("viscoelastic", 0.5, "force", 1e-4)],
)  # fmt: skip
def test_nonlinear_boundary_against_solve_ivp(law, delta, condition, width):
    f_star = law_stick_boundary(law, delta, condition=condition, rtol=1e-6)
    assert 0.0 < f_star < np.inf
    assert releases_ivp(law, delta, f_star * (1 - width), condition)
    assert not releases_ivp(law, delta, f_star * (1 + width), condition)


@pytest.mark.parametrize(("law", "delta"), [("tsuji", 1.0), ("hertz-linear", 0.3)])
def test_force_boundary_to_1e_4(law, delta):
    """The force condition's boundary: a release whose force dips through zero inside one
    integration step is found (the kernel looks for a minimum of the force in the step)."""
    f_star = law_stick_boundary(law, delta, condition="force", rtol=1e-7)
    assert releases_ivp(law, delta, f_star * (1 - 1e-4), "force")
    assert not releases_ivp(law, delta, f_star * (1 + 1e-4), "force")


def test_hertz_linear_sticks_without_force_beyond_its_trap():
    # position condition, f = 0: z' = -D z is invariant inside z^(p-1) < D^2: sticks
    f_star = law_stick_boundary("hertz-linear", [1.0, 3.0], condition="position", rtol=1e-3)
    assert f_star.tolist() == [0.0, 0.0]
    assert not releases_ivp("hertz-linear", 1.0, 0.0, "position")


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"damping_number": -0.1}, ValueError, "damping_number must be >= 0"),
        ({"damping_number": "0.3"}, TypeError, "damping_number"),
        ({"exponent": 0.5}, ValueError, "exponent must be >= 1"),
        ({"rtol": 0.5}, ValueError, "rtol must be a float"),
        ({"law": "hertz"}, ValueError, "law must be one of"),
        ({"condition": "both"}, ValueError, "condition must be"),
    ],
)
def test_bad_input_is_refused(kwargs, error, message):
    call = {"law": "tsuji", "damping_number": 0.3, "condition": "force", **kwargs}
    law = call.pop("law")
    with pytest.raises(error, match=message):
        law_stick_boundary(law, **call)


def test_condition_is_required():
    with pytest.raises(TypeError, match="condition"):
        law_stick_boundary("tsuji", 0.3)


def releases_clipped_ivp(law, delta, f, t_max=200.0):
    """Whether a clipped contact leaves: solve_ivp on the piecewise system (contact
    z'' = f - phi, coast z'' = f where the force would be tensile), switched by terminal
    events of the reduced force, ended by the terminal event z = 0."""
    phi, reduced = _phi(law, delta)
    t, y, contact = 0.0, [0.0, 1.0], True
    while True:

        def out(s, y, t=t):
            return y[0] if s > t + 1e-12 else 1.0

        def zero(s, y):
            return reduced(max(y[0], 0.0), y[1])

        out.terminal = zero.terminal = True
        out.direction, zero.direction = -1, (-1 if contact else 1)

        def rhs(s, y, contact=contact):
            return [y[1], f - (phi(max(y[0], 0.0), y[1]) if contact else 0.0)]

        sol = solve_ivp(rhs, (t, t_max), y, method="DOP853", rtol=1e-12, atol=1e-15,
                        events=[out, zero])  # fmt: skip
        if sol.t_events[0].size:
            return True
        if not sol.t_events[1].size:
            return False
        t, y, contact = sol.t_events[1][0], list(sol.y_events[1][0]), not contact


def test_clipped_linear_boundary_is_where_the_coast_stops_reaching_the_surface():
    """f*: the force-condition release speed e equals 4 D b = 8 D^2 f (the coast's
    parabola 2De - es + bs^2/2 just touches z = 0), below the force condition's f*."""
    from impactsym.contact import restitution

    D = np.array([0.05, 0.3, 0.7, 2.0])
    f_star = law_stick_boundary("linear", D, condition="clipped")
    e = restitution(D, f_star, condition="force")
    np.testing.assert_allclose(e, 8 * D**2 * f_star, rtol=1e-8)
    assert np.all(f_star < law_stick_boundary("linear", D, condition="force"))


@pytest.mark.parametrize(("law", "delta"), [("tsuji", 1.0), ("viscoelastic", 0.5)])
def test_clipped_boundary_against_solve_ivp(law, delta):
    f_star = law_stick_boundary(law, delta, condition="clipped", rtol=1e-6)
    assert releases_clipped_ivp(law, delta, f_star * (1 - 1e-4))
    assert not releases_clipped_ivp(law, delta, f_star * (1 + 1e-4))
    # between the position and the force boundaries (the table of docs/physics.md)
    assert {"tsuji": 0.07605, "viscoelastic": 0.3265}[law] < f_star
    assert f_star < {"tsuji": 0.14772, "viscoelastic": 0.3547}[law]
