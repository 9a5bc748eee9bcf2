"""The clipped condition (coast inside the overlap, re-engagement) and the relaxing element,
against SciPy's solve_ivp on the piecewise system with terminal events, written out here.

The reference switches between contact (``z'' = b - phi``) and coast (``z'' = b``) at the
terminal events "reduced force falls through zero" and "reduced force rises through zero"
(re-engagement), and ends at the terminal event ``z = 0`` (falling); nothing of the
package is used, the laws are written by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact.lawcoast import coast, element, escape_energy, recontact
from impactsym.contact.lawkernel import integrate, law_functions
from tests.references.contact_laws import P, phi, sign


def clipped_reference(law, d, b, t_end=300.0):
    """(contact time, restitution, coasts, re-engagements); ``inf`` time where no exit."""
    t, y, mode, coasts, back = 0.0, [0.0, 1.0], "contact", 0, 0
    while True:

        def out(s, y, t=t):
            return y[0] if s > t + 1e-12 else 1.0

        def zero(s, y):
            return sign(law, y[0], y[1], d)

        out.terminal, out.direction = True, -1
        zero.terminal, zero.direction = True, (-1 if mode == "contact" else 1)
        if mode == "contact":

            def rhs(s, y):
                return [y[1], b - phi(law, y[0], y[1], d)]
        else:

            def rhs(s, y):
                return [y[1], b]

        sol = solve_ivp(
            rhs, (t, t_end), y, method="DOP853", rtol=1e-13, atol=1e-15, events=[out, zero]
        )
        if sol.t_events[0].size:
            return sol.t_events[0][0], -sol.y_events[0][0][1], coasts, back
        if not sol.t_events[1].size:
            return np.inf, 0.0, coasts, back
        t, y = sol.t_events[1][0], list(sol.y_events[1][0])
        coasts += mode == "contact"
        back += mode == "coast"
        mode = "coast" if mode == "contact" else "contact"


CASES = [
    # law, damping number, b: coasting out under a pressing force
    ("tsuji", 1.0, 0.05),
    ("tsuji", 2.0, 0.02),
    ("hertz-linear", 0.3, 0.05),
    ("viscoelastic", 0.5, 0.2),
    ("hunt-crossley", 0.5, 0.2),  # its force never vanishes under b > 0: the position exit
    ("tsuji", 3.0, 0.0),  # no pressing force: coast at constant speed
]


@pytest.mark.parametrize(("law", "d", "b"), CASES)
def test_clipped_impact_against_the_piecewise_solve_ivp(law, d, b):
    r = integrate(law, np.array([d]), np.array([b]), np.array([P]), condition="clipped")
    tau, e, coasts, _ = clipped_reference(law, d, b)
    assert np.isfinite(tau)
    assert not r.sticks[0]
    assert r.tau_c[0] == pytest.approx(tau, rel=1e-10)
    assert r.e[0] == pytest.approx(e, rel=1e-10)
    assert coasts == (0 if law == "hunt-crossley" else 1)


@pytest.mark.parametrize(("law", "d", "b"), [("tsuji", 0.5, 0.3), ("viscoelastic", 2.0, 0.05)])
def test_a_re_engaging_contact_sticks_as_the_reference_does(law, d, b):
    tau, _, coasts, back = clipped_reference(law, d, b)
    assert coasts == back == 1
    assert np.isinf(tau)
    r = integrate(law, np.array([d]), np.array([b]), np.array([P]), condition="clipped")
    assert r.sticks[0]
    assert np.isinf(r.tau_c[0])
    assert r.e[0] == 0.0


def test_a_pressed_sticking_contact_never_coasts_out():
    # hertz-linear D = 1, b = 0.1: no force zero at all before rest; the position verdict
    tau, _, coasts, _ = clipped_reference("hertz-linear", 1.0, 0.1)
    assert np.isinf(tau)
    assert coasts == 0
    r = integrate("hertz-linear", np.array([1.0]), np.array([0.1]), np.array([P]),
                  condition="clipped")  # fmt: skip
    assert r.sticks[0]
    assert r.z_max[0] >= 0.1 ** (1 / P)


def test_coast_events_are_the_piecewise_system_s():
    """One coast from a force zero: the closed-form exit and the Newton re-engagement
    against solve_ivp's events on z'' = b."""
    fns = law_functions("tsuji")
    d, q = np.array([0.5, 0.5]), np.array([P, P])
    b = np.array([0.3, 0.01])
    z1 = np.array([0.2, 0.2])
    w1 = -(z1 ** ((P + 1) / 2)) / d  # on the force zero
    got = coast(fns, z1, w1, d, b, q)
    for i in range(2):

        def back(s, y, i=i):
            return sign("tsuji", y[0], y[1], d[i]) if s > 1e-12 else -1.0

        def out(s, y):
            return y[0]

        back.terminal, back.direction, out.terminal = True, 1, True
        sol = solve_ivp(lambda s, y, i=i: [y[1], b[i]], (0, 100), [z1[i], w1[i]],
                        method="DOP853", rtol=1e-13, atol=1e-15, events=[out, back])  # fmt: skip
        leaves = bool(sol.t_events[0].size)
        assert got.leaves[i] == leaves
        k = 0 if leaves else 1
        assert got.duration[i] == pytest.approx(sol.t_events[k][0], rel=1e-10)
        assert got.w[i] == pytest.approx(sol.y_events[k][0][1], rel=1e-10)
    assert list(got.leaves) == [False, True]


@pytest.mark.parametrize("law", ["linear", "hertz-linear", "tsuji", "viscoelastic"])
def test_the_relaxing_element_and_the_recontact(law):
    """z_e' = w_0(z_e) (force zero) integrated by solve_ivp; the body meets it where the
    event z_b - z_e = 0 says."""
    fns = law_functions(law)
    d, q, b = np.array([0.4]), np.array([P]), np.array([0.2])
    zc = np.array([0.3])
    c = {"linear": 0.8, "hertz-linear": 0.8, "tsuji": 0.4, "viscoelastic": 0.4}[law]
    a = {"linear": 1.0, "hertz-linear": P, "tsuji": (P + 1) / 2, "viscoelastic": 1.0}[law]
    wc = -(zc**a) / c

    def rhs(s, y):
        return [-(max(y[0], 0.0) ** a) / c, y[2], b[0]]

    def meet(s, y):
        return y[1] - y[0] if s > 1e-9 else -1.0

    meet.terminal, meet.direction = True, 1
    sol = solve_ivp(rhs, (0, 100), [zc[0], zc[0], wc[0]], method="DOP853", rtol=1e-13,
                    atol=1e-15, events=meet, dense_output=True)  # fmt: skip
    s_ref = sol.t_events[0][0]
    half = 0.5 * s_ref
    assert element(fns, zc, np.array([half]), d, q)[0] == pytest.approx(sol.sol(half)[0], rel=1e-10)
    got = recontact(fns, zc, wc, d, b, q)
    assert got.flight[0] == pytest.approx(s_ref, rel=1e-9)
    assert got.z[0] == pytest.approx(sol.y_events[0][0][0], rel=1e-8)
    assert got.w[0] == pytest.approx(sol.y_events[0][0][2], rel=1e-9)


def test_escape_energy_of_the_linear_law_is_32_D4_b2():
    """Linear: a coast leaves only from z >= 8 D^2 b, where the bracket is 32 D^4 b^2."""
    fns = law_functions("linear")
    D, b = np.array([0.1, 0.5, 1.0]), np.array([0.2, 0.1, 0.05])
    got = escape_energy(fns, D, b, np.ones(3))
    np.testing.assert_allclose(got, 32 * D**4 * b**2, rtol=1e-9)
    assert escape_energy(law_functions("hunt-crossley"), D, b, np.full(3, P)).tolist() == [0.0] * 3
