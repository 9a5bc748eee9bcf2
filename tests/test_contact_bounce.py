"""The bounce sequence until rest (impactsym.contact.bounce) against an independent
event-driven simulation (tests/references/bounce.py), mpmath and solve_ivp in SI units."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from references import oscillator as ref_oscillator
from references.bounce import simulate
from scipy.integrate import solve_ivp

from impactsym.contact import bounce_sequence, contact_time, restitution
from impactsym.contact.bounce import bounce_map, physical_bounce


def _rows(seq):
    return np.c_[
        seq.start, seq.end, seq.arrival_velocity, seq.departure_speed, seq.element_deflection
    ]


# -- the sequence against an independent event-driven simulation --------------------------
CASES = [
    ("position", 0.1, 0.2),
    ("position", 0.5, 0.05),
    ("position", 0.9, 0.01),
    ("position", 1.0, 0.1),  # critical: sticks at once
    ("position", 0.03, 0.03),  # 59 contacts
    ("force", 0.1, 0.2),
    ("force", 0.26152373, 0.09816179),  # element deflected 370 times the arrival speed
    ("force", 0.5, 0.05),
    ("force", 1.0, 0.02),  # critical
    ("force", 1.1497, 0.01165714),  # over-damped, re-contact
    ("force", 2.0, 0.01),
    ("force", 0.03, 0.03),  # 60 contacts
]


@pytest.mark.parametrize(("condition", "d", "fr"), CASES)
def test_sequence_matches_event_driven_ode(condition, d, fr):
    seq = bounce_sequence(d, fr, condition=condition)
    rows, sticks = simulate(d, fr, condition)
    assert seq.n_contacts == len(rows)
    assert seq.sticks == sticks
    ours = _rows(seq)
    finite = np.isfinite(rows)
    assert np.array_equal(finite, np.isfinite(ours))
    scale = np.maximum(np.abs(rows[finite]), 1.0)
    err = np.abs(ours[finite] - rows[finite]) / scale
    assert err.max() < (1e-6 if len(rows) > 20 else 1e-8)
    if sticks:
        assert seq.time_to_rest == pytest.approx(rows[-1, 0], rel=1e-6)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_random_sequences_match_event_driven_ode(condition):
    """20 random (D, f) per condition, D in [0.05, 2], f in [0.02, 1], 15 contacts at most."""
    rng = np.random.default_rng(10)
    for d, fr in rng.uniform([0.05, 0.02], [2.0, 1.0], size=(20, 2)):
        seq = bounce_sequence(d, fr, condition=condition, max_contacts=15)
        rows, sticks = simulate(d, fr, condition, max_contacts=15)
        assert (seq.n_contacts, seq.sticks) == (len(rows), sticks), (d, fr)
        ours = _rows(seq)
        finite = np.isfinite(rows)
        assert np.array_equal(finite, np.isfinite(ours))
        np.testing.assert_allclose(ours[finite], rows[finite], rtol=1e-7, atol=1e-9)


def test_near_sticking_sequence_has_more_than_fifty_contacts():
    for condition in ("position", "force"):
        seq = bounce_sequence(0.03, 0.03, condition=condition)
        assert seq.sticks
        assert seq.n_contacts > 50


def test_recontact_caught_from_behind_against_ode():
    """The relaxing element catches a body that still moves away (arrival velocity < 0)."""
    d, fr = 0.4297, 0.2  # 0.4 % below the force stick boundary D*(0.2) = 0.4315
    seq = bounce_sequence(d, fr, condition="force")
    assert seq.arrival_velocity[1] < 0 < seq.element_deflection[1]
    rows, _ = simulate(d, fr, "force", max_contacts=2)
    assert rows[1, 0] == pytest.approx(seq.start[1], rel=1e-9)
    assert rows[1, 2] == pytest.approx(seq.arrival_velocity[1], rel=1e-7)
    assert rows[1, 4] == pytest.approx(seq.element_deflection[1], rel=1e-7)


@pytest.mark.parametrize(("d", "fr"), [(0.3, 0.3), (1.0, 0.02)])
def test_trajectory_follows_the_ode_through_contact_and_flight(d, fr):
    seq = bounce_sequence(d, fr, condition="force")
    t_release, t_back = seq.end[0], seq.start[1]
    contact = solve_ivp(
        lambda _t, y: [y[1], 2 * d * fr - 2 * d * y[1] - y[0]],
        (0, t_release),
        [0.0, 1.0],
        dense_output=True,
        rtol=1e-12,
        atol=1e-14,
    )
    z_c = contact.sol(t_release)
    flight = solve_ivp(
        lambda _t, y: [y[1], 2 * d * fr, -y[2] / (2 * d)],
        (t_release, t_back),
        [z_c[0], z_c[1], z_c[0]],
        dense_output=True,
        rtol=1e-12,
        atol=1e-14,
    )
    in_contact = np.linspace(0, t_release, 7)[1:-1]
    in_flight = np.linspace(t_release, t_back, 7)[1:-1]
    z, element = seq.trajectory(np.concatenate([in_contact, in_flight]))
    np.testing.assert_allclose(z[:5], contact.sol(in_contact)[0], atol=1e-9)
    np.testing.assert_allclose(element[:5], z[:5], rtol=0)
    np.testing.assert_allclose(z[5:], flight.sol(in_flight)[0], atol=1e-9)
    np.testing.assert_allclose(element[5:], flight.sol(in_flight)[2], atol=1e-9)
    assert (z[5:] < element[5:]).all()  # off the element during the flight


# -- position condition: the exact sums and the termination proof -------------------------
@pytest.mark.parametrize(("d", "fr"), [(0.1, 0.2), (0.05, 0.05), (0.7, 0.02)])
def test_position_sequence_is_the_exact_sum_of_first_contacts(d, fr):
    """v_{n+1} = e(D, f/v_n) v_n and flights 2 v_{n+1}/(2Df), from the public functions."""
    seq = bounce_sequence(d, fr, condition="position")
    speed, t, starts = 1.0, 0.0, []
    while True:
        starts.append(t)
        tau_c = contact_time(d, fr / speed, condition="position")
        if math.isinf(tau_c):
            break
        speed *= restitution(d, fr / speed, condition="position")
        t += tau_c + 2 * speed / (2 * d * fr)
    assert seq.n_contacts == len(starts)
    np.testing.assert_allclose(seq.start, starts, rtol=1e-12)
    assert seq.time_to_rest == pytest.approx(t, rel=1e-12)


def test_position_contact_sticks_beyond_the_closed_form_force_bound():
    damping = np.linspace(0.01, 0.99, 50)
    omega = np.sqrt(1 - damping**2)
    bound = 1 / (4 * damping * omega * np.sinh(np.pi * damping / omega))
    assert np.isinf(contact_time(damping, bound * (1 + 1e-9), condition="position")).all()
    # and the bound is not vacuous: somewhat below it the body can release
    assert np.isfinite(contact_time(damping, bound * 0.3, condition="position")).any()


@settings(max_examples=40, deadline=None)
@given(st.floats(0.02, 3.0), st.floats(0.02, 2.0))
def test_position_sequence_ends_with_falling_speeds(d, fr):
    seq = bounce_sequence(d, fr, condition="position", max_contacts=400)
    assert seq.sticks
    assert math.isfinite(seq.time_to_rest)
    assert np.isinf(seq.end[-1])
    assert seq.departure_speed[-1] == 0
    released = seq.departure_speed[:-1]
    assert (released < seq.arrival_speed[:-1]).all()
    assert (np.diff(seq.arrival_speed) < 0).all()


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 3.0), st.floats(0.0, 2.0), st.sampled_from(["position", "force"]))
def test_first_contact_is_the_section_2_contact(d, fr, condition):
    # one contact: a tiny f sends the second so far out that its end is refused
    seq = bounce_sequence(d, fr, condition=condition, max_contacts=1)
    assert seq.start[0] == 0
    assert seq.arrival_speed[0] == 1
    tau_c = contact_time(d, fr, condition=condition)
    if math.isinf(tau_c):
        assert math.isinf(seq.end[0])
        assert seq.n_contacts == 1
        assert seq.sticks
    else:
        assert seq.end[0] == pytest.approx(tau_c, rel=1e-14)
        assert seq.departure_speed[0] == pytest.approx(
            restitution(d, fr, condition=condition), rel=1e-12
        )


@settings(max_examples=40, deadline=None)
@given(st.floats(0.05, 3.0), st.floats(0.05, 2.0))
def test_force_sequence_rests_in_finite_time(d, fr):
    seq = bounce_sequence(d, fr, condition="force", max_contacts=400)
    assert seq.sticks
    assert math.isfinite(seq.time_to_rest)
    assert (np.diff(seq.start) > 0).all()
    assert (seq.element_deflection >= 0).all()
    # body + element energy at the contact starts never increases
    energy = 0.5 * seq.arrival_velocity**2 - 2 * d * fr * seq.element_deflection
    energy += 0.5 * seq.element_deflection**2
    assert (np.diff(energy) <= 1e-12).all()
    # the contact force at every start is compressive: 2 D v + z > 0
    force = 2 * d * seq.arrival_velocity + seq.element_deflection
    assert (force[1:] > 0).all()


# -- special points ----------------------------------------------------------------------
def test_without_pressing_force_the_body_leaves_for_good():
    for condition in ("position", "force"):
        seq = bounce_sequence(0.2, 0.0, condition=condition)
        assert seq.n_contacts == 1
        assert not seq.sticks
        assert math.isinf(seq.time_to_rest)
        assert seq.departure_speed[0] == restitution(0.2, 0.0, condition=condition)


def test_overdamped_without_force_creeps_back_and_counts_as_sticking():
    seq = bounce_sequence(1.0, 0.0, condition="position")
    assert seq.sticks
    assert seq.time_to_rest == 0
    assert math.isinf(seq.end[0])


def test_undamped_contact_is_elastic_and_never_returns():
    seq = bounce_sequence(0.0, 5.0, condition="force")
    assert seq.n_contacts == 1
    assert not seq.sticks
    assert seq.departure_speed[0] == pytest.approx(1.0)


def test_max_contacts_running_out_is_not_sticking():
    seq = bounce_sequence(0.01, 0.01, condition="position", max_contacts=5)
    assert seq.n_contacts == 5
    assert not seq.sticks
    assert math.isinf(seq.time_to_rest)


def test_map_matches_event_driven_ode():
    # every point of a map against the independent event-driven simulation
    damping = np.array([[0.05, 0.3], [1.0, 2.0]])
    force = np.array([[0.1, 0.1], [0.01, 0.3]])
    for condition in ("position", "force"):
        m = bounce_map(damping, force, condition=condition)
        assert m.n_contacts.shape == (2, 2)
        for i in np.ndindex(2, 2):
            rows, sticks = simulate(damping[i], force[i], condition)
            assert m.n_contacts[i] == len(rows), (condition, i)
            assert bool(m.sticks[i]) == sticks
            if sticks:
                assert m.time_to_rest[i] == pytest.approx(rows[-1, 0], rel=1e-6)
            else:
                assert math.isinf(m.time_to_rest[i])


# -- physical units ----------------------------------------------------------------------
def test_physical_bounce_force_condition_in_si_units_against_a_direct_simulation():
    """m x'' = F - k x - d x' in contact until k x + d x' = 0; then the body flies
    (m x'' = F) while the massless element relaxes (d x_e' + k x_e = 0) until they meet.
    Seconds, metres, newtons: no normalization."""
    m_, k, d, v_, F = 0.01, 1e3, 2.0, 0.5, 0.0981
    phys = physical_bounce(m_, k, d, v_, F, condition="force")

    def release(_t, y):
        return k * y[0] + d * y[1]

    def meet(_t, y):
        return y[0] - y[2]

    release.terminal, release.direction = True, -1
    meet.terminal, meet.direction = True, 1
    t, x, v = 0.0, 0.0, v_
    starts, arrivals, departures, deflections = [], [], [], []
    for _ in range(phys.n_contacts - 1):
        starts.append(t)
        arrivals.append(abs(v))
        deflections.append(x)
        sol = solve_ivp(
            lambda _t, y: [y[1], (F - k * y[0] - d * y[1]) / m_],
            (t, t + 1.0),
            [x, v],
            events=release,
            rtol=1e-12,
            atol=1e-15,
            method="DOP853",
        )
        t = sol.t_events[0][0]
        x, v = sol.y_events[0][0]
        departures.append(-v)
        sol = solve_ivp(
            lambda _t, y: [y[1], F / m_, -k * y[2] / d],
            (t, t + 1.0),
            [x, v, x],
            events=meet,
            rtol=1e-12,
            atol=1e-15,
            method="DOP853",
        )
        t = sol.t_events[0][0]
        x, v = sol.y_events[0][0][2], sol.y_events[0][0][1]
    starts.append(t)
    arrivals.append(abs(v))
    deflections.append(x)
    departures.append(0.0)  # the sticking contact
    assert phys.sticks
    np.testing.assert_allclose(phys.start, starts, rtol=1e-8)
    np.testing.assert_allclose(phys.arrival_speed, arrivals, rtol=1e-8)
    np.testing.assert_allclose(phys.departure_speed, departures, rtol=1e-8)
    np.testing.assert_allclose(phys.element_deflection, deflections, rtol=1e-8, atol=1e-15)
    assert phys.time_to_rest == pytest.approx(starts[-1], rel=1e-8)


def test_physical_bounce_in_seconds_against_a_direct_simulation():
    """m x'' = F - k x - d x' in contact, m x'' = F in flight, no normalization."""
    m_, k, d, v_, F = 0.02, 500.0, 0.4, 0.3, 0.02 * 9.81
    phys = physical_bounce(m_, k, d, v_, F, condition="position")

    def release(_t, y):
        return y[0]

    release.terminal, release.direction = True, -1
    t, v, starts = 0.0, v_, []
    for _ in range(phys.n_contacts - 1):
        starts.append(t)
        sol = solve_ivp(
            lambda _t, y: [y[1], (F - k * y[0] - d * y[1]) / m_],
            (t, t + 1.0),
            [0.0, v],
            events=release,
            rtol=1e-12,
            atol=1e-15,
        )
        t, v = sol.t_events[0][0], -sol.y_events[0][0][1]
        t += 2 * v / (F / m_)
    starts.append(t)
    np.testing.assert_allclose(phys.start, starts, rtol=1e-7)


def test_undamped_physical_bounce_under_load_repeats_for_ever():
    phys = physical_bounce(1.0, 1.0, 0.0, 1.0, 0.5, condition="position", max_contacts=4)
    assert not phys.sticks
    assert phys.n_contacts == 4
    assert math.isinf(phys.f)
    rows, _ = _undamped_reference(b=0.5)
    assert phys.end[0] == pytest.approx(rows[0], rel=1e-9)
    assert phys.start[1] == pytest.approx(rows[1], rel=1e-9)


def _undamped_reference(b):
    def release(_t, y):
        return y[0]

    release.terminal, release.direction = True, -1
    sol = solve_ivp(
        lambda _t, y: [y[1], b - y[0]], (0, 20), [0.0, 1.0], events=release, rtol=1e-12, atol=1e-14
    )
    end = sol.t_events[0][0]
    speed = -sol.y_events[0][0][1]
    return (end, end + 2 * speed / b), speed


# -- bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"D": -0.1, "f": 0.1, "condition": "force"}, ValueError, "D must be >= 0"),
        ({"D": 0.1, "f": float("nan"), "condition": "force"}, ValueError, "f must be finite"),
        ({"D": 0.1, "f": 0.1, "condition": "speed"}, ValueError, "condition"),
        ({"D": "0.1", "f": 0.1, "condition": "force"}, TypeError, "D must be a real"),
        ({"D": [0.1, 0.2], "f": 0.1, "condition": "force"}, TypeError, "D must be a scalar"),
        (
            {"D": 0.1, "f": 0.1, "condition": "force", "max_contacts": 0},
            ValueError,
            "max_contacts must be >= 1",
        ),
        (
            {"D": 0.1, "f": 0.1, "condition": "force", "max_contacts": 2.5},
            TypeError,
            "max_contacts must be an integer",
        ),
    ],
)
def test_bad_input_names_the_argument(kwargs, error, message):
    D_, f_ = kwargs.pop("D"), kwargs.pop("f")
    with pytest.raises(error, match=message):
        bounce_sequence(D_, f_, **kwargs)


def test_bad_physical_input_names_the_argument():
    with pytest.raises(ValueError, match="m must be > 0"):
        physical_bounce(0.0, 1.0, 1.0, 1.0, 1.0, condition="force")
    with pytest.raises(ValueError, match="F must be >= 0"):
        physical_bounce(1.0, 1.0, 1.0, 1.0, -1.0, condition="force")
    with pytest.raises(ValueError, match="f must be >= 0"):
        bounce_map([0.1], [-1.0], condition="force")


def test_bounce_sequence_at_huge_damping_warns_nothing():
    # sqrt((D - 1)(D + 1)) overflowed for D > 1.3e154 (warnings are errors here)
    assert bounce_sequence(1e300, 1.0, condition="force").n_contacts == 1


# -- extremes: nothing silently wrong (against mpmath at 40 digits) ------------------------
def test_a_contact_end_the_absolute_time_cannot_resolve_is_refused_by_name():
    """D = 1e-6, f = 1e-9: the second contact starts at tau ~ 1e15 (mpmath), where floats
    are 0.125 apart, so its end (duration ~ pi) cannot be told from its start; it used to
    come out as end == start for 1963 contacts. Refused, naming the inputs and the contact;
    the contacts before it and the map stay available."""
    d, fr = 1e-6, 1e-9
    with mp.workdps(40):
        tau_c = ref_oscillator.first_root(d, fr, "force", t_max=4.0, samples=40)
        u = -ref_oscillator.state(tau_c, d, fr)[1]
        ratio = 2 * mp.mpf(d) ** 2 * fr / u
        x = mp.findroot(lambda y: (y - 1 + mp.exp(-y)) / y**2 - ratio, 1 / ratio)
        second = float(tau_c + 2 * d * x)  # start of contact 2
    assert np.spacing(second) > 1e-6 * float(tau_c)  # the reference agrees: unresolvable
    for condition in ("force", "position"):
        pattern = r"^bounce_sequence\(D=1e-06, f=1e-09\): contact 2 starts at tau = 9.99997e\+14,"
        with pytest.raises(ValueError, match=pattern):
            bounce_sequence(d, fr, condition=condition, max_contacts=2000)
    first = bounce_sequence(d, fr, condition="force", max_contacts=1)
    assert first.end[0] == pytest.approx(float(tau_c), rel=1e-13)
    assert first.departure_speed[0] == pytest.approx(float(u), rel=1e-13)
    m = bounce_map(d, fr, condition="force", max_contacts=3)
    assert m.n_contacts.tolist() == 3
    assert not m.sticks


@pytest.mark.parametrize("condition", ["position", "force"])
@pytest.mark.parametrize(("d", "fr"), [(1e-150, 1e150), (1e-20, 1e20), (1e-12, 1e12)])
def test_vanishing_damping_never_gains_energy(condition, d, fr):
    """2 D f = 2 with D -> 0: e = 1 - O(D). The departure speed used to come out
    4.4e-16 above the arrival speed (rounding above the dissipation); now it never
    exceeds it and matches the 40-digit contact."""
    seq = bounce_sequence(d, fr, condition=condition, max_contacts=6)
    assert (seq.departure_speed <= seq.arrival_speed).all()
    assert (seq.end > seq.start).all()
    with mp.workdps(40):
        tau_c = ref_oscillator.first_root(d, fr, condition, t_max=7.0, samples=70)
        e = -ref_oscillator.state(tau_c, d, fr)[1]
    assert seq.end[0] == pytest.approx(float(tau_c), rel=1e-13)
    assert abs(seq.departure_speed[0] - float(e)) <= 1e-15
    assert float(e) <= 1.0


@pytest.mark.parametrize("d", [1 - 8.888e-6, 0.999995, 1 - 1e-6])
def test_position_release_whose_speed_underflows_is_a_release(d):
    """D in [0.999991112, 1), f = 0: z = exp(-D tau) sin(omega tau)/omega ends at
    pi/omega; the rebound speed exp(-D pi/omega) underflows to 0. It used to be taken
    for a grazing release (sticking at tau = 0, end = inf)."""
    seq = bounce_sequence(d, 0.0, condition="position")
    with mp.workdps(40):
        omega = mp.sqrt((1 - mp.mpf(d)) * (1 + mp.mpf(d)))
        tau_c = mp.pi / omega
        e = mp.exp(-d * tau_c)
        # the closed form solves z'' + 2 D z' + z = 0, z(0) = 0, z'(0) = 1 (residual at
        # 40 digits relative to the solution's size there)
        z = lambda t: mp.exp(-d * t) * mp.sin(omega * t) / omega  # noqa: E731
        t = tau_c / 3
        residual = mp.diff(z, t, 2) + 2 * d * mp.diff(z, t) + z(t)
        assert abs(residual) < mp.mpf("1e-30") * abs(z(t))
        assert (z(0), mp.diff(z, 0)) == (0, 1)
    assert (seq.n_contacts, seq.sticks, seq.time_to_rest) == (1, False, math.inf)
    assert seq.end[0] == pytest.approx(float(tau_c), rel=1e-12)
    assert seq.end[0] == contact_time(d, 0.0, condition="position")
    assert abs(seq.departure_speed[0] - float(e)) <= 5e-324
    assert float(e) < 2.3e-308


def _energy(seq, d, fr, velocity, deflection):
    return 0.5 * velocity**2 + deflection * (0.5 * deflection - 2 * d * fr)


EXTREME = np.logspace(-12, 12, 7)


def _attempt(d, fr, condition):
    """``(sequence, None)``, or ``(None, message)`` for a ``ValueError``."""
    try:
        return bounce_sequence(d, fr, condition=condition, max_contacts=6), None
    except ValueError as exc:
        return None, str(exc)


@pytest.mark.parametrize("condition", ["position", "force"])
def test_extreme_sequences_keep_their_invariants_or_are_refused_by_name(condition):
    """D and f over 1e-12 .. 1e12 (and f = 0): each sequence has end > start, no energy
    gain (u <= v under the position condition, the body + element energy under the
    force condition), contact durations equal to contact_time of the arriving state --
    or it is refused with a ValueError naming its inputs."""
    checked = 0
    for d in EXTREME.tolist():
        for fr in [0.0, *EXTREME.tolist()]:
            seq, error = _attempt(d, fr, condition)
            if error is not None:
                assert error.startswith((f"bounce_sequence(D={d!r}, f={fr!r})", "contact "))
                assert "D = " in error or f"D={d!r}" in error
                continue
            checked += 1
            ends = np.isfinite(seq.end)
            assert (seq.end[ends] > seq.start[ends]).all(), (d, fr)
            u = seq.departure_speed[ends]
            if condition == "position":
                assert (u <= seq.arrival_speed[ends]).all(), (d, fr)
                durations = contact_time(d, fr / seq.arrival_speed, condition=condition)
            else:
                before = _energy(seq, d, fr, seq.arrival_velocity, seq.element_deflection)
                after = _energy(seq, d, fr, u, 2 * d * u)
                assert (after <= before[ends] * (1 + 1e-15) + 1e-300).all(), (d, fr)
                fresh = seq.element_deflection == 0
                durations = np.where(
                    fresh,
                    contact_time(d, fr / seq.arrival_speed, condition=condition),
                    seq.end - seq.start,
                )
            assert seq.end[0] - seq.start[0] == contact_time(d, fr, condition=condition)
            np.testing.assert_allclose(seq.end - seq.start, durations, rtol=1e-6)
    assert checked > 40


@pytest.mark.parametrize("d", [1e12, 1e160, 1e300])
def test_far_overdamped_release_without_force_matches_the_closed_form(d):
    """f = 0, force condition: z = (e^{l1 t} - e^{l2 t})/(l1 - l2), l = -D +- sqrt(D^2 - 1),
    and 2 D z' + z = 0 at t = ln((2 D l2 + 1)/(2 D l1 + 1))/(l1 - l2), at 50 digits with
    l1 = -1/mu, 2 D l1 + 1 = -1/mu^2 (mu = D + sqrt(D^2 - 1)) written without cancellation.
    The departure speed was NaN for D = 1e160 (the closed forms overflow; the limits of
    contact_time now decide it, as for restitution)."""
    seq = bounce_sequence(d, 0.0, condition="force")
    with mp.workdps(50):
        damping = mp.mpf(d)
        mu = damping + mp.sqrt(damping**2 - 1)
        l1, l2 = -1 / mu, -mu
        tau_c = mp.log((2 * damping * l2 + 1) / (-1 / mu**2)) / (l1 - l2)
        e = -(l1 * mp.exp(l1 * tau_c) - l2 * mp.exp(l2 * tau_c)) / (l1 - l2)
    assert (seq.n_contacts, seq.sticks) == (1, False)
    assert seq.end[0] == pytest.approx(float(tau_c), rel=1e-12)
    assert seq.departure_speed[0] == pytest.approx(float(e), rel=1e-9, abs=1e-323)
    assert seq.end[0] == contact_time(d, 0.0, condition="force")
    assert seq.departure_speed[0] == restitution(d, 0.0, condition="force")
