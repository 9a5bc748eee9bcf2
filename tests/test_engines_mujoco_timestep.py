"""MuJoCo at the user's timestep: impactsym.engines.mujoco.predict / solref_for with a
``timestep``, an ``integrator`` and a touch ``phase`` against MuJoCo itself
(impactsym.engines.drivers.mujoco_phases, the phase set by the initial state).

Euler, implicitfast and RK4 at dt = 0.002, 0.001, 0.0005; flat and default ``solimp``;
gravity on and off; the continuous designs for e = 0.1 ... 0.9 and textbook solrefs:

* per phase, the predicted restitution and contact time equal MuJoCo's to 1e-6
  (flat impedance) and 1e-4 (default ``solimp``), and the stick verdict is MuJoCo's;
* over phases (``phase=None``), MuJoCo's values at every phase of a fine even grid lie in
  the predicted range, and their mean is the predicted mean within the grid's
  quadrature error;
* designs at the default timestep (``solref_for(..., timestep=0.002)``) give MuJoCo a
  phase-mean restitution (and contact time) within 0.5 % of the target.

One MuJoCo model per case, reused over its phases.
"""

from __future__ import annotations

import itertools
import os

import numpy as np
import pytest

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("mujoco")

from impactsym.engines.drivers import mujoco_phases
from impactsym.engines.mujoco import predict, solref_for

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)
INTEGRATORS = ("euler", "implicitfast", "rk4")
TIMESTEPS = (0.002, 0.001, 0.0005)
RTOL = {FLAT: 1e-6, DEFAULT: 1e-4}
PHASES = np.array([0.03, 0.17, 0.29, 0.42, 0.5, 0.63, 0.71, 0.86, 0.97])
GRID = (np.arange(256) + 0.5) / 256  # the even phase grid of the means (midpoints)
MAX_STEPS = 1500  # 3 s of contact at dt = 0.002: longer counts as sticking

# dampratios of the continuous designs (solref_for with timestep=None, timeconst 0.02,
# speed 1 m/s) for e = 0.1, 0.3, 0.5, 0.7, 0.9 (under gravity e = 0.1 is out of reach at
# 1 m/s: 0.2 instead)
CONTINUOUS = {
    (FLAT, 0.0): (1.2431878510137804, 0.4972393946992944, 0.25527563764865185,
                  0.12221474778772486, 0.03426520412623275),
    (FLAT, 9.81): (0.584969996964649, 0.46474407624864106, 0.2520919342321012,
                   0.12178575175903117, 0.03424073509609117),
    (DEFAULT, 0.0): (1.2454721277917242, 0.49870980816106325, 0.2566410287517208,
                     0.12357688597187841, 0.03448424444017943),
    (DEFAULT, 9.81): (0.5883104884454271, 0.46800991168447653, 0.25404907006039074,
                      0.12329318291854598, 0.03446152694122271),
}  # fmt: skip
# textbook solrefs: MuJoCo's default, a stiffer one, refsafe active at 0.002 and 0.001
# (timeconst 0.002 runs as 2 dt), the direct (-stiffness, -damping) form
TEXTBOOK = ((0.02, 1.0), (0.01, 0.5), (0.002, 1.0), (-4000.0, -15.0))


def _solrefs(dt, solimp, gravity, i):
    """The continuous designs for e = 0.1 (0.2) ... 0.7, and 0.9 below dt = 0.001 (at
    coarser steps that design is near the stability limit: MuJoCo's e exceeds 1), and
    one textbook solref (cycled with ``i``)."""
    targets = 5 if dt < 0.001 else 4
    return [(0.02, dr) for dr in CONTINUOUS[solimp, gravity][:targets]] + [
        TEXTBOOK[i % len(TEXTBOOK)]
    ]


COMBOS = list(itertools.product(INTEGRATORS, TIMESTEPS, (FLAT, DEFAULT), (0.0, 9.81)))


def engine(solref, solimp, gravity, dt, integrator, phases, speed=1.0):
    return mujoco_phases(
        solref=solref,
        solimp=solimp,
        speed=speed,
        gravity=gravity,
        timestep=dt,
        integrator=integrator,
        phases=phases,
        max_steps=MAX_STEPS,
    )


def model(solref, solimp, gravity, dt, integrator, phase, speed=1.0):
    return predict(
        solref=solref,
        solimp=solimp,
        speed=speed,
        gravity=gravity,
        mass=1.0,
        timestep=dt,
        integrator=integrator,
        phase=phase,
    )


def assert_per_phase(p, mj, rtol, where):
    """Predicted (per phase) against MuJoCo: the stick verdict, then e and t_c."""
    sticks = np.asarray(p.sticks)
    np.testing.assert_array_equal(sticks, mj["sticks"], err_msg=f"stick verdict, {where}")
    e, t = (
        np.broadcast_to(p.restitution, sticks.shape),
        np.broadcast_to(p.contact_time, sticks.shape),
    )
    assert np.all(e[sticks] == 0.0), where
    assert np.all(np.isinf(t[sticks])), where
    go = ~sticks
    np.testing.assert_allclose(e[go], mj["restitution"][go], rtol=rtol, err_msg=where)
    np.testing.assert_allclose(t[go], mj["contact_time"][go], rtol=rtol, err_msg=where)


@pytest.mark.parametrize(("integrator", "dt", "solimp", "gravity"), COMBOS)
def test_each_phase_is_mujocos(integrator, dt, solimp, gravity):
    for solref in _solrefs(dt, solimp, gravity, COMBOS.index((integrator, dt, solimp, gravity))):
        mj = engine(solref, solimp, gravity, dt, integrator, PHASES)
        p = model(solref, solimp, gravity, dt, integrator, PHASES)
        assert_per_phase(p, mj, RTOL[solimp], f"{integrator} dt={dt} solref={solref}")


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize(("gravity", "solimp"), [(0.0, FLAT), (9.81, DEFAULT), (9.81, FLAT)])
def test_phase_zero_is_mujocos_phase_zero(integrator, gravity, solimp):
    # touch exactly at an engine state: MuJoCo keeps a contact at distance 0 out of its
    # constraints (mj_setContact excludes dist >= 0), so for Euler and implicitfast the
    # first detecting state is the next one
    for solref in ((0.02, 0.3), (0.01, 0.6)):
        for dt in (0.002, 0.0005):
            mj = engine(solref, solimp, gravity, dt, integrator, [0.0])
            p = model(solref, solimp, gravity, dt, integrator, np.array([0.0]))
            assert_per_phase(p, mj, RTOL[solimp], f"phase 0, {integrator} dt={dt} {solref}")


STICKY = [
    # (solref, solimp, speed, dt): under gravity at low speed, and a design whose force
    # comes back inside the overlap at some phases
    ((0.02, 1.0), FLAT, 0.05, 0.002),
    ((0.02, 0.3), DEFAULT, 0.05, 0.001),
    ((0.02, 0.6), FLAT, 0.1, 0.0005),
    ((0.02, CONTINUOUS[FLAT, 9.81][0]), FLAT, 1.0, 0.002),
    ((0.02, CONTINUOUS[DEFAULT, 9.81][0]), DEFAULT, 1.0, 0.001),
]


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize(("solref", "solimp", "speed", "dt"), STICKY)
def test_stick_verdict_under_gravity(integrator, solref, solimp, speed, dt):
    phases = np.array([0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95])
    mj = engine(solref, solimp, 9.81, dt, integrator, phases, speed=speed)
    p = model(solref, solimp, 9.81, dt, integrator, phases, speed=speed)
    assert_per_phase(p, mj, RTOL[solimp], f"{integrator} dt={dt} {solref} v={speed}")


def test_the_stick_cases_stick():
    # not vacuous: MuJoCo sticks in the first case at every phase, and in the Euler run
    # of the design at some phases only
    solref, solimp, speed, dt = STICKY[0]
    assert engine(solref, solimp, 9.81, dt, "euler", PHASES, speed=speed)["sticks"].all()
    solref, solimp, speed, dt = STICKY[3]
    sticks = engine(solref, solimp, 9.81, dt, "euler", GRID[::8], speed=speed)["sticks"]
    assert sticks.any()
    assert not sticks.all()


MEANS = [
    ("euler", 0.002, FLAT, 0.0, (0.02, CONTINUOUS[FLAT, 0.0][2])),
    ("euler", 0.002, DEFAULT, 9.81, (0.02, CONTINUOUS[DEFAULT, 9.81][1])),
    ("implicitfast", 0.001, DEFAULT, 9.81, (0.02, CONTINUOUS[DEFAULT, 9.81][3])),
    ("rk4", 0.002, FLAT, 9.81, (0.02, CONTINUOUS[FLAT, 9.81][2])),
    ("rk4", 0.0005, DEFAULT, 0.0, (0.02, CONTINUOUS[DEFAULT, 0.0][4])),
    ("euler", 0.0005, FLAT, 9.81, (0.01, 0.5)),
]


def quadrature_error(values: np.ndarray) -> float:
    """Error bound of the midpoint mean of a piecewise smooth periodic sample.

    A cell's error is at most the function's oscillation over the cell over N; summed
    over cells that is the variation over N, estimated by the sampled variation (jumps
    included), doubled for safety.
    """
    variation = np.abs(np.diff(np.append(values, values[0]))).sum()
    return 2.0 * variation / values.size


def assert_in_range(values, lo, hi, rtol, what):
    slack = rtol * np.abs(values) + 1e-15
    assert np.all(values >= lo - slack), f"{what}: {values.min()!r} below range {lo!r}"
    assert np.all(values <= hi + slack), f"{what}: {values.max()!r} above range {hi!r}"
    # not vacuous: the sampled extremes come within one grid step of the range's ends
    step = np.abs(np.diff(np.append(values, values[0]))).max()
    assert lo >= values.min() - step - slack.max(), f"{what}: range starts too low"
    assert hi <= values.max() + step + slack.max(), f"{what}: range ends too high"


@pytest.mark.parametrize(("integrator", "dt", "solimp", "gravity", "solref"), MEANS)
def test_phase_mean_and_range(integrator, dt, solimp, gravity, solref):
    mj = engine(solref, solimp, gravity, dt, integrator, GRID)
    assert not mj["sticks"].any()
    p = model(solref, solimp, gravity, dt, integrator, None)
    rtol = RTOL[solimp]
    for name, values in (("restitution", mj["restitution"]), ("contact_time", mj["contact_time"])):
        lo, hi = (float(v) for v in getattr(p, f"{name}_range"))
        assert_in_range(values, lo, hi, rtol, name)
        mean = float(getattr(p, name))
        assert abs(values.mean() - mean) <= quadrature_error(values) + rtol * abs(mean), name


DESIGNS = [
    # (integrator, solimp, gravity, target e, target contact time or None)
    ("euler", FLAT, 0.0, 0.5, None),
    ("euler", DEFAULT, 9.81, 0.3, None),
    ("implicitfast", FLAT, 9.81, 0.7, None),
    ("rk4", DEFAULT, 0.0, 0.5, None),
    ("rk4", FLAT, 9.81, 0.2, None),
    ("euler", FLAT, 0.0, 0.3, 0.03),
]


@pytest.mark.parametrize(("integrator", "solimp", "gravity", "target", "t_c"), DESIGNS)
def test_design_at_the_default_timestep_delivers_the_phase_mean(
    integrator, solimp, gravity, target, t_c
):
    dt = 0.002
    design = solref_for(
        restitution=target,
        speed=1.0,
        gravity=gravity,
        contact_time=t_c,
        solimp=solimp,
        timestep=dt,
        integrator=integrator,
    )
    solref = tuple(float(v) for v in design.solref)
    assert float(design.restitution) == pytest.approx(target, rel=1e-4)
    mj = engine(solref, solimp, gravity, dt, integrator, GRID)
    assert not mj["sticks"].any()
    e = mj["restitution"]
    assert e.mean() == pytest.approx(target, rel=5e-3)
    lo, hi = (float(v) for v in design.prediction.restitution_range)
    assert_in_range(e, lo, hi, RTOL[solimp], "restitution")
    if t_c is not None:
        assert mj["contact_time"].mean() == pytest.approx(t_c, rel=5e-3)
        lo, hi = (float(v) for v in design.prediction.contact_time_range)
        assert_in_range(mj["contact_time"], lo, hi, RTOL[solimp], "contact_time")
