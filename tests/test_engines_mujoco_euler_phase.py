"""The closed-form phase statistics of the flat Euler contact (euler_phase) against two
references that do not use its piecewise quadratics: the general summary (end-step jumps
by bisection on the exact per-phase model, Gauss-Legendre on each piece) and, where the
body sticks at some phases, dense sampling of the per-phase model."""

import numpy as np

from impactsym.engines.mujoco import discrete, euler_phase
from impactsym.engines.mujoco.euler import euler_contact
from impactsym.engines.mujoco.euler_phase import flat_phases
from impactsym.engines.mujoco.model import (
    Coefficients,
    coefficients,
    effective_impedance,
    impedance_at,
)

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


def _designs(n, seed, sticky=False):
    rng = np.random.default_rng(seed)
    dr = rng.uniform(0.15, 3.0 if sticky else 1.2, n)
    g = np.where(rng.random(n) < 0.6, 9.81, 0.0)
    v = rng.uniform(0.2, 2.0, n) if sticky else rng.uniform(0.8, 2.0, n)
    dt = rng.choice([0.002, 0.001, 0.0005], n)
    c = coefficients((np.full(n, 0.02), dr), FLAT, 0.002)
    return c, g, v, dt


def _fast(c, g, v, dt):
    d = float(impedance_at(np.zeros(()), FLAT))
    dp = effective_impedance(d, 1.0)
    kdt2, bdt = d * c.stiffness * dt * dt, c.damping * dt
    return flat_phases(
        kappa=dp * kdt2, beta=dp * bdt, dp=np.full(g.shape, dp), G=g * dt / v, bdt=bdt, dkdt2=kdt2
    )


def test_matches_the_general_summary_where_no_phase_sticks():
    c, g, v, dt = _designs(120, 3)
    fast = _fast(c, g, v, dt)
    ref = discrete._split_and_integrate(
        euler_contact, "euler", FLAT, c.damping, c.stiffness, np.ones(g.size), g, v, dt
    )
    use = fast.ok & (ref[6] == 0)
    assert use.sum() > 80
    got = np.stack(
        [
            fast.restitution,
            fast.steps * dt,
            fast.restitution_min,
            fast.restitution_max,
            fast.steps_min * dt,
            fast.steps_max * dt,
            fast.stick_fraction,
        ]
    )
    scale = np.array([1.0, 0.05, 1.0, 1.0, 0.05, 0.05, 1.0])[:, None]
    with np.errstate(invalid="ignore"):  # inf - inf where both contact times are inf
        diff = np.where(got == ref, 0.0, np.abs(got - ref))
    assert np.max(diff[:, use] / scale) < 1e-11


def test_sticking_phases_against_dense_sampling():
    """Designs where the body stays in contact for good at some phases: the mean and the
    stick fraction against the per-phase model on 2e5 phases (midpoint rule: each jump
    costs at most its height / 4e5)."""
    c, g, v, dt = _designs(4000, 6, sticky=True)
    # and one the general summary gets wrong by 6e-6 (two jumps in one of its grid
    # intervals): dampratio 0.7533, 1.3854 m/s under gravity at dt = 0.0005
    one = coefficients((np.array([0.02]), np.array([0.75327302])), FLAT, 0.002)
    c = Coefficients(np.append(c.damping, one.damping), np.append(c.stiffness, one.stiffness))
    g, v, dt = np.append(g, 9.81), np.append(v, 1.38544375), np.append(dt, 0.0005)
    fast = _fast(c, g, v, dt)
    some = np.flatnonzero(fast.ok & (fast.stick_fraction > 0.02) & (fast.stick_fraction < 0.98))
    assert some.size >= 3
    assert some[-1] == g.size - 1
    p = (np.arange(200_000) + 0.5) / 200_000
    for i in (*some[:2], some[-1]):
        r = euler_contact(
            Coefficients(c.damping[i], c.stiffness[i]), FLAT, 1.0, g[i], v[i], dt[i], p
        )
        assert abs(r.restitution.mean() - fast.restitution[i]) < 2e-5
        assert abs(r.sticks.mean() - fast.stick_fraction[i]) < 2e-5
        assert np.isinf(fast.steps[i])


def test_phase_summary_uses_it_and_keeps_phase_zero():
    """``phase_summary`` of a flat Euler contact: the closed form, plus phase 0 (one run
    of the per-phase model) in the range."""
    c, g, v, dt = _designs(20, 8)
    s = discrete.phase_summary(c, FLAT, 1.0, g, v, dt, integrator="euler")
    fast = _fast(c, g, v, dt)
    zero = euler_contact(c, FLAT, 1.0, g, v, dt, np.zeros(g.size))
    ok = fast.ok
    assert np.allclose(s.restitution[ok], fast.restitution[ok], rtol=0, atol=1e-15)
    assert np.all(s.restitution_min <= zero.restitution)
    assert np.all(s.restitution_max >= zero.restitution)
    assert np.all(s.contact_time_max >= zero.contact_time)


def test_an_unstable_map_is_left_to_the_general_summary():
    """Spectral radius >= 1 (dampratio far below the stability limit at dt = 0.002)."""
    c = coefficients((np.array([0.02]), np.array([0.01])), FLAT, 0.002)
    fast = _fast(c, np.zeros(1), np.ones(1), np.array([0.002]))
    assert not fast.ok[0]


def test_many_ending_steps_are_done_in_closed_form_against_the_general_summary(monkeypatch):
    """Near the stability limit and for soft, loaded contacts the contact ends at more
    than six different steps over the phases: those elements are redone alone with more
    slots (not left to the general summary), and agree with it (here some phases
    stick: the stick fraction too)."""
    dt, v, g = 0.002, 1.0, 9.81
    dr = np.geomspace(0.07, 3.0, 600)  # a restitution design's table at 1 m/s, gravity
    c = coefficients((np.full(dr.size, 0.02), dr), FLAT, dt)
    ones = np.ones(dr.size)
    d = float(impedance_at(np.zeros(()), FLAT))
    dp = effective_impedance(d, 1.0)
    args = {
        "kappa": dp * d * c.stiffness * dt * dt, "beta": dp * c.damping * dt,
        "dp": dp * ones, "G": g * dt / v * ones, "bdt": c.damping * dt,
        "dkdt2": d * c.stiffness * dt * dt,
    }  # fmt: skip
    fast = flat_phases(**args)
    with monkeypatch.context() as m:  # without the second pass
        m.setattr(euler_phase, "_MORE_SLOTS", 6)
        few = flat_phases(**args)
    i = np.flatnonzero(fast.ok & ~few.ok)  # more than six slots needed
    assert i.size >= 2
    ref = discrete._split_and_integrate(
        euler_contact, "euler", FLAT, c.damping[i], c.stiffness[i], ones[i], g * ones[i],
        v * ones[i], dt * ones[i],
    )  # fmt: skip
    got = np.stack([fast.restitution[i], fast.restitution_min[i], fast.restitution_max[i],
                    fast.stick_fraction[i]])  # fmt: skip
    assert np.max(np.abs(got - ref[[0, 2, 3, 6]])) < 1e-11


def test_a_proven_stick_skips_the_general_summary_only_when_asked():
    """``resolve_sticking=False`` (a design's black box): an element the closed form
    proves to stick at some phase comes back with an infinite mean contact time and no
    mean, while the full summary (general way) confirms a stick fraction > 0."""
    c, g, v, dt = _designs(4000, 6, sticky=True)
    fast = _fast(c, g, v, dt)
    caught = np.flatnonzero(fast.sticks_at_some_phase)
    assert caught.size > 0
    assert not fast.ok[caught].any()
    i = caught[:3]
    part = Coefficients(c.damping[i], c.stiffness[i])
    quick = discrete.phase_mean(
        part, FLAT, 1.0, g[i], v[i], dt[i], integrator="euler", resolve_sticking=False
    )
    full = discrete.phase_mean(part, FLAT, 1.0, g[i], v[i], dt[i], integrator="euler")
    assert np.all(np.isinf(quick.contact_time))
    assert np.all(np.isnan(quick.restitution))
    assert np.all(full.stick_fraction > 0)
    assert np.all(np.isinf(full.contact_time))
