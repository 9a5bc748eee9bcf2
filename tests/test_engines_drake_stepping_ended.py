"""``stepping.ended_at``: a run to the state the caller expects to end the contact, which
must give ``contact_ends``' numbers bit for bit wherever it says the contact ends there
and leaves, and never say so where the full contact does otherwise (ends elsewhere,
coasts and sticks, turns back, settles). Checked against ``contact_ends`` itself, the
step loop with the end test at every update, on random contacts of 2-70 steps that
leave, coast out (no gravity, a rebound at ``-1/d``) or stick (soft, heavily damped,
under gravity), at their own end states and at states around them; and a run whose
update is one ulp off, or whose end test misses the impulse floor, is caught.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.drake import step_buffers, stepping
from impactsym.engines.drake.stepping import ContactEnds, contact_ends, end_steps, ended_at


def _contacts(n, g, h, seed):
    """Random contacts of 0.1 kg at 1 m/s, 2-70 steps (a third soft and heavily damped:
    under gravity many stick), random phases, and end states to ask about: the full
    contact's own where it ends, and states up to 3 off it (or about its length)."""
    rng = np.random.default_rng(seed)
    steps = np.exp(rng.uniform(np.log(2.0), np.log(70.0), n))
    m, v = 0.1, 1.0
    k = m * (np.pi / (steps * h)) ** 2
    d = rng.uniform(0.0, 3.0, n) ** 2
    soft = rng.random(n) < 0.3
    k[soft] /= rng.uniform(1.0, 50.0, soft.sum())
    d[soft] *= rng.uniform(5.0, 200.0, soft.sum())
    phase = rng.random(n)
    full = contact_ends(k, d, m, g, v, h, phase)
    own = end_steps(full.contact_time, full.sticks, h, phase)
    ask = np.where(own >= 0, own, np.rint(steps)).astype(np.int64)
    off = rng.random(n) < 0.3
    ask = np.maximum(ask + off * rng.integers(-3, 4, n), 0)
    return (k, d, m, g, v, h, phase), ask, full, own


def _disagreements(ends, status, full, own, ask):
    """What ``ended_at`` gets wrong against the full contact: status 1 where it does not
    end at ``ask`` unstuck, a field not bit for bit the full contact's there, status -1
    where it ends at ``ask`` (stuck or not), status 0 where it does not end there, and
    status below 1 where it ends there outside the overlap, unstuck (a count each)."""
    there = own == ask
    one = status == 1
    wrong = {
        "status 1 elsewhere": np.count_nonzero(one & ~(there & ~full.sticks)),
        "status -1 there": np.count_nonzero((status == -1) & there),
        "status 0 elsewhere": np.count_nonzero((status == 0) & ~there & ~full.sticks),
        "left, not 1": np.count_nonzero(there & ~full.sticks & (full.end_penetration < 0) & ~one),
    }
    for name in ContactEnds._fields:
        a, b = getattr(ends, name)[one], getattr(full, name)[one]
        wrong[name] = np.count_nonzero(a.view(np.uint8) != b.view(np.uint8))
    return wrong


@pytest.mark.parametrize(("g", "h"), [(0.0, 1e-3), (9.81, 1e-3), (30.0, 1e-3), (0.0, 1e-4),
                                      (9.81, 1e-4), (30.0, 1e-4)])  # fmt: skip
def test_where_it_says_the_contact_ends_there_it_is_contact_ends_bit_for_bit(g, h):
    args, ask, full, own = _contacts(4000, g, h, seed=int(g) + int(1e4 * h))
    ends, status = ended_at(*args, ask)
    assert not any(_disagreements(ends, status, full, own, ask).values())
    # every kind is met: ends there and leaves, ends elsewhere or sticks, and without
    # gravity coasts out of the overlap (with it: sticks, some after turning back)
    assert np.count_nonzero(status == 1) > 1000
    assert np.count_nonzero((status == -1) & (own != ask)) > 100
    if g == 0.0:
        assert np.count_nonzero(status == 0) > 100
        assert not full.sticks.any()
    else:
        assert np.count_nonzero(full.sticks) > 300


def test_broadcasts_and_reads_state_zero():
    """Rows of contacts against columns of phases and states; state 0 (a contact that
    ends at its first detecting state, here by asking there) is run as any other."""
    k, d, m, g, v, h = np.array([[3e3], [5e3]]), 2.0, 0.1, 9.81, 1.0, 1e-3
    p, s = np.array([0.1, 0.5, 0.9]), np.array([0, 1, 30])
    ends, status = ended_at(k, d, m, g, v, h, p, s)
    full = contact_ends(k, d, m, g, v, h, p)
    assert status.shape == (6,)
    flat = ContactEnds(*(a.ravel() for a in full))
    own = end_steps(flat.contact_time, flat.sticks, h, np.tile(p, 2))
    assert not any(_disagreements(ends, status, flat, own, np.tile(s, 2)).values())


def test_an_update_one_ulp_off_is_caught(monkeypatch):
    args, ask, full, own = _contacts(1500, 9.81, 1e-3, seed=3)
    update = stepping._update

    def off(*a, **options):
        ustar, new = update(*a, **options)
        return ustar, np.nextafter(new, np.inf, out=new)

    monkeypatch.setattr(stepping, "_update", off)
    ends, status = ended_at(*args, ask)
    wrong = _disagreements(ends, status, full, own, ask)
    assert wrong["restitution"] > 100
    assert wrong["max_penetration"] > 100


def test_a_run_whose_end_test_misses_the_impulse_floor_is_caught(monkeypatch):
    """Without gravity a contact whose impulse vanishes inside the overlap (its rebound at
    ``-1/d``) ends there and coasts out: a run that only saw the overlap would have it
    end later, where it leaves."""
    args, ask, full, own = _contacts(4000, 0.0, 1e-3, seed=4)
    constants = stepping.update_constants

    def no_floor(*a):
        consts, scaled = constants(*a)
        return (*consts[:8], np.full_like(consts[8], -np.inf), *consts[9:]), scaled

    monkeypatch.setattr(stepping, "update_constants", no_floor)
    ends, status = ended_at(*args, ask)
    assert _disagreements(ends, status, full, own, ask)["status 1 elsewhere"] > 100
    monkeypatch.undo()
    ends, status = ended_at(*args, ask)
    assert not any(_disagreements(ends, status, full, own, ask).values())


def test_the_impulse_floor_as_a_bound_or_scaled_gives_the_same_verdicts(monkeypatch):
    """``u* - u' <= T`` (``step_buffers.impulse_bound``) or the impulse against the floor
    itself: the same statuses and numbers."""
    args, ask, _, _ = _contacts(2000, 9.81, 1e-3, seed=5)
    ends, status = ended_at(*args, ask)
    floor = stepping.IMPULSE_FLOOR
    monkeypatch.setattr(step_buffers, "impulse_bound", lambda m, v: (floor * m * v, True))
    ends_scaled, status_scaled = ended_at(*args, ask)
    np.testing.assert_array_equal(status, status_scaled)
    for a, b in zip(ends, ends_scaled, strict=True):
        np.testing.assert_array_equal(a.view(np.uint8), b.view(np.uint8))


@pytest.mark.parametrize("g", [0.0, 9.81, 30.0])
def test_end_state_s_end_test_is_margin_at_s_and_unchecked_its_states_are_the_same(g):
    """``end_state(..., ends=True)``: the same states, ``valid`` only where the state also
    ends by ``margin_at``'s test (``hunt_crossley_velocity``'s impulse against the floor,
    or out of the overlap), at states before, at and after the contacts' own end states
    (past the end: free updates, the impulse's floor and the overlap both decide)."""
    args, ask, _, _ = _contacts(4000, g, 1e-3, seed=6 + int(g))
    ask = ask + np.random.default_rng(7).integers(-2, 3, ask.size)
    ask = np.maximum(ask, 0)
    x, u, valid, flat = stepping.end_state(*args, ask)
    x_e, u_e, valid_e, _ = stepping.end_state(*args, ask, ends=True)
    np.testing.assert_array_equal(x_e.view(np.uint64), x.view(np.uint64))
    np.testing.assert_array_equal(u_e.view(np.uint64), u.view(np.uint64))
    _, ends = stepping.margin_at(x, u, *flat)
    np.testing.assert_array_equal(valid_e, valid & ends)
    # unchecked (jump_means reads no validity): the same states, nothing tracked
    x_u, u_u, valid_u, _ = stepping.end_state(*args, ask, checked=False)
    np.testing.assert_array_equal(x_u.view(np.uint64), x.view(np.uint64))
    np.testing.assert_array_equal(u_u.view(np.uint64), u.view(np.uint64))
    assert valid_u.all()
    assert np.count_nonzero(valid & ends) > 200
    assert np.count_nonzero(valid & ~ends) > 200
