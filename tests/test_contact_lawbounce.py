"""Bounce sequences on the nonlinear laws, against one solve_ivp of the whole motion."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from impactsym.contact import bounce_sequence
from impactsym.contact.lawbounce import law_sequence, speed_exponents
from impactsym.contact.laws import p


def test_speed_exponents_are_the_hand_derived_powers():
    a_T = -(p - 1) / (p + 1)
    expected = {
        "linear": (0, 0, -1),
        "hertz-linear": (a_T, a_T, a_T - 1),
        "hunt-crossley": (a_T, 1, a_T - 1),
        "tsuji": (a_T, 0, a_T - 1),
        "viscoelastic": (sp.Rational(-1, 5), sp.Rational(1, 5), sp.Rational(-6, 5)),
    }
    for law, powers in expected.items():
        got = speed_exponents(law)
        assert all(sp.simplify(g - e) == 0 for g, e in zip(got, powers, strict=True)), law


def test_the_recursion_at_p_1_is_the_linear_sequence():
    old = bounce_sequence(0.1, 0.2, condition="position")
    new = law_sequence("linear", 0.1, 0.2, 1.0, condition="position", max_contacts=100)
    assert new.n_contacts == old.n_contacts
    np.testing.assert_allclose(new.start, old.start, rtol=1e-13)
    np.testing.assert_allclose(new.departure, old.departure_speed, rtol=0, atol=1e-14)


def test_linear_default_is_unchanged():
    a = bounce_sequence(0.1, 0.2, condition="force")
    b = bounce_sequence(0.1, 0.2, condition="force", law="linear", exponent=3.0)
    assert a == b
    assert a.law == "linear"


PHI = {
    "hunt-crossley": lambda z, w, d: z**1.5 * (1 + d * w),
    "viscoelastic": lambda z, w, d: z**1.5 + d * np.sqrt(z) * w,
    "hertz-linear": lambda z, w, d: z**1.5 + 2 * d * w,
}


def ivp_bounces(law, delta, f, n):
    """The whole motion in units of the first impact: z'' = f - phi(z, z') while z > 0
    (the first impact's numbers throughout), free flight z'' = f outside; contact by
    contact with solve_ivp and a terminal event at z = 0."""
    phi = PHI[law]

    def out(t, y):
        return y[0] if t > 1e-9 else 1.0

    out.terminal, out.direction = True, -1
    t, u, rows = 0.0, 1.0, []
    for _ in range(n):
        sol = solve_ivp(
            lambda s, y: [y[1], f - phi(max(y[0], 0.0), y[1], delta)],
            (0, 200), [0.0, u], method="DOP853", rtol=1e-12, atol=1e-14, events=out,
        )  # fmt: skip
        if not sol.t_events[0].size:
            rows.append((t, np.inf, u, 0.0))
            break
        tau, e = sol.t_events[0][0], -sol.y_events[0][0][1]
        rows.append((t, t + tau, u, e))
        t, u = t + tau + 2 * e / f, e
    return np.array(rows)


@pytest.mark.parametrize(
    ("law", "delta", "f"),
    [("hunt-crossley", 0.3, 0.2), ("viscoelastic", 0.4, 0.1), ("hertz-linear", 0.05, 0.05)],
)
def test_bounces_against_one_solve_ivp_of_the_motion(law, delta, f):
    seq = bounce_sequence(delta, f, condition="position", law=law)
    assert seq.sticks
    assert seq.n_contacts >= 3
    ref = ivp_bounces(law, delta, f, seq.n_contacts)
    assert len(ref) == seq.n_contacts
    np.testing.assert_allclose(seq.start, ref[:, 0], rtol=1e-8)
    np.testing.assert_allclose(seq.end, ref[:, 1], rtol=1e-8)
    np.testing.assert_allclose(seq.arrival_speed, ref[:, 2], rtol=1e-8)
    np.testing.assert_allclose(seq.departure_speed, ref[:, 3], rtol=1e-8, atol=1e-12)
    assert seq.time_to_rest == pytest.approx(ref[-1, 0], rel=1e-8)


def test_without_pressing_force_a_single_contact_under_either_condition():
    for condition in ("position", "force"):
        seq = bounce_sequence(0.5, 0.0, condition=condition, law="tsuji")
        assert seq.n_contacts == 1
        assert not seq.sticks
        assert seq.departure_speed[0] > 0


def test_no_damping_bounces_until_max_contacts():
    seq = bounce_sequence(0.0, 0.3, condition="position", law="hunt-crossley", max_contacts=4)
    assert seq.n_contacts == 4
    assert not seq.sticks
    np.testing.assert_allclose(seq.departure_speed, 1.0, rtol=1e-9)


def test_refusals():
    with pytest.raises(ValueError, match="law must be one of"):
        bounce_sequence(0.3, 0.2, condition="position", law="hertz")
    with pytest.raises(ValueError, match="exponent must be >= 1"):
        bounce_sequence(0.3, 0.2, condition="position", law="tsuji", exponent=0.5)
    with pytest.raises(TypeError, match="exponent must be a scalar"):
        bounce_sequence(0.3, 0.2, condition="position", law="tsuji", exponent=[1.5, 2.0])
    seq = bounce_sequence(0.3, 0.2, condition="position", law="tsuji")
    with pytest.raises(ValueError, match="linear law only"):
        seq.trajectory([1.0])


# the force condition: contact until the force vanishes, then the body flies while the
# massless element relaxes with zero force, z_e' = -R(z_e)/c (reduced force R(z) + c z')
REDUCED = {  # (R(z), c as a function of the damping number)
    "viscoelastic": (lambda z: z, lambda d: d),
    "hertz-linear": (lambda z: z**1.5, lambda d: 2 * d),
    "tsuji": (lambda z: z**1.25, lambda d: d),
}
PHI["tsuji"] = lambda z, w, d: z**1.5 + d * z**0.25 * w


def ivp_force_bounces(law, delta, f, n, t_end=400.0):
    """The whole motion in first-impact units with solve_ivp: contact z'' = f - phi until
    the terminal event "reduced force falls through 0"; then flight of the body (z_b'' =
    f) and relaxation of the element (z_e' = -R(z_e)/c) until the terminal event "body
    meets element" (z_b - z_e rising through 0); the next contact starts from there."""
    phi, (R, c_of) = PHI[law], REDUCED[law]
    c = c_of(delta)
    opts = {"method": "DOP853", "rtol": 1e-13, "atol": 1e-15}
    t, z, w, rows = 0.0, 0.0, 1.0, []
    for _ in range(n):

        def released(s, y):
            return R(max(y[0], 0.0)) + c * y[1]

        released.terminal, released.direction = True, -1
        sol = solve_ivp(lambda s, y: [y[1], f - phi(max(y[0], 0.0), y[1], delta)],
                        (t, t_end), [z, w], events=released, **opts)  # fmt: skip
        if not sol.t_events[0].size:
            rows.append((t, np.inf, w, 0.0, z))
            break
        t1, (zc, wc) = sol.t_events[0][0], sol.y_events[0][0]
        rows.append((t, t1, w, -wc, z))

        def meet(s, y, t1=t1):
            return y[0] - y[2] if s > t1 + 1e-9 else -1.0

        meet.terminal, meet.direction = True, 1
        sol = solve_ivp(lambda s, y: [y[1], f, -R(max(y[2], 0.0)) / c], (t1, t_end),
                        [zc, wc, zc], events=meet, **opts)  # fmt: skip
        t, (_, w, z) = sol.t_events[0][0], sol.y_events[0][0]
    return np.array(rows)


@pytest.mark.parametrize(
    ("law", "delta", "f"),
    [("tsuji", 0.4, 0.05), ("viscoelastic", 0.5, 0.1), ("hertz-linear", 0.1, 0.05)],
)
def test_force_bounces_against_one_solve_ivp_of_the_motion(law, delta, f):
    seq = bounce_sequence(delta, f, condition="force", law=law)
    assert seq.sticks
    assert seq.n_contacts >= 3
    assert np.all(seq.element_deflection[1:] > 0)  # every re-contact meets a deflected element
    ref = ivp_force_bounces(law, delta, f, seq.n_contacts)
    assert len(ref) == seq.n_contacts
    np.testing.assert_allclose(seq.start, ref[:, 0], rtol=1e-8)
    np.testing.assert_allclose(seq.end, ref[:, 1], rtol=1e-8)
    np.testing.assert_allclose(seq.arrival_velocity, ref[:, 2], rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(seq.departure_speed, ref[:, 3], rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(seq.element_deflection, ref[:, 4], rtol=1e-7, atol=1e-14)
    assert seq.time_to_rest == pytest.approx(ref[-1, 0], rel=1e-8)


def test_linear_force_sequence_from_the_relaxing_element_is_section_2_s():
    """The nonlinear machinery on the linear law (b = 2 D f, element z_e' = -z_e/(2D)) meets
    the section-2 sequence of the closed forms (contact.loop)."""
    from impactsym.contact.lawbounce import law_sequences

    seq = law_sequences("linear", np.array([0.1]), np.array([0.2]), np.array([1.0]),
                        condition="force", max_contacts=100, record=True).sequence(0)  # fmt: skip
    ref = bounce_sequence(0.1, 0.2, condition="force")
    assert seq.n_contacts == ref.n_contacts
    np.testing.assert_allclose(seq.start, ref.start, rtol=1e-10)
    np.testing.assert_allclose(seq.departure, ref.departure_speed, rtol=0, atol=1e-12)
    np.testing.assert_allclose(seq.arrival_velocity, ref.arrival_velocity, rtol=0, atol=1e-12)
    np.testing.assert_allclose(seq.deflection, ref.element_deflection, rtol=0, atol=1e-12)


def test_hunt_crossley_force_sequence_is_its_position_sequence():
    """Its force vanishes only with the overlap (under a pressing force the force rate at
    a zero is s z^p b > 0): every contact starts undeformed, as under the position
    condition (there: rescaled to each arrival speed; here: in first-impact units)."""
    a = bounce_sequence(0.3, 0.2, condition="force", law="hunt-crossley")
    b = bounce_sequence(0.3, 0.2, condition="position", law="hunt-crossley")
    assert a.n_contacts == b.n_contacts
    np.testing.assert_allclose(a.start, b.start, rtol=1e-10)
    np.testing.assert_allclose(a.departure_speed, b.departure_speed, rtol=0, atol=1e-10)
    assert np.all(a.element_deflection == 0)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_bounce_map_on_a_law_is_the_sequences_point_by_point(condition):
    from impactsym.contact import bounce_map

    D, f = np.array([0.3, 2.0]), np.array([[0.1]])
    m = bounce_map(D, f, condition=condition, law="viscoelastic")
    assert m.law == "viscoelastic"
    assert m.n_contacts.shape == (1, 2)
    for i in range(1):
        for j in range(2):
            seq = bounce_sequence(D[j], f[i, 0], condition=condition, law="viscoelastic")
            assert m.n_contacts[i, j] == seq.n_contacts
            assert m.sticks[i, j] == seq.sticks
            assert m.time_to_rest[i, j] == pytest.approx(seq.time_to_rest, rel=1e-12)


# the clipped condition: the engines' max(0, F) on the geometric overlap; the body coasts
# inside the overlap where the force would pull, may be caught again, and leaves at z = 0
CLIP_PHI = {  # the force and the reduced force (its sign), first-impact units, b
    "linear": (lambda z, w, d: z + 2 * d * w, lambda z, w, d: z + 2 * d * w),
    "tsuji": (lambda z, w, d: z**1.5 + d * z**0.25 * w, lambda z, w, d: z**1.25 + d * w),
    "viscoelastic": (lambda z, w, d: z**1.5 + d * np.sqrt(z) * w, lambda z, w, d: z + d * w),
    "hertz-linear": (lambda z, w, d: z**1.5 + 2 * d * w, lambda z, w, d: z**1.5 + 2 * d * w),
}


def ivp_clipped_bounces(law, delta, b, n, t_rest=300.0):
    """The whole motion in first-impact units with solve_ivp, nothing of the package:
    three modes switched by terminal events, contact (z'' = b - phi) -> coast (z'' = b,
    the reduced force falls through 0) -> contact (it rises through 0), either -> flight
    (z = 0 falling; z'' = b) -> contact (z = 0 rising). A contact that has not left
    ``t_rest`` after its start sticks. Rows (start, end, arrival, departure)."""
    force, red = CLIP_PHI[law]
    opts = {"method": "DOP853", "rtol": 1e-13, "atol": 1e-15}
    t, y, rows = 0.0, [0.0, 1.0], []
    while len(rows) < n:
        start, u, mode = t, y[1], "contact"
        while True:

            def out(s, y, t=t):
                return y[0] if s > t + 1e-12 else 1.0

            def zero(s, y):
                return red(max(y[0], 0.0), y[1], delta)

            out.terminal, out.direction = True, -1
            zero.terminal, zero.direction = True, (-1 if mode == "contact" else 1)

            def rhs(s, y, mode=mode):
                push = force(max(y[0], 0.0), y[1], delta) if mode == "contact" else 0.0
                return [y[1], b - push]

            sol = solve_ivp(rhs, (t, start + t_rest), y, events=[out, zero], **opts)
            if sol.t_events[0].size:
                t, y = sol.t_events[0][0], list(sol.y_events[0][0])
                rows.append((start, t, u, -y[1]))
                break
            if not sol.t_events[1].size:
                rows.append((start, np.inf, u, 0.0))
                return np.array(rows)
            t, y = sol.t_events[1][0], list(sol.y_events[1][0])
            mode = "coast" if mode == "contact" else "contact"
        t, y = t + 2.0 * -y[1] / b, [0.0, -y[1]]  # the flight z'' = b from z = 0 to z = 0
    return np.array(rows)


@pytest.mark.parametrize(
    ("law", "delta", "f"),
    [("tsuji", 1.0, 0.02), ("linear", 0.1, 0.2), ("viscoelastic", 0.5, 0.05),
     ("hertz-linear", 0.1, 0.02)],
)  # fmt: skip
def test_clipped_bounces_against_one_solve_ivp_of_the_motion(law, delta, f):
    seq = bounce_sequence(delta, f, condition="clipped", law=law)
    assert seq.sticks
    assert seq.n_contacts >= 3
    assert np.all(seq.element_deflection == 0)
    b = 2 * delta * f if law == "linear" else f
    ref = ivp_clipped_bounces(law, delta, b, seq.n_contacts)
    assert len(ref) == seq.n_contacts
    np.testing.assert_allclose(seq.start, ref[:, 0], rtol=1e-8)
    np.testing.assert_allclose(seq.end, ref[:, 1], rtol=1e-8)
    np.testing.assert_allclose(seq.arrival_speed, ref[:, 2], rtol=1e-8)
    np.testing.assert_allclose(seq.departure_speed, ref[:, 3], rtol=1e-8, atol=1e-12)
    assert seq.time_to_rest == pytest.approx(ref[-1, 0], rel=1e-8)
    # the coast matters: the clipped sequence is neither the position nor the force one
    pos = bounce_sequence(delta, f, condition="position", law=law)
    assert not np.allclose(pos.departure_speed[:2], seq.departure_speed[:2], rtol=1e-3)


def test_law_sequence_refuses_the_force_condition():
    with pytest.raises(ValueError, match="condition must be 'position' or 'clipped' here"):
        law_sequence("tsuji", 0.3, 0.1, 1.5, condition="force", max_contacts=5)


def test_linear_clipped_sequence_is_lammps_limit_damping_contact_by_contact():
    """LAMMPS's continuous Hooke contact under limit_damping and gravity
    (engines.lammps.predict: force release, then the closed-form coast) at each arrival
    speed gives the next departure speed; the body sticks where LAMMPS's force comes back."""
    from impactsym.engines.lammps import predict

    kn, eta, m, v0, g = 2000.0, 4.0, 0.5, 1.0, 9.81
    D, f = eta / (2 * np.sqrt(kn * m)), m * g / (eta * v0)
    seq = bounce_sequence(D, f, condition="clipped")
    assert seq.law == "linear"
    assert seq.sticks
    assert seq.n_contacts >= 4
    omega0 = np.sqrt(kn / m)
    for n in range(seq.n_contacts):
        c = predict(kn=kn, damping=eta, mass=m, speed=seq.arrival_speed[n] * v0, gravity=g,
                    limit_damping=True)  # fmt: skip
        if n < seq.n_contacts - 1:
            assert not c.sticks
            assert c.departure_speed / v0 == pytest.approx(seq.departure_speed[n], rel=1e-10)
            # contact: the force end plus the coast, longer than LAMMPS's force end
            assert (seq.end[n] - seq.start[n]) / omega0 > c.contact_time
            assert seq.start[n + 1] - seq.end[n] == pytest.approx(
                2 * seq.departure_speed[n] / (2 * D * f), rel=1e-12
            )
        else:
            assert c.sticks
    with pytest.raises(ValueError, match="linear law only"):
        seq.trajectory([1.0])


def test_clipped_without_pressing_force_leaves_once_with_the_force_restitution():
    seq = bounce_sequence(0.5, 0.0, condition="clipped", law="tsuji")
    force = bounce_sequence(0.5, 0.0, condition="force", law="tsuji")
    assert seq.n_contacts == 1
    assert not seq.sticks
    assert seq.departure_speed[0] == pytest.approx(force.departure_speed[0], rel=1e-12)
    assert seq.end[0] > force.end[0]  # the coast to zero overlap


@pytest.mark.parametrize("law", ["linear", "tsuji"])
def test_clipped_bounce_map_is_the_sequences_point_by_point(law):
    from impactsym.contact import bounce_map

    D, f = np.array([0.1, 0.5, 3.0]), np.array([[0.05], [0.2]])
    m = bounce_map(D, f, condition="clipped", law=law)
    assert m.condition == "clipped"
    assert m.n_contacts.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            seq = bounce_sequence(D[j], f[i, 0], condition="clipped", law=law)
            assert m.n_contacts[i, j] == seq.n_contacts
            assert m.sticks[i, j] == seq.sticks
            assert m.time_to_rest[i, j] == pytest.approx(seq.time_to_rest, rel=1e-12)
