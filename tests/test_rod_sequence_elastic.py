"""Tests of the contact-spring step model of the rod impact sequence,
:mod:`impactsym.rod.sequence_elastic` (through :func:`impactsym.rod.impact_sequence`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from references.rod_characteristics import SpringGrid
from references.rod_spring_steps import SpringSteps

from impactsym.rod import contact_force, contact_time, displacement, impact_sequence
from impactsym.rod.sequence_elastic import _CONFLUENT, _rates

#: (alpha, f, kappa): soft, critical (exactly, alpha kappa = 4), complex pair, stiff
#: (split per rate), with and without pressing force.
CASES = [
    (1.0, 0.0, 10.0),
    (0.5, 0.0, 8.0),
    (2.0, 0.3, 100.0),
    (0.3, 0.5, 1.0),
    (1.0, 0.5, 20.0),
    (1.0, 0.3, 0.5),
    (0.5, 0.2, 2e3),
]


def merged(contacts, gap):
    """Contact intervals with the flights shorter than ``gap`` closed, and the index of
    the last contact of each merged interval."""
    out, last = [list(contacts[0])], [0]
    for i, (start, end) in enumerate(contacts[1:], start=1):
        if start - out[-1][1] < gap:
            out[-1][1] = end
            last[-1] = i
        else:
            out.append([start, end])
            last.append(i)
    return np.array(out), last


@pytest.mark.parametrize(("alpha", "f", "kappa"), CASES)
def test_first_contact_agrees_with_the_laplace_series(alpha, f, kappa):
    """Until the first separation the sequence is the persistent-contact solution of
    :mod:`impactsym.rod.elastic` (inverted Laplace delay series, pole data in mpmath):
    an independent derivation."""
    seq = impact_sequence(alpha, f, kappa=kappa, t_max=20.0)
    end = seq.contacts[0][1]
    assert end == pytest.approx(contact_time(alpha, f, kappa=kappa, condition="force"), abs=1e-12)
    t = np.linspace(0.0, min(end, 20.0), 23)[1:-1]
    assert np.abs(seq.contact_force(t) - contact_force(t, alpha, f, kappa=kappa)).max() < 1e-11
    assert np.abs(seq.displacement(t) - displacement(t, alpha, f, kappa=kappa)).max() < 1e-11


@pytest.mark.parametrize(
    ("alpha", "f", "kappa", "t_max", "steps"),
    [(*case, 20.0, 4000) for case in CASES[:-1]] + [(*CASES[-1], 10.0, 20000)],
)
def test_sequence_agrees_with_a_grid_solver_of_the_characteristics(alpha, f, kappa, t_max, steps):
    """Every contact interval and separation speed against the spring-contact grid
    solver (first order at the events; the stiff contact, whose tensile fronts open
    flights of length ~1/kappa, on a finer grid)."""
    seq = impact_sequence(alpha, f, kappa=kappa, t_max=t_max)
    ref = SpringGrid(alpha, f, kappa, t_max, steps_per_transit=steps)
    assert len(seq.contacts) == len(ref.contacts)
    assert np.abs(np.array(seq.contacts) - np.array(ref.contacts)).max() < 2e-3
    assert len(seq.separation_velocities) == len(ref.separation_speeds)
    if seq.separation_velocities:
        got, want = np.array(seq.separation_velocities), np.array(ref.separation_speeds)
        assert np.abs(got - want).max() < 2e-3
    t = np.linspace(0.0, t_max, 4001)
    stress = np.abs(seq.fixed_end_stress(t) - ref.fixed_end_stress(t))
    assert np.median(stress) < 1e-4
    assert seq.max_fixed_end_stress >= ref.fixed_end_stress(t).max() - 1e-3


@pytest.mark.parametrize(("alpha", "f", "kappa"), [*CASES, (0.3, 0.3, 1e4), (3.0, 1.0, 0.5)])
def test_energy_balance_holds_to_rounding(alpha, f, kappa):
    """Striker + spring + rod energy = initial kinetic energy + work of f, everywhere
    (event times included), to rounding."""
    seq = impact_sequence(alpha, f, kappa=kappa)
    energy = seq.energy
    t = np.r_[np.linspace(0.0, seq.t_max, 4001)[:-1], np.ravel(seq.contacts)[1:-1]]
    scale = 0.5 * alpha + np.abs(energy.work(t))
    assert np.abs(energy.balance(t) / scale).max() < 1e-11
    assert np.all(energy.spring(t) >= 0.0)
    in_flight = np.array([all(not (a < x < b) for a, b in seq.contacts) for x in t])
    assert np.all(energy.spring(t)[in_flight] < 1e-25)  # zero, or N rounding at an event


@pytest.mark.parametrize(("alpha", "f", "kappa"), CASES)
def test_state_is_continuous_and_consistent(alpha, f, kappa):
    """N = kappa (y - u) in contact, y and y' continuous through every event, and the
    velocity is the derivative of the displacement (central differences)."""
    seq = impact_sequence(alpha, f, kappa=kappa, t_max=20.0)
    t = np.linspace(0.013, 19.9, 1501)
    N = seq.contact_force(t)
    gap = seq.displacement(t) - seq.rod_end_displacement(t)
    contact = N > 0.0
    assert np.abs(N[contact] - kappa * gap[contact]).max() < 1e-9 * max(1.0, kappa)
    assert np.all(gap[~contact] <= 1e-12)
    events = np.array([e for c in seq.contacts for e in c if 0.0 < e < 20.0])
    for e in events:
        before, after = e - 1e-9, e + 1e-9
        assert abs(seq.displacement(before) - seq.displacement(after)) < 1e-8
        assert abs(seq.velocity(before) - seq.velocity(after)) < 1e-6 * max(1.0, kappa / 100)
    dt = 1e-6
    fd = (seq.displacement(t + dt) - seq.displacement(t - dt)) / (2 * dt)
    assert np.median(np.abs(fd - seq.velocity(t))) < 1e-7


@pytest.mark.parametrize(("alpha", "f", "t_max"), [(0.5, 0.0, 40.0), (1.0, 0.5, 12.0)])
def test_rigid_limit_is_reached_at_rate_one_over_kappa(alpha, f, t_max):
    """kappa -> inf: contact intervals, separation speeds and restitution converge to the
    rigid sequence like 1/kappa (kappa x error nearly constant), the largest fixed-end
    stress like log(kappa)/kappa (measured: kappa x error grows by a constant per
    decade; only while the contacts agree, see the test below). Flights of length
    O(1/kappa) (a tensile front that leaves the rigid N > 0 still makes the spring
    chatter) are closed before comparing."""
    rigid = impact_sequence(alpha, f, t_max=t_max)
    scaled = []
    for kappa in (1e2, 1e3, 1e4):
        seq = impact_sequence(alpha, f, kappa=kappa, t_max=t_max)
        contacts, last = merged(seq.contacts, 3.0 / kappa)
        assert contacts.shape == np.array(rigid.contacts).shape
        err_contacts = np.abs(contacts - np.array(rigid.contacts)).max()
        n = len(rigid.separation_velocities)
        speeds = np.array([seq.separation_velocities[i] for i in last[:n]])
        err_speeds = np.abs(speeds - np.array(rigid.separation_velocities)).max()
        err_stress = abs(seq.max_fixed_end_stress - rigid.max_fixed_end_stress)
        scaled.append((kappa * err_contacts, kappa * err_speeds, kappa * err_stress))
        if f == 0.0:
            assert seq.final
            assert abs(seq.restitution - rigid.restitution) < 3.0 / kappa
    scaled = np.array(scaled)
    # 1/kappa: the scaled errors agree within 10 % from kappa = 1e3 on
    assert np.all(np.abs(scaled[2, :2] - scaled[1, :2]) <= 0.1 * scaled[1, :2] + 1e-9)
    assert np.all(scaled[:, :2].max(axis=0) < 10.0)
    # the stress more slowly (kappa x error grows per decade): it falls by at least 2.5
    # per decade, by 5 from kappa = 1e3 on, and is below 150 / kappa at kappa = 1e4
    assert np.all(scaled[1:, 2] < 4.0 * scaled[:-1, 2])
    assert scaled[2, 2] < 2.0 * scaled[1, 2]
    assert scaled[2, 2] < 150.0


def test_largest_stress_converges_only_while_the_contacts_agree():
    """What docs/physics.md says of the rigid limit of the largest fixed-end stress,
    measured against the rigid sequence (a separate solver): for (0.7, 0.5) to t = 10 (the
    same three contacts) the error falls by more than 5 per decade (log(kappa)/kappa:
    measured 7 to 8); to t = 40 the chattering sequences differ and the error stays of
    order one, growing from kappa = 1e2 to 1e4."""
    alpha, f = 0.7, 0.5
    rigid = impact_sequence(alpha, f, t_max=10.0)
    errors = []
    for kappa in (1e3, 1e4):
        seq = impact_sequence(alpha, f, kappa=kappa, t_max=10.0)
        assert len(seq.contacts) == len(rigid.contacts)
        errors.append(abs(seq.max_fixed_end_stress - rigid.max_fixed_end_stress))
    assert errors[1] < errors[0] / 5.0
    assert 1e4 * errors[1] < 70.0
    rigid = impact_sequence(alpha, f, t_max=40.0)
    far = []
    for kappa in (1e2, 1e4):
        seq = impact_sequence(alpha, f, kappa=kappa, t_max=40.0)
        assert len(seq.contacts) != len(rigid.contacts)
        far.append(abs(seq.max_fixed_end_stress - rigid.max_fixed_end_stress))
    assert 0.3 < far[0] < far[1]


def test_rigid_limit_light_striker_restitution():
    """The light-striker closed form 2 exp(-1 - e/2), e = exp(-2/alpha) (rigid, f = 0)
    is approached with error O(1/kappa)."""
    alpha = 0.5
    e = math.exp(-2.0 / alpha)
    want = 2.0 * math.exp(-1.0 - e / 2.0)
    errors = [abs(impact_sequence(alpha, 0.0, kappa=k).restitution - want) for k in (1e3, 1e4)]
    assert errors[1] < errors[0] / 8.0
    assert errors[1] < 3.0 / 1e4


def test_exactly_critical_damping_is_exact_and_continuous():
    """alpha kappa = 4 exactly (a double rate) against the grid, and nearby values of
    kappa (a complex pair below, two real rates above) converge to it linearly."""
    alpha, f = 0.5, 0.3
    crit = impact_sequence(alpha, f, kappa=8.0, t_max=20.0)
    ref = SpringGrid(alpha, f, 8.0, 20.0, steps_per_transit=4000)
    assert len(crit.contacts) == len(ref.contacts)
    assert np.abs(np.array(crit.contacts) - np.array(ref.contacts)).max() < 3e-3
    for eps in (1e-4, 1e-8, 1e-12):
        for kappa in (8.0 * (1 - eps), 8.0 * (1 + eps)):
            near = impact_sequence(alpha, f, kappa=kappa, t_max=20.0)
            assert len(near.contacts) == len(crit.contacts)
            diff = np.abs(np.array(near.contacts) - np.array(crit.contacts)).max()
            assert diff < 100 * eps + 1e-12
            assert abs(near.max_fixed_end_stress - crit.max_fixed_end_stress) < 100 * eps + 1e-12


def test_confluent_and_split_representations_agree_at_the_switch():
    """On either side of the switch between the confluent series and the per-rate split
    (d = theta^2 sigma^2) the two representations give the same sequence."""
    alpha, f = 1.0, 0.3
    # d / sigma^2 = 1 - 4 / (alpha kappa) = theta^2
    kappa = 4.0 / (alpha * (1.0 - _CONFLUENT**2))
    below, above = kappa * (1 - 1e-9), kappa * (1 + 1e-9)
    assert _rates(alpha, below)[1] is not None  # confluent
    assert _rates(alpha, above)[1] is None  # split
    one = impact_sequence(alpha, f, kappa=below, t_max=20.0)
    two = impact_sequence(alpha, f, kappa=above, t_max=20.0)
    assert len(one.contacts) == len(two.contacts)
    assert np.abs(np.array(one.contacts) - np.array(two.contacts)).max() < 1e-8
    t = np.linspace(0.0, 20.0, 501)
    assert np.abs(one.contact_force(t) - two.contact_force(t)).max() < 1e-7


@pytest.mark.parametrize(
    ("alpha", "f", "kappa"),
    [
        (0.4508, 1.975, 10.0),  # once refused at t = 34 (confluent terms of size 1e8)
        (0.4339, 1.577, 100.0),  # once refused (stiff: per-rate parts doubling per passage)
        (0.7512, 0.7455, 100.0),  # 43 contacts, once off by 1.7e-10
    ],
)
def test_long_sequences_agree_with_the_taylor_steps(alpha, f, kappa):
    """To t = 40 every contact interval, separation velocity and the fixed-end stress
    agree with the 30-digit Taylor method of steps of the delay ODE
    (``references/rod_spring_steps.py``, its own energy balance ~1e-19), and the
    library's energy balance holds to rounding."""
    ref = SpringSteps(alpha, f, kappa, 40.0)
    assert abs(ref.balance) < 1e-18
    seq = impact_sequence(alpha, f, kappa=kappa, t_max=40.0)
    want = np.array([[float(a), float(b)] for a, b in ref.contacts])
    assert np.array(seq.contacts).shape == want.shape
    assert np.abs(np.array(seq.contacts) - want).max() < 1e-11
    speeds = np.array([float(v) for v in ref.separation_velocities])
    assert np.abs(np.array(seq.separation_velocities) - speeds).max() < 1e-11
    t = np.linspace(1.0, 40.0, 157)[1:-1] + 1e-3  # off the piece boundaries
    stress = np.array([ref.stress(x) for x in t])
    assert np.abs(seq.fixed_end_stress(t) - stress).max() < 1e-10
    grid = np.linspace(0.0, 40.0, 2001)[:-1]
    assert np.abs(seq.energy.balance(grid)).max() < 1e-12 * (0.5 * alpha + 40.0 * f)


def test_float64_limit_is_a_clear_refusal():
    """A light, strongly pressed striker on a very stiff spring: the per-rate parts of the
    split cancel, the confluent form would need ~1e5 pieces, and the split goes on until
    float64 no longer vouches for it: refused with alpha, f, kappa and the time named,
    never a silent result; below that time it runs."""
    with pytest.raises(
        ValueError, match=r"alpha=0\.1, f=1\.0, kappa=10000\.0.*confluent.*lower t_max below 34"
    ):
        impact_sequence(0.1, 1.0, kappa=1e4, t_max=40.0)
    assert impact_sequence(0.1, 1.0, kappa=1e4, t_max=30.0).t_max == 30.0


@pytest.mark.parametrize(("alpha", "f", "kappa"), [(1.0, 0.5, 20.0), (0.3, 0.3, 100.0)])
def test_max_fixed_end_stress_is_the_maximum(alpha, f, kappa):
    """The branch-and-bound maximum is at least every sampled value and is met by a
    dense sampling around the sampled peak."""
    seq = impact_sequence(alpha, f, kappa=kappa)
    t = np.linspace(0.0, seq.t_max, 40001)
    stress = seq.fixed_end_stress(t)
    i = int(np.argmax(stress))
    fine = np.linspace(t[max(i - 1, 0)], t[min(i + 1, t.size - 1)], 200001)
    sampled = max(stress.max(), seq.fixed_end_stress(fine).max())
    assert -1e-12 < seq.max_fixed_end_stress - sampled < 1e-9  # B&B stops within 1e-13
