"""The lean step loops of :mod:`impactsym.engines.drake.stepping` (``contact_ends``,
``end_state``, ``end_margin``) against a frozen copy of them as they were before
(fewer array operations per update), below: the same numbers, bit for bit (float
fields compared as their 64-bit patterns, so signs of zero and NaNs too), on random
contacts of 2-100 steps at ``h = 1e-3`` and ``1e-4`` under ``g = 0, 9.81, 50``, with
``d v`` from 0 to 10 (a tenth undamped), sticking ones, ones leaving the overlap and ones
whose impulse ends inside it (then coasting), ``d v > 5.5`` among them, at touch phases
in ``[0, 1)`` including 0 and ``1 - 1e-15``, with ``stuck_peaks`` True and False; one
member (``m``, ``g``, ``v``, ``h``) per call too. ``states_through`` and the overlap tables
of ``change_table`` built from it against the frozen ``end_state`` at every step."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from impactsym.contact.lawtable import chebyshev_points
from impactsym.engines.drake import change_table, step_buffers, stepping
from impactsym.engines.drake.chebyshev_tables import fit
from impactsym.engines.drake.phases import GRID_PHASES
from impactsym.engines.drake.settling import stuck_early
from impactsym.engines.drake.stepping import (
    ContactEnds,
    _touch,
    contact_ends,
    end_margin,
    end_state,
    margin_at,
    states_through,
)

MAX_STEPS = stepping.MAX_STEPS
_ZERO = 1e-12
_SETTLE_EVERY = 64
_BLOCK = 16_384  # (the old loops in the old blocks)


def _designs(n, seed):
    """Random contacts: ``(k, d, m, g, v, h, phase, steps)`` (``steps`` about the
    contact's length in updates)."""
    rng = np.random.default_rng(seed)
    h = rng.choice([1e-3, 1e-4], n)
    steps = rng.uniform(2.0, 100.0, n)
    m, v = rng.uniform(0.05, 2.0, n), 10 ** rng.uniform(-2.0, 0.5, n)
    k = m * (np.pi / (steps * h)) ** 2
    dv = rng.uniform(0.0, 10.0, n)
    dv[rng.uniform(size=n) < 0.1] = 0.0
    g = rng.choice([0.0, 9.81, 50.0], n)
    p = rng.uniform(0.0, 1.0, n)
    p[: n // 10], p[n // 10 : n // 5] = 0.0, 1.0 - 1e-15
    return k, dv / v, m, g, v, h, p, steps


def _old(run, *args, **options):
    """``run`` (``contact_ends`` or ``end_state``, whose wrappers did not change) with
    the frozen loops below, in the blocks of before."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(stepping, "_block_ends", ref_block_ends)
        patch.setattr(stepping, "_margin_states", ref_margin_states)
        patch.setattr(stepping, "_BLOCK", _BLOCK)
        return run(*args, **options)


def _same(new, old, name):
    """Bit for bit: floats as their 64-bit patterns (signs of zero, NaN), else equal."""
    new, old = np.asarray(new), np.asarray(old)
    assert new.dtype == old.dtype, name
    assert new.shape == old.shape, name
    if new.dtype == float:
        new, old = new.view(np.uint64), old.view(np.uint64)
    assert np.array_equal(new, old), name


@pytest.mark.parametrize(("seed", "limit"), [(1, 20_000), (2, 20_000), (5, 60)])
@pytest.mark.parametrize("stuck_peaks", [True, False])
def test_contact_ends_is_the_frozen_loop_bit_for_bit(seed, limit, stuck_peaks, monkeypatch):
    # limit: MAX_STEPS of both (20000: creeping contacts alike; 60: many stopped there,
    # in the loop to the end state and in the coast after it)
    monkeypatch.setattr(stepping, "_BLOCK", 1500)  # several blocks, and a short last one
    for module in (stepping, sys.modules[__name__]):
        monkeypatch.setattr(module, "MAX_STEPS", limit)
    k, d, m, g, v, h, p, _ = _designs(6000, seed)
    new = contact_ends(k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)
    old = _old(contact_ends, k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)
    for name in ContactEnds._fields:
        _same(getattr(new, name), getattr(old, name), name)
    assert 0.02 < np.mean(old.sticks) < 0.8
    on_floor = old.end_penetration >= 0.0  # the impulse ended inside the overlap
    assert 0.02 < np.mean(on_floor) < 0.9
    assert np.any(on_floor & (g == 0.0))
    assert np.any(on_floor & (g > 0.0))
    assert np.any(on_floor & (d * v > 5.5))


@pytest.mark.parametrize("seed", [6, 7])
def test_contacts_that_coast_many_steps_are_the_frozen_loop_bit_for_bit(seed, monkeypatch):
    """Heavy damping (d v 30-300) ends the impulse deep inside the overlap: the body
    coasts several steps before it leaves (or the impulse comes back), through the
    coast's position update and drops (at d v up to 10 every coast is decided in its
    first step; a flipped sign there passed the test above, found by review)."""
    monkeypatch.setattr(stepping, "_BLOCK", 1500)
    k, d, m, g, v, h, p, _ = _designs(4000, seed)
    d = d * (v * d > 0) + 10 ** np.random.default_rng(seed).uniform(1.5, 2.5, d.size) / v
    new = contact_ends(k, d, m, g, v, h, p)
    old = _old(contact_ends, k, d, m, g, v, h, p)
    for name in ContactEnds._fields:
        _same(getattr(new, name), getattr(old, name), name)
    leaves = ~old.sticks & (old.end_penetration > 0.0)
    coast = old.end_penetration[leaves] / (h[leaves] * old.restitution[leaves] * v[leaves])
    assert np.count_nonzero(coast > 3.0) > 100  # steps of coasting, about


@pytest.mark.parametrize("seed", [3, 4])
def test_end_state_and_margin_are_the_frozen_loop_bit_for_bit(seed, monkeypatch):
    monkeypatch.setattr(stepping, "_BLOCK", 1500)
    k, d, m, g, v, h, p, steps = _designs(6000, seed)
    rng = np.random.default_rng(seed)
    step = rng.integers(0, (1.5 * steps).astype(np.int64) + 3)
    x, u, valid, flat = end_state(k, d, m, g, v, h, p, step)
    x0, u0, valid0, flat0 = _old(end_state, k, d, m, g, v, h, p, step)
    for name, a, b in (("x", x, x0), ("u", u, u0), ("valid", valid, valid0)):
        _same(a, b, name)
    for a, b in zip(flat, flat0, strict=True):
        _same(a, b, "flat")
    assert 0.2 < np.mean(valid0) < 0.9
    margin, ends, valid = end_margin(k, d, m, g, v, h, p, step)
    margin0, ends0 = margin_at(x0, u0, *flat0[:4], flat0[4], flat0[5])
    for name, a, b in (("margin", margin, margin0), ("ends", ends, ends0), ("v", valid, valid0)):
        _same(a, b, name)
    # scalars broadcast, one phase: the same as elementwise
    one = end_state(k[0], d[0], m[0], g[0], v[0], h[0], [0.0, 0.5], [3, 4])
    _same(one[0], _old(end_state, k[0], d[0], m[0], g[0], v[0], h[0], [0.0, 0.5], [3, 4])[0], "x")


@pytest.mark.parametrize("g", [0.0, 9.81])
@pytest.mark.parametrize("scaled", [False, True])
def test_one_member_per_call_is_the_frozen_loop_bit_for_bit(g, scaled, monkeypatch):
    """``m``, ``g``, ``v``, ``h`` the same for every contact (a call's member; then their
    constants are 0-d arrays) and a first block of undamped contacts (its damping terms
    0-d too): the same numbers. ``scaled``: with the impulses' floor where the floor of
    ``u* - u'`` is not exact (``step_buffers.impulse_bound``)."""
    monkeypatch.setattr(stepping, "_BLOCK", 1500)
    if scaled:
        monkeypatch.setattr(step_buffers, "impulse_bound", lambda m, v: (_ZERO * m * v, True))
    k, d, _, _, _, _, p, steps = _designs(6000, 11)
    m, v, h = 0.1, 0.5, 1e-3
    k = m * (np.pi / (steps * h)) ** 2
    d = np.where(np.arange(k.size) < 1500, 0.0, d * v / 0.5)
    for stuck_peaks in (True, False):
        new = contact_ends(k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)
        old = _old(contact_ends, k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)
        for name in ContactEnds._fields:
            _same(getattr(new, name), getattr(old, name), name)
    assert np.any(old.end_penetration >= 0.0)  # some coasted
    step = np.random.default_rng(12).integers(0, (1.5 * steps).astype(np.int64) + 3)
    new, old = end_state(k, d, m, g, v, h, p, step), _old(end_state, k, d, m, g, v, h, p, step)
    for name, a, b in zip(("x", "u", "valid"), new[:3], old[:3], strict=True):
        _same(a, b, name)
    assert 0.2 < np.mean(old[2]) < 0.95


def test_the_floor_of_u_star_less_u_is_that_of_the_impulse():
    """``step_buffers.impulse_bound``: ``u* - u' <= T`` exactly where ``m (u* - u') <= 1e-12 m v``
    (rounded), checked by the products at and around ``T`` (to 3 floats either side),
    at random differences, zeros, infinities and nan; where ``T`` is not exact for
    every contact, the floor itself, to be compared with the products."""
    rng = np.random.default_rng(14)
    m = np.concatenate([rng.uniform(0.05, 2.0, 3000), 10 ** rng.uniform(-200, 200, 1000)])
    v = 10 ** rng.uniform(-3.0, 3.0, m.size)
    t, scaled = step_buffers.impulse_bound(m, v)
    assert not scaled
    floor = _ZERO * m * v
    near = [t]
    for _ in range(3):
        near = [np.nextafter(near[0], -np.inf), *near, np.nextafter(near[-1], np.inf)]
    odd = [np.full(m.size, a) for a in (0.0, -0.0, np.inf, -np.inf, np.nan, 1e-300, -1.0)]
    wide = [t * 10 ** rng.uniform(-3.0, 3.0, m.size) * rng.choice([-1.0, 1.0], m.size)]
    for delta in near + odd + wide:
        np.testing.assert_array_equal(delta <= t, m * delta <= floor)
        np.testing.assert_array_equal(delta > t, m * delta > floor)
    # v = 0 (floor 0), m = 0.1: T is 5 subnormals up (0.1 T rounds to 0), beyond the
    # search: the floor itself, for every contact (m = 0.3: 1 up, found)
    m, v = np.array([0.3, 0.1, 1.0]), np.array([0.0, 0.0, 1.0])
    with np.errstate(all="ignore"):
        assert step_buffers.impulse_bound(m[::2], v[::2])[1:] == (False,)
        t, scaled = step_buffers.impulse_bound(m, v)
    assert scaled
    np.testing.assert_array_equal(t, _ZERO * m * v)


@pytest.mark.parametrize("seed", [8, 9])
def test_states_through_is_the_frozen_loop_at_every_step_bit_for_bit(seed):
    k, d, m, g, v, h, p, _ = _designs(500, seed)
    n = 110  # beyond the end of most: they end, leave, turn back, stick
    x = states_through(k, d, m, g, v, h, p, n)
    rows = (np.repeat(a, n) for a in (k, d, m, g, v, h, p))
    x0, _, valid0, _ = _old(end_state, *rows, np.tile(np.arange(n), k.size))
    _same(x, x0.reshape(k.size, n), "x")
    assert 0.3 < np.mean(~valid0.reshape(k.size, n)[:, -1]) < 0.99


def test_overlaps_are_those_of_the_frozen_end_state_bit_for_bit():
    """``change_table._overlaps`` (one run for every node design of several tables of one
    member, each to the last table's end state) against the way it was (per table, the
    frozen end state of every state, the node designs tiled): the same coefficients."""
    rng = np.random.default_rng(13)
    x_e, x_p = (chebyshev_points(n) for n in (change_table.NODES_E, change_table.NODES_PHASE))
    ye, yp = np.meshgrid(x_e, x_p, indexing="ij")
    tables = 0
    for _ in range(4):
        g = float(rng.choice([0.0, 9.81]))
        member, h = (rng.uniform(0.05, 2.0), rng.uniform(0.3, 3.0), g), 1e-3
        nodes = []
        for base in rng.integers(15, 70, 3):
            w = np.pi / (base + 1) * (1.0 + 0.02 * ye + rng.uniform(-0.01, 0.01) * yp)
            s = rng.uniform(0.2, 2.0) * (1.0 + 0.1 * ye + 0.05 * yp)
            nodes.append((s, w, int(base)))
        for (s, w, base), new in zip(nodes, change_table._overlaps(nodes, member, h), strict=True):
            old = ref_overlaps(s, w, base, member, h)
            if isinstance(old, str):
                assert new == old
                continue
            tables += 1
            _same(new, old, "coefficients")
    assert tables >= 8


# Frozen copy: the loops of contact_ends and end_state as they were (docstrings dropped),
# run by their unchanged wrappers (_old).


def ref_block_ends(k, d, m, g, v, h, phase, out, *, stuck_peaks, **_):  # (no buffers)
    with np.errstate(all="ignore"):  # the finished contacts step on until gathered
        t0, x, u = _touch(v, g, h, phase)
        consts = ref_constants(k, d, m, g, v, h)
        coast = ref_ends_loop(np.arange(k.size), x, u, consts, (k, d, m, g, h, v, t0), out,
                           stuck_peaks=stuck_peaks)  # fmt: skip
        if coast is not None:
            ref_coast(*coast, consts, out)


def ref_margin_states(k, d, m, g, v, h, x, u, step, valid, **_):  # (no buffers)
    live = np.flatnonzero(step > 0)  # stepped; gathered when a quarter reached their step
    with np.errstate(all="ignore"):  # (those that reached it step on until gathered)
        consts = tuple(a[live] for a in ref_constants(k, d, m, g, v, h))
        xl, ul, sl = x[live], u[live], step[live]
        bad = np.zeros(live.size, bool)  # a state so far ended or turned back
        arrivals = np.bincount(sl)  # how many reach their step at each count
        done, count = 0, 0  # those reached among the gathered, and the count
        while live.size:
            ustar, new, free = ref_update(xl, ul, consts, contact=False)
            impulse = ustar - new
            impulse *= consts[1]
            ended = np.where(free, 0.0, impulse) <= consts[8]
            ended |= xl < 0.0
            turned = ul < 0.0
            turned &= new > 0.0
            ended |= turned
            bad |= ended
            xl += consts[9] * new
            ul = new
            count += 1
            if arrivals[count]:  # its state, and whether a state before it ended
                reached = sl == count
                i = live[reached]
                x[i], u[i], valid[i] = xl[reached], ul[reached], ~bad[reached]
                done += int(arrivals[count])
                if 4 * done >= live.size:
                    rest = sl > count
                    live, xl, ul, sl, bad = live[rest], xl[rest], ul[rest], sl[rest], bad[rest]
                    consts = tuple(a[rest] for a in consts)
                    done = 0


def ref_constants(k, d, m, g, v, h):
    hk = h * k
    return (
        h * g,  # u* = u + h g
        m,
        hk,  # c = m u* - h k x
        m + h * h * k,  # b = m + h^2 k + (h k d) x
        hk * d,
        4.0 * (h * h * k * d),  # disc = b^2 + (4 a) c
        -h,  # limit = max(-x/h, -1/d), -x/h = x/(-h)
        np.where(d > 0, -1.0 / d, -np.inf),
        _ZERO * m * v,  # the impulse floor
        h,
    )


def ref_update(x, u, consts, *, contact=True):
    hg, m, hk, b0, hkd, a4, nh, nd = consts[:8]
    ustar = u + hg
    c = m * ustar
    c -= hk * x
    b = hkd * x
    b += b0
    disc = b * b
    disc += a4 * c
    np.maximum(disc, 0.0, out=disc)
    np.sqrt(disc, out=disc)
    disc += b
    c *= 2.0
    c /= disc  # the root
    limit = x / nh
    np.maximum(limit, nd, out=limit)
    free = ustar <= limit
    if contact:
        free |= x < 0.0
    return ustar, np.where(free, ustar, c), free


def ref_ends_loop(live, x, u, consts, raw, out, *, stuck_peaks):
    k, d, m, g, h, v, t0 = raw
    settle = bool(np.any(g > 0))  # the settled, creep and rest rules (module docstring)
    x_max, peak = np.zeros(live.size), np.zeros(live.size) if settle else None
    going = np.ones(live.size, bool)  # not yet ended (the others are dropped in a while)
    finished = 0  # of the gathered
    coasting = []
    count = 0
    for count in range(MAX_STEPS):
        if live.size == 0:
            break
        impulse, new, _ = ref_update(x, u, consts)
        impulse -= new  # u* - new
        impulse *= consts[1]
        # going, and no impulse above the floor (or no contact): the end state
        ends = np.greater(going, impulse > consts[8])
        if ends.any():  # the end state: separation speed, and the time
            i = live[ends]
            out.restitution[i] = -u[ends] / v[i]
            out.contact_time[i] = t0[i] + count * h[i]
            out.max_penetration[i] = x_max[ends]
            out.end_penetration[i] = x[ends]
            stay = ends & (x >= 0.0)  # no impulse inside the overlap: it coasts on
            if stay.any():
                start = np.full(np.count_nonzero(stay), count + 1)
                coasting.append((live[stay], x[stay] + consts[9][stay] * new[stay],
                                 new[stay], start))  # fmt: skip
            going &= ~ends
            finished += int(np.count_nonzero(ends))
        np.maximum(x_max, x, out=x_max)
        if settle:
            np.maximum(peak, impulse / consts[9], out=peak)
        turned = u < 0.0
        turned &= new > 0.0
        turned &= going
        if settle and count % _SETTLE_EVERY == _SETTLE_EVERY - 1:  # step_contact's checks
            rows = (a[live] for a in (k, d, m, g, h, v))
            stuck, x_max = stuck_early(going, x, u, new, *rows, x_max, peak, stuck_peaks)
            turned |= stuck
        if turned.any():
            i = live[turned]
            out.sticks[i] = True
            out.max_penetration[i] = x_max[turned]
            going &= ~turned
            finished += int(np.count_nonzero(turned))
        x += consts[9] * new
        u = new
        if 4 * finished >= live.size:  # drop the finished ones
            live, x, u, x_max = live[going], x[going], u[going], x_max[going]
            consts = tuple(a[going] for a in consts)
            peak = peak[going] if settle else None
            going = np.ones(live.size, bool)
            finished = 0
    i = live[going]
    out.sticks[i] = True
    out.max_penetration[i] = x_max[going]
    if not coasting:
        return None
    return tuple(np.concatenate(a) for a in zip(*coasting, strict=True))


def ref_coast(live, x, u, start, consts, out):
    consts = tuple(a[live] for a in consts)
    for j in range(MAX_STEPS):
        if live.size == 0:
            break
        ustar, new, _ = ref_update(x, u, consts)
        impulse = ustar - new
        impulse *= consts[1]
        back = (x >= 0.0) & (impulse > consts[8])
        out.sticks[live[back | (start + j >= MAX_STEPS)]] = True
        keep = (x >= 0.0) & ~back & (start + j < MAX_STEPS)
        x = x + consts[9] * new
        live, x, u, start = live[keep], x[keep], new[keep], start[keep]
        consts = tuple(a[keep] for a in consts)


def ref_overlaps(s, w, base, member, h):
    m, v, g = member
    steps = np.arange(base + 2)  # the states before the end state B + 1, and it
    k, d = m * (w.ravel() / h) ** 2, s.ravel() / v
    size = steps.size
    x, _, _, _ = _old(end_state, np.repeat(k, size), np.repeat(d, size), m, g, v, h,
                      GRID_PHASES[-1], np.tile(steps, k.size))  # fmt: skip
    x = x.reshape(k.size, steps.size) / (v * h)
    deepest = np.argmax(x, axis=1)
    j0, j1 = max(int(deepest.min()) - 1, 0), min(int(deepest.max()) + 1, base)
    shape = (change_table.NODES_E, change_table.NODES_PHASE, -1)
    values = np.moveaxis(x[:, j0 : j1 + 1].reshape(shape), 2, 0)
    return fit(values, change_table.TAIL)
