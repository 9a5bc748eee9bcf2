"""Drake's discrete step loop, gathering the live elements only when half have finished,
against the loop that gathers them at every step (tests/references/drake_steps.py): the
same numbers, bit for bit (except the update count of a sticking contact, which the
settled-contact rule decides early: the reference steps it until it turns back or to
``MAX_STEPS``). The lean loop of the phase means (``contact_ends``) against
``step_contact``, and the lean ``end_margin`` against its masked loop: the same numbers,
bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from references.drake_steps import end_margin as margin_reference
from references.drake_steps import step_contact as reference

from impactsym.engines.drake import settling, stepping
from impactsym.engines.drake.stepping import (
    contact_ends,
    end_margin,
    end_state,
    end_steps,
    states_through,
    step_contact,
)

RNG = np.random.default_rng(1000)


def _contacts(n, tau_max):
    k, d = 10 ** RNG.uniform(3, 5, n), RNG.uniform(0.0, 3.0, n)
    m, v = RNG.uniform(0.05, 2.0, n), RNG.uniform(0.2, 3.0, n)
    g = np.where(RNG.uniform(size=n) < 0.5, 0.0, 9.81)
    p, tau = RNG.uniform(0.0, 1.0, n), RNG.uniform(0.0, tau_max, n)
    return k, d, tau, m, g, v, p


def _same(new, old, rest=None):
    """Bit for bit, but the update count of sticking contacts and the largest overlap of
    those creeping up to rest from below (``rest``: there ``m g / k``, the limit, which
    the reference, stalled by rounding or stopped at its limit, approaches from below)."""
    for name in new.__dataclass_fields__:
        a, b = getattr(new, name), getattr(old, name)
        if name == "steps":  # of a sticking contact: the updates until the verdict
            a, b = a[~old.sticks], b[~old.sticks]
        if name == "max_penetration" and rest is not None:
            creep = a == rest
            assert np.all(b[creep] <= a[creep] * (1 + 1e-15)), name  # an ulp or two above
            np.testing.assert_allclose(b[creep], a[creep], rtol=1e-11, err_msg=name)
            a, b = a[~creep], b[~creep]
        np.testing.assert_array_equal(a, b, err_msg=name)


@pytest.mark.parametrize("h", [1e-3, 1e-2])
def test_lazy_gathering_is_the_per_step_gathering(h):
    # sticking, short and long contacts mixed, with and without gravity
    k, d, tau, m, g, v, p = _contacts(1500, 0.0)
    new = step_contact(k, d, tau, m, g, v, h, p, approximation="lagged")
    old = reference(k, d, tau, m, g, v, h, p, approximation="lagged")
    assert old.sticks.any()
    assert not old.sticks.all()
    _same(new, old)


def test_lazy_gathering_under_sap():
    k, d, tau, m, g, v, p = _contacts(400, 2e-3)  # short relaxation times: quick contacts
    _same(step_contact(k, d, tau, m, g, v, 1e-3, p, approximation="sap"),
          reference(k, d, tau, m, g, v, 1e-3, p, approximation="sap"))  # fmt: skip
    one = step_contact(1e4, 0.5, 0.2, 1.0, 0.0, 1.0, 1e-3, [[0.0, 0.5]], approximation="lagged")
    assert one.restitution.shape == (1, 2)


def test_a_settled_contact_sticks_without_stepping_to_the_limit(monkeypatch):
    # heavily damped soft contacts under gravity creep to rest without turning back: the
    # reference steps them to MAX_STEPS (2e6 updates, a minute); stepped here to 3e4
    # updates, it has not released them; the verdicts agree
    import references.drake_steps as ref

    monkeypatch.setattr(ref, "MAX_STEPS", 30_000)
    monkeypatch.setattr(stepping, "MAX_STEPS", 30_000)  # the creeping ones, both alike
    h, m = 1e-3, 0.1
    s, w = np.meshgrid([2.0, 4.0, 6.0, 9.0], [0.01, 0.02, 0.04])
    k, d = m * (w.ravel() / h) ** 2, s.ravel()
    p = np.linspace(0.0, 1.0, k.size, endpoint=False)
    new = step_contact(k, d, 0.0, m, 9.81, 1.0, h, p, approximation="lagged")
    old = ref.step_contact(k, d, 0.0, m, 9.81, 1.0, h, p, approximation="lagged")
    assert old.sticks.all()
    assert np.count_nonzero(old.steps == 30_000) >= 6  # crept to the reference's limit
    rest = m * 9.81 / k
    _same(new, old, rest)  # peak_accel exact: decided once it peaked
    assert np.count_nonzero(new.max_penetration == rest) >= 3  # those creeping up to rest
    assert np.count_nonzero(new.steps <= 1024) >= 6  # those decided after a few checks
    # without the peaks (designs by contact time) every one is decided after a few checks
    quick = step_contact(k, d, 0.0, m, 9.81, 1.0, h, p, approximation="lagged",
                         stuck_peaks=False)  # fmt: skip
    assert np.all(quick.steps <= 1024)
    for name in ("restitution", "contact_time", "sticks", "released_by_position",
                 "departure_speed"):  # fmt: skip
        np.testing.assert_array_equal(getattr(quick, name), getattr(old, name), err_msg=name)


def test_a_contact_at_rest_sticks_with_the_peaks_of_the_full_loop(monkeypatch):
    # under "sap" overdamped loaded contacts creep up to rest from below; once an update
    # gives back the state bit for bit the verdict and peaks are final
    import references.drake_steps as ref

    monkeypatch.setattr(ref, "MAX_STEPS", 20_000)
    h, m = 1e-3, 1.0
    k, tau = np.array([1e4, 1e4, 3e4, 1e4]), np.array([0.2, 0.1, 0.3, 0.2])
    p = np.array([0.0, 0.3, 0.6, 0.9])
    new = step_contact(k, 0.0, tau, m, 9.81, 0.1, h, p, approximation="sap")
    old = ref.step_contact(k, 0.0, tau, m, 9.81, 0.1, h, p, approximation="sap")
    assert old.sticks.all()
    assert np.all(old.steps == 20_000)  # crept to the reference's limit
    _same(new, old)  # the peaks bit for bit
    assert np.all(new.steps < 10_000)  # decided at rest, well before the limit


def test_a_creeping_contact_sticks_at_its_rest(monkeypatch):
    # overdamped loaded "lagged" contacts creep up to rest from below: the energy rule
    # cannot decide them with their peaks; the creep rule reports the rest m g / k
    import references.drake_steps as ref

    monkeypatch.setattr(ref, "MAX_STEPS", 20_000)
    h, m = 1e-3, 1.0
    k, d = np.array([1e4, 1e4, 3e4, 1e4]), np.array([50.0, 40.0, 50.0, 80.0])
    p = np.array([0.0, 0.3, 0.6, 0.9])
    new = step_contact(k, d, 0.0, m, 9.81, 0.1, h, p, approximation="lagged")
    old = ref.step_contact(k, d, 0.0, m, 9.81, 0.1, h, p, approximation="lagged")
    assert old.sticks.all()
    assert np.all(old.steps == 20_000)  # crept to the reference's limit
    rest = m * 9.81 / k
    _same(new, old, rest)
    assert np.count_nonzero(new.max_penetration == rest) >= 2
    assert np.all(new.steps < 1_000)


def _exact_lagged(x, u, k, d, m, g, h, n):
    """``n`` updates of the lagged map in 40-digit arithmetic: positions and forces."""
    import mpmath

    with mpmath.workdps(40):
        x, u, k, d, m, g, h = (mpmath.mpf(float(q)) for q in (x, u, k, d, m, g, h))
        xs, fs = [], []
        for _ in range(n):
            # m (u' - u - h g) + h k (x + h u')(1 + d u') = 0, the larger root
            qa, qb, qc = (
                h * h * k * d,
                m + h * h * k + h * k * d * x,
                -(m * (u + h * g) - h * k * x),
            )
            new = (-qb + mpmath.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
            fs.append(m * (u + h * g - new) / h)
            x, u = x + h * new, new
            xs.append(x)
        return np.array(xs, float), np.array(fs, float)


def test_the_creep_rule_against_the_exact_map():
    # random states below rest, moving in or out, some barely in contact, some fast
    # (the impulse floor 1e-12 m v): where the rule holds (force bound waived), the
    # 40-digit map rises monotonically below m g / k with impulses above the floor; with
    # the peak set just below the largest later force the rule must not hold
    rng = np.random.default_rng(7)
    held = 0
    for _ in range(300):
        k, m, h = 10 ** rng.uniform(2, 5), rng.uniform(0.05, 2.0), 10 ** rng.uniform(-4, -2)
        g, v = 9.81, 10 ** rng.uniform(0, 13)
        x_e = m * g / k
        d = 10 ** rng.uniform(0, 3) * np.sqrt(k / m) / g  # from under- to far over-damped
        x = x_e * (rng.uniform(0.0, 1.0) if rng.uniform() < 0.8 else 10 ** rng.uniform(-16, -8))
        u = rng.uniform(-0.2, 1.0) * (x_e - x) / h * rng.uniform(0.0, 1.0) ** 4
        args = (x, u, k, d, m, g, h, v)
        if not settling._creeping(*args, np.inf):
            continue
        held += 1
        xs, fs = _exact_lagged(x, u, k, d, m, g, h, 400)
        assert np.all(np.diff(np.concatenate([[x], xs])) >= 0.0)
        assert np.all(xs < x_e * (1 + 1e-15))
        assert np.all(fs * h > 1e-12 * m * v)
        assert not settling._creeping(*args, fs.max() * (1 - 1e-7))
    assert held >= 50


@pytest.mark.parametrize("h", [1e-3, 1e-2])
@pytest.mark.parametrize("stuck_peaks", [True, False])
def test_the_lean_loop_is_step_contact_bit_for_bit(h, stuck_peaks, monkeypatch):
    monkeypatch.setattr(stepping, "_BLOCK", 700)  # several blocks
    monkeypatch.setattr(stepping, "MAX_STEPS", 20_000)  # (creeping contacts: both alike)
    k, d, _, m, g, v, p = _contacts(3000, 0.0)
    d[:300], p[300:450] = 0.0, 0.0  # undamped; touching exactly at a state
    d[450:600] *= 20.0  # beyond the rebound bound: contacts that end without leaving
    old = step_contact(k, d, 0.0, m, g, v, h, p, approximation="lagged", stuck_peaks=stuck_peaks)
    new = contact_ends(k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)
    coasted = ~old.sticks & ~old.released_by_position
    assert coasted.any()  # ended by the impulse inside the overlap, then left
    assert old.sticks.any()
    assert not old.sticks.all()
    for name in set(new._fields) - {"end_penetration"}:
        np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)
    # the end state's penetration: end_state's loop stepped to step_contact's end state
    ended = ~old.sticks
    last = end_steps(old.contact_time, old.sticks, h, p).astype(np.int64)
    x_end = end_state(k, d, m, g, v, h, p, np.maximum(last, 0))[0]
    np.testing.assert_array_equal(new.end_penetration[ended], x_end[ended])
    assert np.all(np.isnan(new.end_penetration[old.sticks]))
    one = contact_ends(1e4, 0.5, 1.0, 0.0, 1.0, 1e-3, [[0.0, 0.5]])
    assert one.restitution.shape == (1, 2)


def test_the_lean_margin_loop_is_the_masked_one_bit_for_bit(monkeypatch):
    monkeypatch.setattr(stepping, "_BLOCK", 700)  # several blocks
    k, d, _, m, g, v, p = _contacts(3000, 0.0)
    d[:300] = 0.0
    h = np.where(RNG.uniform(size=k.size) < 0.5, 1e-3, 1e-2)
    step = RNG.integers(0, 60, k.size)
    new = end_margin(k, d, m, g, v, h, p, step)
    old = margin_reference(k, d, m, g, v, h, p, step)
    assert 0.2 < np.mean(new[2]) < 0.95  # valid and not (ended or turned before the step)
    for a, b, name in zip(new, old, ("margin", "ends", "valid"), strict=True):
        np.testing.assert_array_equal(a, b, err_msg=name)


def test_states_through_are_the_end_states_at_every_step_bit_for_bit():
    # end_state steps on whatever the states before (no end test): contacts that end,
    # leave, turn back or stick well before the last step, with and without gravity
    k, d, _, m, g, v, p = _contacts(300, 0.0)
    d[:30], p[30:60] = 0.0, 0.0  # undamped; touching exactly at a state
    d[60:90] *= 20.0  # beyond the rebound bound: the impulse ends inside the overlap
    h = np.where(RNG.uniform(size=k.size) < 0.5, 1e-3, 1e-2)
    steps = 90
    x = states_through(k, d, m, g, v, h, p, steps)
    assert x.shape == (k.size, steps)
    rows = (np.repeat(a, steps) for a in (k, d, m, g, v, h, p))
    x_end, _, valid, _ = end_state(*rows, np.tile(np.arange(steps), k.size))
    x_end, valid = x_end.reshape(x.shape), valid.reshape(x.shape)
    np.testing.assert_array_equal(x.view(np.uint64), x_end.view(np.uint64))
    early = ~valid[:, steps // 3]  # ended or turned back within the first third
    assert 0.2 < np.mean(early) < 0.9
    assert np.any(early & (g > 0))
    assert np.any(early & (g == 0))
    assert np.any(x < 0.0)  # some left
    assert np.any(x[:, -1] > 0.0)  # some still inside
    # scalars broadcast
    one = states_through(1e4, [0.5, 0.0], 1.0, 9.81, 1.0, 1e-3, 0.25, 3)
    two = end_state(1e4, [0.5, 0.0], 1.0, 9.81, 1.0, 1e-3, 0.25, 2)[0]
    assert one.shape == (2, 3)
    np.testing.assert_array_equal(one[:, 2], two)


@pytest.mark.parametrize("stuck_peaks", [True, False])
def test_the_lean_loop_decides_creeping_contacts_as_step_contact(stuck_peaks, monkeypatch):
    # overdamped loaded contacts creeping up to rest, and some at rest to the last bit
    monkeypatch.setattr(stepping, "MAX_STEPS", 20_000)
    h, m = 1e-3, 1.0
    k = np.repeat([1e4, 1e4, 3e4, 1e4, 1e3], 8)
    d = np.repeat([50.0, 40.0, 50.0, 80.0, 500.0], 8)
    p = np.tile(np.linspace(0.0, 1.0, 8, endpoint=False), 5)
    old = step_contact(k, d, 0.0, m, 9.81, 0.1, h, p, approximation="lagged",
                       stuck_peaks=stuck_peaks)  # fmt: skip
    updates, lean_update = [], stepping._update

    def counted(*args, **options):
        updates.append(1)
        return lean_update(*args, **options)

    monkeypatch.setattr(stepping, "_update", counted)
    new = contact_ends(k, d, m, 9.81, 0.1, h, p, stuck_peaks=stuck_peaks)
    monkeypatch.setattr(stepping, "_update", lean_update)
    assert len(updates) < 2_000  # decided by the rules, not stepped to MAX_STEPS
    assert old.sticks.all()
    assert np.count_nonzero(old.max_penetration == m * 9.81 / k) >= 8  # the creep rule
    for name in set(new._fields) - {"end_penetration"}:
        np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)
    assert np.all(np.isnan(new.end_penetration))
    # settling to rest to the last bit, its peaks wanted (found in a random search)
    k, d = (
        np.array([2334.6713204733805, 2269.1204974017573]),
        np.array([11.95354944396061, 18.04068001524455]),
    )
    m, v = (
        np.array([1.0088777106807114, 1.2895273632951088]),
        np.array([0.0430962879979416, 0.4326955656871267]),
    )
    p = np.array([0.1972316200004598, 0.9109266011601548])
    old = step_contact(k, d, 0.0, m, 9.81, v, h, p, approximation="lagged",
                       stuck_peaks=stuck_peaks)  # fmt: skip
    updates.clear()
    monkeypatch.setattr(stepping, "_update", counted)
    new = contact_ends(k, d, m, 9.81, v, h, p, stuck_peaks=stuck_peaks)
    monkeypatch.setattr(stepping, "_update", lean_update)
    assert len(updates) < 5_000  # decided at rest, not stepped to MAX_STEPS
    assert old.sticks.all()
    for name in set(new._fields) - {"end_penetration"}:
        np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)
    assert np.all(np.isnan(new.end_penetration))
