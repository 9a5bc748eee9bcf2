"""The phases where a state of MuJoCo's Euler contact crosses a kink of the impedance.

The restitution has a kink where a state's penetration crosses ``mid * width`` or the
width of ``solimp`` (`impactsym.engines.mujoco.euler_kinks`), where the phase summary
cuts its pieces. Checked against the states of a plain Python loop with MuJoCo's own
impedance and force (`references.mujoco_steps`); the summary itself in
`test_engines_mujoco_dense_mean.py`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from impactsym.engines.mujoco.euler import euler_state
from impactsym.engines.mujoco.euler_kinks import kink_cuts, split_pieces
from impactsym.engines.mujoco.model import DEFAULT_SOLIMP, check_solimp, coefficients

sys.path.insert(0, str(Path(__file__).parent))
from references.mujoco_steps import contact_law, impedance

DEFAULT = DEFAULT_SOLIMP  # (0.9, 0.95, 0.001, 0.5, 2)


def _plain_depths(solref, speed, gravity, dt, phase, steps):
    """Penetration (m) of the states 0 .. steps - 1 after the first detecting one: MuJoCo's
    Euler step written out (mass 1, force clipped at zero, no end test)."""
    k, b, simp = contact_law(solref, DEFAULT, dt)
    t = phase * dt
    x, u = speed * t + 0.5 * gravity * t * t, speed + gravity * t
    out = []
    for _ in range(steps):
        out.append(x)
        d = impedance(-x, simp)
        r = (1 - d) / d
        f = max(0.0, (gravity + b * u + k * d * x) / (1.0 + r))  # (aref - a0) / (A + R)
        u += dt * (gravity - f)
        x += dt * u
    return np.array(out)


CONTACTS = [  # solref, speed, gravity, timestep
    ((0.03983713160728383, 0.18858158549730225), 4.796796172383586, 9.81, 0.01),
    ((0.036411799065449516, 0.22505001422117524), 3.1966362886551694, 9.81, 0.01),
    ((0.028929455888798045, 0.3149149594834228), 2.6591509850016326, 0.0, 0.01),
    ((0.02, 0.4), 1.0, 9.81, 0.002),
    ((0.01, 1.5), 0.3, 9.81, 0.002),  # barely reaches the width
]


@pytest.mark.parametrize(("solref", "speed", "gravity", "dt"), CONTACTS)
def test_cuts_are_where_a_state_crosses_mid_width_or_width(solref, speed, gravity, dt):
    """Every sign change of ``x_k - level * width`` (k < steps) on a scan of 2000 phases of
    the plain loop has a cut within the scan's spacing, and every cut is such a root."""
    simp = check_solimp(DEFAULT)
    steps = 6
    n = 2000
    p = (np.arange(n) + 0.5) / n
    x = np.array([_plain_depths(solref, speed, gravity, dt, q, steps) for q in p])
    want = []
    for level in (0.5 * 0.001, 0.001):
        side = x > level
        for i in np.nonzero(side[1:] != side[:-1])[0]:
            want.append(0.5 * (p[i] + p[i + 1]))
    c = coefficients(solref, simp, dt)
    one = np.ones(1)
    piece, cut, _ = kink_cuts(
        c.__class__(c.damping * one, c.stiffness * one), simp, one, gravity * one,
        speed * one, dt * one, np.array([p[0]]), np.array([p[-1]]), np.array([steps]),
    )  # fmt: skip
    assert np.all(piece == 0)
    assert len(want) > 0
    assert len(cut) == len(want)
    for phase in want:
        assert np.min(np.abs(cut - phase)) <= 0.5 / n
    # each cut: some state's depth at a level to 1e-9 of the width (the secant's bracket)
    for q in cut:
        depths = _plain_depths(solref, speed, gravity, dt, q, steps)
        miss = np.abs(depths[:, None] - np.array([0.5e-3, 1e-3])[None, :]).min()
        assert miss < 1e-9 * (1.0 + speed * dt / 1e-3) * 1e-3


def test_euler_state_penetration_is_the_plain_loops():
    simp = check_solimp(DEFAULT)
    solref, speed, g, dt, phase = (0.02, 0.4), 1.3, 9.81, 0.002, 0.37
    c = coefficients(solref, simp, dt)
    got = euler_state(c, simp, 1.0, g, speed, dt, phase, np.arange(8))[0] * speed * dt
    np.testing.assert_allclose(got, _plain_depths(solref, speed, g, dt, phase, 8), rtol=1e-12)


def test_split_pieces_cuts_in_order():
    p0, p1 = np.array([0.0, 0.5, 0.7]), np.array([0.5, 0.7, 1.0])
    q0, q1, parent = split_pieces(p0, p1, np.array([0, 0, 2]), np.array([0.1, 0.3, 0.9]))
    np.testing.assert_array_equal(q0, [0.0, 0.1, 0.3, 0.5, 0.7, 0.9])
    np.testing.assert_array_equal(q1, [0.1, 0.3, 0.5, 0.7, 0.9, 1.0])
    np.testing.assert_array_equal(parent, [0, 0, 0, 1, 2, 2])


def _flags(solref, speed, gravity, dt, p0, p1, steps):
    simp = check_solimp(DEFAULT)
    c = coefficients(solref, simp, dt)
    one = np.ones(len(p0))
    return kink_cuts(
        c.__class__(c.damping * one, c.stiffness * one), simp, one, gravity * one,
        speed * one, dt * one, np.array(p0), np.array(p1), np.array(steps),
    )[2]  # fmt: skip


def test_pieces_with_a_band_of_another_end_step_between_samples_are_flagged():
    """The end steps over the phase by a scan of the plain loop: 3 -> 2 -> 3 -> 2 at
    0.00142, 0.00893, 0.02643, and 4 -> 5 -> 4 at 0.04360, 0.04741 (bands narrower than
    the samples' spacing 1/32): those pieces are flagged, pieces of one end step not."""
    a = ((0.022914556416744388, 0.5488991515373116), 4.430008325332154, 9.81, 0.01)
    b = ((0.028064687511759747, 0.5370509861658027), 1.9253745430890092, 9.81, 0.01)
    for contact, changes, hidden, smooth in (
        (a, (0.00142, 0.00893, 0.02643), ([0.0, 0.125], 3), ([0.25, 0.375], 2)),
        (b, (0.04360, 0.04741), ([0.0, 0.125], 4), ([0.25, 0.375], 3)),
    ):
        solref, speed, g, dt = contact
        simp = check_solimp(DEFAULT)
        p = (np.arange(4096) + 0.5) / 4096 * 0.375
        ends = np.array([_plain_end(solref, simp, speed, g, dt, q) for q in p])
        at = 0.5 * (p[1:] + p[:-1])[ends[1:] != ends[:-1]]
        np.testing.assert_allclose(at[: len(changes)], changes, atol=1e-4)
        assert not np.any(at > 0.25)  # the second piece has one end step
        (h0, h1), h_steps = hidden
        (s0, s1), s_steps = smooth
        got = _flags(solref, speed, g, dt, [h0, s0], [h1, s1], [h_steps, s_steps])
        np.testing.assert_array_equal(got, [True, False])


def _plain_end(solref, simp, speed, gravity, dt, phase):
    """The end state of the plain loop (counted from the first detecting one)."""
    k, b, law = contact_law(solref, DEFAULT, dt)
    t = phase * dt
    x, u = speed * t + 0.5 * gravity * t * t, speed + gravity * t
    n = 0
    while True:
        d = impedance(-x, law)
        f = (gravity + b * u + k * d * x) * d
        if n > 0 and (x <= 0 or f <= 0):
            return n
        u += dt * (gravity - max(f, 0.0))
        x += dt * u
        n += 1
