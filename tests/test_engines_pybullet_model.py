"""The PyBullet model without the engine: the map against its SymPy derivation, the
continuous limit, the phase mean against dense sampling, the pair rules, the design."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from impactsym.contact import restitution as linear_restitution
from impactsym.engines import pybullet as pyb
from impactsym.engines.pybullet.derivation import BulletContactRow
from impactsym.engines.pybullet.stepping import step_contact

K, C, M, V = 1e4, 40.1, 1.0, 1.0


def _sympy_run(k, c, m, v, g, h, p, s, threshold):
    """The end state iterated with the derivation's expressions, one scalar step at a time."""
    row = BulletContactRow()
    subs = {row.k: k, row.c: c, row.m: m, row.h: h, row.g: g, row.s: s}
    steps = {
        b: sp.lambdify((row.x, row.w), [e.subs(subs) for e in row.step(b)], "math")
        for b in ("speculative", "penetrating")
    }
    rhs = {b: sp.lambdify((row.x, row.w), e.subs(subs), "math") for b, e in row.rhs.items()}
    t = (p - 1.0) * h
    x, w = v * t + g * t * t / 2, v + g * t
    on = False
    for n in range(10_000):
        branch = "speculative" if s - x > 0 else "penetrating"
        push = -x <= threshold and rhs[branch](x, w) > 0
        x, w = steps[branch](x, w) if push else (x + h * (w + g * h), w + g * h)
        if push:
            on = True
        elif on:
            return -w / v, (p + n) * h
    raise AssertionError("no end")


@pytest.mark.parametrize(
    ("g", "p", "s", "threshold"),
    [
        (0.0, 0.3, 1e-5, np.inf),
        (9.81, 0.7, 1e-5, np.inf),
        (9.81, 0.4, 0.0, 0.0),
        (0.0, 1e-3, 1e-5, np.inf),
    ],
)
def test_the_map_is_the_derivation(g, p, s, threshold):
    e, t = _sympy_run(K, C, M, V, g, 1 / 240, p, s, threshold)
    r = step_contact(K, C, M, V, g, 1 / 240, p, slop=s, processing_threshold=threshold)
    assert float(r.restitution) == pytest.approx(e, rel=1e-12)
    assert float(r.contact_time) == pytest.approx(t, rel=1e-14)


def test_the_map_contracts_and_tends_to_the_spring_dashpot():
    row = BulletContactRow()
    assert sp.simplify(row.determinant - row.m / (row.m + row.h * row.c + row.h**2 * row.k)) == 0
    assert sp.simplify(row.pgs_first_iteration - row.D * row.rhs["penetrating"]) == 0
    # restitution -> the clipped (force-condition) linear value as the step shrinks
    zeta = 20.0 / (2.0 * np.sqrt(K * M))
    exact = linear_restitution(zeta, 0.0, condition="force")
    errors = [
        abs(
            pyb.predict(
                stiffness=K, damping=19.9, mass=M, speed=V, timestep=h, slop=0.0
            ).restitution
            - exact
        )
        for h in (1e-3, 1e-4)
    ]
    assert errors[1] < errors[0] / 5
    assert errors[1] < 0.02


@pytest.mark.parametrize(
    "settings", [{}, {"gravity": 9.81, "substeps": 2}, {"slop": 0.0, "processing_threshold": 0.0}]
)
def test_the_phase_mean_is_the_dense_phase_average(settings):
    phases = (np.arange(100_000) + 0.5) / 100_000
    dense = pyb.predict(stiffness=K, damping=40.0, mass=M, speed=V, phase=phases, **settings)
    mean = pyb.predict(stiffness=K, damping=40.0, mass=M, speed=V, **settings)
    assert mean.restitution == pytest.approx(dense.restitution.mean(), abs=2e-6)
    assert mean.contact_time == pytest.approx(dense.contact_time.mean(), rel=1e-6)
    lo, hi = mean.restitution_range
    assert lo <= dense.restitution.min() + 1e-12
    assert dense.restitution.max() <= hi + 1e-12
    assert dense.restitution.min() - lo < 1e-4
    assert hi - dense.restitution.max() < 1e-4


def test_pair_rules_round_trip():
    k, c = pyb.combine_pair(stiffness=3e4, damping=12.0, other_stiffness=6e4, other_damping=3.0)
    assert (k, c) == (pytest.approx(2e4), 15.0)
    assert pyb.split_pair(stiffness=k, damping=c, other_stiffness=6e4, other_damping=3.0) == (
        pytest.approx(3e4),
        pytest.approx(12.0),
    )
    with pytest.raises(ValueError, match="other body already brings"):
        pyb.split_pair(stiffness=1e4, damping=0.05)


def test_designs_are_vectorized_and_meet_their_targets():
    e = np.array([0.3, 0.5, 0.7])
    t = np.array([0.03, 0.05, 0.08])
    d = pyb.contact_for(restitution=e, speed=1.0, mass=0.2, contact_time=t)
    np.testing.assert_allclose(d.restitution, e, rtol=1e-6)
    np.testing.assert_allclose(d.contact_time, t, rtol=1e-6)
    again = pyb.predict(stiffness=d.stiffness, damping=d.damping, mass=0.2, speed=1.0)
    np.testing.assert_allclose(again.restitution, e, rtol=1e-6)
    default = pyb.contact_for(restitution=0.5, speed=1.0, mass=0.2)
    assert default.contact_time == pytest.approx(10 / 240, rel=1e-6)


def test_an_unreachable_design_names_a_timestep_that_reaches_it():
    with pytest.raises(ValueError, match=r"timestep = ([0-9.e-]+) s reaches it") as err:
        pyb.contact_for(restitution=0.75, speed=1.0, mass=0.1, contact_time=0.02)
    step = float(err.value.args[0].split("timestep = ")[-1].split(" s reaches")[0])
    d = pyb.contact_for(restitution=0.75, speed=1.0, mass=0.1, contact_time=0.02, timestep=step)
    assert d.restitution == pytest.approx(0.75, rel=1e-6)


def test_close_pattern_changes_inside_one_grid_interval_are_all_found():
    # three sub-steps put two changes 0.011 apart in one grid interval near 1/3 and 2/3
    case = {"stiffness": 15789.73, "mass": 2.6011, "speed": 4.9899, "gravity": 9.81}
    damping = 18.22 - 0.1
    phases = (np.arange(200_000) + 0.5) / 200_000
    dense = pyb.predict(**case, damping=damping, substeps=3, phase=phases)
    mean = pyb.predict(**case, damping=damping, substeps=3)
    assert mean.restitution == pytest.approx(dense.restitution.mean(), abs=2e-6)
    assert mean.restitution_range[1] >= dense.restitution.max() - 1e-12
    assert mean.restitution_range[0] <= dense.restitution.min() + 1e-12
