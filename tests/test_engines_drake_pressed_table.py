"""Continuous Drake designs under gravity read off one Chebyshev table in (s, b).

The designs read off the table are checked by what did not make them: a fresh exact
``predict`` at the design (the order-8 integration), SciPy's ``solve_ivp`` with an end
event, and the exact iteration of ``point_contact_for`` on the same targets in calls
too small for a table.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.engines import drake
from impactsym.engines.drake import design
from impactsym.engines.drake.pressed_table import MIN_TARGETS, pressed_designs

RNG = np.random.default_rng(2024)


def _targets(n, b_max=0.1):
    """Random targets (e, t_c, x_max, m, v, g) whose pressing numbers before gravity's
    shift, about ``t_c g / (pi v)`` and ``x_max g / v^2``, stay below ``b_max``."""
    e = RNG.uniform(0.3, 0.95, n)
    m, v = 10 ** RNG.uniform(-2, 1, n), 10 ** RNG.uniform(-1, 1, n)
    g = 10 ** RNG.uniform(-1, 1.5, n)
    t = b_max * np.pi * v / g * RNG.uniform(0.01, 1.0, n)
    x = 0.5 * b_max * v**2 / g * RNG.uniform(0.01, 1.0, n)
    return e, t, x, m, v, g


@pytest.mark.parametrize("size_name", ["contact_time", "max_penetration"])
def test_read_designs_meet_their_targets_by_a_fresh_prediction(size_name):
    e, t, x, m, v, g = _targets(600)
    size = t if size_name == "contact_time" else x
    assert pressed_designs(e, v, m, g, size, size_name)[0].all()  # every one read off
    c = drake.point_contact_for(restitution=e, speed=v, mass=m, gravity=g, **{size_name: size})
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=m, speed=v, gravity=g)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e, rtol=1e-12)
    np.testing.assert_allclose(getattr(p, size_name), size, rtol=1e-12)
    # what the design reports is what the prediction gives
    for name in ("restitution", "contact_time", "max_penetration"):
        np.testing.assert_allclose(getattr(c, name), getattr(p, name), rtol=1e-12)
    assert not np.any(c.sticks)
    assert np.all(c.prediction.stick_fraction == 0.0)


def _ode(k, d, m, v, g):
    """Restitution and contact time by SciPy: m x'' = m g - k x (1 + d x')_+ until x = 0."""

    def rhs(_, y):
        return [y[1], g - k / m * y[0] * max(0.0, 1.0 + d * y[1])]

    def out(_, y):
        return y[0]

    out.terminal, out.direction = True, -1.0
    t_end = 50.0 * np.pi * np.sqrt(m / k)
    r = solve_ivp(rhs, (0.0, t_end), [1e-300, v], method="DOP853", rtol=1e-13,
                  atol=[1e-16 * v * t_end, 1e-16 * v], events=out)  # fmt: skip
    return -r.y_events[0][0][1] / v, r.t_events[0][0]


def test_read_designs_hold_in_an_independent_integration():
    e, t, _, m, v, g = _targets(MIN_TARGETS)
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g)
    for j in range(0, MIN_TARGETS, 16):
        e_ode, t_ode = _ode(c.point_contact_stiffness[j], c.hunt_crossley_dissipation[j],
                            m[j], v[j], g[j])  # fmt: skip
        assert abs(e_ode / e[j] - 1.0) < 1e-9
        assert abs(t_ode / t[j] - 1.0) < 1e-9


def test_read_designs_are_those_of_the_exact_iteration():
    e, t, _, m, v, g = _targets(2 * MIN_TARGETS)
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g)
    half = MIN_TARGETS // 2  # calls too small for a table: the exact iteration
    for j in range(0, e.size, half):
        part = slice(j, j + half)
        x = drake.point_contact_for(restitution=e[part], contact_time=t[part], speed=v[part],
                                    mass=m[part], gravity=g[part])  # fmt: skip
        np.testing.assert_allclose(c.point_contact_stiffness[part], x.point_contact_stiffness,
                                   rtol=1e-9)  # fmt: skip
        np.testing.assert_allclose(c.hunt_crossley_dissipation[part],
                                   x.hunt_crossley_dissipation, rtol=1e-9)  # fmt: skip


def test_calls_below_min_targets_never_read_a_table(monkeypatch):
    e, t, _, m, v, g = _targets(MIN_TARGETS)

    def refuse(*args):
        raise AssertionError("a table for fewer than MIN_TARGETS targets")

    monkeypatch.setattr(design, "pressed_designs", refuse)
    g_mixed = g.copy()
    g_mixed[0] = 0.0  # MIN_TARGETS - 1 under gravity
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g_mixed)
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=m, speed=v, gravity=g_mixed)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e, rtol=1e-9)
    with pytest.raises(AssertionError, match="fewer than"):
        drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g)


def test_unpressed_targets_of_a_table_call_are_designed_as_alone():
    e, t, _, m, v, g = _targets(MIN_TARGETS + 20)
    g[:20] = 0.0
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g)
    alone = drake.point_contact_for(restitution=e[:20], contact_time=t[:20], speed=v[:20],
                                    mass=m[:20], gravity=0.0)  # fmt: skip
    assert np.array_equal(c.point_contact_stiffness[:20], alone.point_contact_stiffness)
    assert np.array_equal(c.hunt_crossley_dissipation[:20], alone.hunt_crossley_dissipation)
    assert np.array_equal(c.contact_time[:20], alone.contact_time)


def test_targets_near_sticking_split_the_table_or_are_iterated():
    # pressing numbers up to 0.3: the box of all of them reaches sticking (no table), its
    # halves read most targets off, the exact iteration designs the rest
    e, t, _, m, v, g = _targets(4 * MIN_TARGETS, b_max=0.3)
    ok = pressed_designs(e, v, m, g, t, "contact_time")[0]
    assert 0.5 < ok.mean() < 1.0
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=v, mass=m, gravity=g)
    p = drake.predict(stiffness=c.point_contact_stiffness, dissipation=c.hunt_crossley_dissipation,
                      mass=m, speed=v, gravity=g)  # fmt: skip
    np.testing.assert_allclose(p.restitution, e, rtol=1e-9)
    np.testing.assert_allclose(p.contact_time, t, rtol=1e-9)
    np.testing.assert_allclose(c.restitution[ok], p.restitution[ok], rtol=1e-12)


def test_a_box_with_a_sticking_corner_costs_its_corners_not_a_table(monkeypatch):
    # e <= 0.02 under gravity: heavy damping, and the box's far corner (largest damping
    # and pressing numbers) sticks; each box is refused after its four corner impacts
    # (it cost 512 exact impacts, 7 s, before) and the targets are left to the iteration
    from impactsym.engines.drake import pressed_table

    evaluated = []
    exact = pressed_table.normalized_impact

    def counting(law, s, b, *args, **kwargs):
        evaluated.append(np.size(s))
        return exact(law, s, b, *args, **kwargs)

    monkeypatch.setattr(pressed_table, "normalized_impact", counting)
    n = 2 * MIN_TARGETS
    e, t = np.linspace(0.005, 0.02, n), np.linspace(0.02, 0.04, n)[::-1]
    one = np.ones(n)
    ok = pressed_designs(e, one, 0.1 * one, 9.81 * one, t, "contact_time")[0]
    assert not ok.any()
    assert evaluated
    assert set(evaluated) == {4}


def test_read_designs_deliver_in_drake():
    if os.environ.get("CI") != "true":  # CI installs the engine: there it must run
        pytest.importorskip("pydrake")
    from impactsym.engines.drake.driver import drake_continuous

    e = np.linspace(0.4, 0.8, MIN_TARGETS)
    t = np.linspace(2e-3, 1.5e-2, MIN_TARGETS)
    c = drake.point_contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1, gravity=9.81)
    for j in (0, MIN_TARGETS // 2, MIN_TARGETS - 1):
        run = drake_continuous(stiffness=c.point_contact_stiffness[j],
                               dissipation=c.hunt_crossley_dissipation[j], mass=0.1, speed=1.0,
                               gravity=9.81)  # fmt: skip
        assert abs(run["restitution"] / e[j] - 1.0) < 5e-3
        assert abs(run["contact_time"] / t[j] - 1.0) < 5e-3


def test_leftovers_refused_together_are_iterated_apart(monkeypatch):
    # the iteration's stopping rules act on its whole batch: where it refuses the targets
    # a table left, they are iterated in halves down to single targets (never the whole
    # call again), and a target is refused only alone, with its own reason
    e, t, _, m, v, g = _targets(MIN_TARGETS + 8)
    g[:8] = 0.0  # left to the iteration
    args = {"restitution": e, "contact_time": t, "speed": v, "mass": m, "gravity": g}
    iterate, sizes = design._iterate, []

    def refuse_batches(*rows):
        sizes.append(rows[0].size)
        if rows[0].size > 1:
            raise ValueError("refused in a batch")
        return iterate(*rows)

    monkeypatch.setattr(design, "_iterate", refuse_batches)
    c = drake.point_contact_for(**args)
    assert sizes == [8, 4, 2, 1, 1, 2, 1, 1, 4, 2, 1, 1, 2, 1, 1]
    for i in (0, 5):  # each as designed alone (no table: the iteration alone)
        alone = drake.point_contact_for(**{key: val[i] for key, val in args.items()})
        assert alone.point_contact_stiffness == c.point_contact_stiffness[i]
        assert alone.hunt_crossley_dissipation == c.hunt_crossley_dissipation[i]

    def refuse_one(*rows):
        if np.any(rows[0] == e[5]):
            raise ValueError(f"restitution {float(e[5])} refused")
        return iterate(*rows)

    monkeypatch.setattr(design, "_iterate", refuse_one)
    with pytest.raises(ValueError, match=f"restitution {float(e[5])} refused"):
        drake.point_contact_for(**args)
