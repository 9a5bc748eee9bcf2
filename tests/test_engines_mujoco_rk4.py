"""MuJoCo's RK4 as an exact discrete model (impactsym.engines.mujoco.rk4) against MuJoCo
itself stepping at its own timestep (drivers.mujoco_steps), against a plain stage-by-stage
recurrence written here, and the SymPy derivation of its interior step."""

from __future__ import annotations

import os

import numpy as np
import pytest
import sympy as sp

from impactsym.engines.derivation import mujoco_rk4_step
from impactsym.engines.mujoco.model import Coefficients, check_solimp, coefficients, impedance_at
from impactsym.engines.mujoco.rk4 import rk4_contact, rk4_spectral_radius

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)
#: solrefs for restitution from about 0.9 down to 0.13 (flat, no gravity), all with
#: omega0 dt below RK4's stability limit 2 sqrt(2) at dt = 0.002
SOLREFS = ((0.05, 0.035), (0.02, 0.1), (0.02, 0.25), (0.02, 0.6), (0.02, 1.0))
PHASES = (0.05, 0.45, 0.7, 0.95)


def _plain(solref, solimp, speed, gravity, timestep, phase, *, inside=False, max_steps=100_000):
    """One contact by MuJoCo's RK4 stage by stage in plain Python floats (the reference).

    Starts from free flight one step before the first detecting state, as the touch-phase
    definitions say, or (``inside=True``) at the first detecting state itself. Returns
    ``(restitution, contact_time, steps, departure_speed)``: the force zero or contact loss,
    then the coast through the overlap until the contact is gone (``departure_speed``,
    ``nan`` where the force comes back).
    """
    si = check_solimp(solimp)
    c = coefficients(solref, si, timestep)
    b, kbar, g, h = float(c.damping), float(c.stiffness), gravity, timestep

    def accel(x, v):
        d = float(impedance_at(np.abs(np.asarray(x)), si))
        drive = g + b * v + d * kbar * x
        return (g - d * drive if x >= 0 and drive > 0 else g), drive

    t = phase * h if inside else (phase - 1.0) * h
    x, v = speed * t + 0.5 * g * t * t, speed + g * t
    touched, steps, end = False, 0, None
    for _ in range(max_steps):
        a0, drive = accel(x, v)
        touched |= x >= 0
        if end is not None and (x < 0 or drive > 0):
            return (*end, -v if x < 0 else np.nan)
        if end is None and touched and (x < 0 or drive <= 0):
            end = (-v / speed, t, steps)
            continue
        steps += touched and end is None
        x1, v1 = x + 0.5 * h * v, v + 0.5 * h * a0
        a1 = accel(x1, v1)[0]
        x2, v2 = x + 0.5 * h * v1, v + 0.5 * h * a1
        a2 = accel(x2, v2)[0]
        x3, v3 = x + h * v2, v + h * a2
        a3 = accel(x3, v3)[0]
        x, v = (
            x + h * (v / 6 + v1 / 3 + v2 / 3 + v3 / 6),
            v + h * (a0 / 6 + a1 / 3 + a2 / 3 + a3 / 6),
        )
        t += h
    return 0.0, np.inf, -1, np.nan


def _model(solref, solimp, speed, gravity, timestep, phase):
    si = check_solimp(solimp)
    return rk4_contact(coefficients(solref, si, timestep), si, 1.0, gravity, speed, timestep, phase)


# -- the derivation ---------------------------------------------------------------------


def test_interior_step_matrix_is_the_taylor_polynomial_of_the_exponential():
    r = mujoco_rk4_step()
    assert sp.simplify(r["matrix"] - r["taylor"]) == sp.zeros(2, 2)
    # the static penetration is the map's fixed point
    assert sp.simplify(r["matrix"] * r["equilibrium"] + r["offset"] - r["equilibrium"]) == sp.zeros(
        2, 1
    )
    # undamped: |P(i y)| <= 1 exactly up to y = omega0 h = 2 sqrt(2)
    y = sp.Symbol("y", positive=True)
    mod2 = r["undamped_modulus2"]
    assert sp.simplify(mod2.subs(y, 2 * sp.sqrt(2))) == 1
    assert mod2.subs(y, 2.8) < 1 < mod2.subs(y, 2.9)


def test_spectral_radius_is_the_modulus_of_p_at_the_eigenvalues():
    r = mujoco_rk4_step()
    h, b, d, kbar, dp = sp.symbols("h b d kbar d_eff", positive=True)
    values = {h: 0.002, b: 2 / (0.9 * 0.02), d: 0.9, kbar: 1 / (0.81 * 0.02**2 * 0.25**2), dp: 0.9}
    m = np.array(r["matrix"].subs(values).evalf(), dtype=float)
    mu = [complex(e.subs(values).evalf()) for e in r["eigenvalues"]]
    assert np.allclose(sorted(np.abs(np.linalg.eigvals(m))), sorted(np.abs(mu)), rtol=1e-12)


def test_spectral_radius_crosses_one_at_the_undamped_limit():
    # undamped, flat: omega0 h = 2 sqrt(2) is the limit the derivation gives
    si = check_solimp(FLAT)
    h = 0.002
    y = np.array([2.8, 2 * np.sqrt(2) - 1e-6, 2 * np.sqrt(2) + 1e-6, 2.9])
    c = Coefficients(np.zeros(4), (y / h) ** 2 / 0.81)
    radius = rk4_spectral_radius(c, si, 1.0, h)
    np.testing.assert_allclose(radius, np.sqrt(1 - y**6 / 72 + y**8 / 576), rtol=1e-12)
    assert list(radius < 1) == [True, True, False, False]


# -- the model against a plain recurrence ----------------------------------------------


@pytest.mark.parametrize(
    ("dampratio", "gravity"), [(0.1, 0.0), (0.5, 0.0), (2.0, 0.0), (0.1, 9.81), (0.5, 9.81)]
)
def test_closed_form_interior_equals_the_plain_recurrence_over_long_contacts(dampratio, gravity):
    # at dt = 5e-5 a contact lasts hundreds of steps: the model jumps through its interior
    # by the closed form, the reference steps through every stage
    for phase in (0.2, 0.8):
        e, t_c, steps, departure = _plain((0.02, dampratio), FLAT, 2.0, gravity, 5e-5, phase)
        r = _model((0.02, dampratio), FLAT, 2.0, gravity, 5e-5, phase)
        assert steps > 100
        assert int(r.steps) == steps
        assert float(r.restitution) == pytest.approx(e, rel=1e-9)
        assert float(r.contact_time) == pytest.approx(t_c, rel=1e-12)
        assert float(r.departure_speed) == pytest.approx(departure, rel=1e-9)


def test_arrays_broadcast_and_scalars_give_floats():
    si = check_solimp(FLAT)
    c = coefficients((0.02, np.array([[0.1], [0.5]])), si, 0.002)
    r = rk4_contact(c, si, 1.0, 9.81, 1.0, 0.002, np.array([0.1, 0.6, 0.9]))
    assert r.restitution.shape == (2, 3)
    assert r.steps.dtype.kind == "i"
    one = _model((0.02, 0.5), FLAT, 1.0, 9.81, 0.002, 0.6)
    assert isinstance(one.restitution, float)
    assert one.restitution == r.restitution[1, 1]


def test_entering_step_matters_starting_inside_differs_by_5_to_30_percent():
    # the step that carries the body in feels the contact in its later stages; a model
    # that starts the body at the first detecting state misses that (phase mean at 0.002)
    for dampratio in (0.1, 0.25, 0.5, 1.0):
        diffs = []
        for phase in np.linspace(0.05, 0.95, 10):
            inside = _plain((0.02, dampratio), FLAT, 1.0, 0.0, 0.002, phase, inside=True)[0]
            stepped = _model((0.02, dampratio), FLAT, 1.0, 0.0, 0.002, phase).restitution
            assert stepped == pytest.approx(
                _plain((0.02, dampratio), FLAT, 1.0, 0.0, 0.002, phase)[0], rel=1e-12
            )
            diffs.append(abs(inside - stepped) / stepped)
        assert 0.05 <= np.mean(diffs) <= 0.30


# -- the model against MuJoCo ------------------------------------------------------------

if os.environ.get("CI") == "true":
    import mujoco  # CI installs the [engines] extra: a missing engine fails

    HAVE_MUJOCO = True
else:
    try:
        import mujoco  # noqa: F401

        HAVE_MUJOCO = True
    except ImportError:
        HAVE_MUJOCO = False

engine = pytest.mark.skipif(not HAVE_MUJOCO, reason="needs MuJoCo")


def _agree(solref, solimp, speed, gravity, timestep, rtol, max_steps=100_000):
    from impactsym.engines.drivers import mujoco_steps

    model = _model(solref, solimp, speed, gravity, timestep, np.array(PHASES))
    for i, phase in enumerate(PHASES):
        run = mujoco_steps(
            solref=solref,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=timestep,
            integrator="rk4",
            phase=phase,
            max_steps=max_steps,
        )
        case = (solref, solimp, speed, gravity, timestep, phase)
        assert bool(model.sticks[i]) == run["sticks"], case
        if run["sticks"]:
            continue
        assert int(model.steps[i]) == run["steps"], case
        assert bool(model.released_by_position[i]) == run["released_by_position"], case
        assert model.restitution[i] == pytest.approx(run["restitution"], rel=rtol), case
        assert model.contact_time[i] == pytest.approx(run["contact_time"], rel=rtol), case
        assert model.departure_speed[i] == pytest.approx(run["departure_speed"], rel=rtol), case
        assert model.max_penetration[i] == pytest.approx(run["max_penetration"], rel=rtol), case
        assert model.peak_accel[i] == pytest.approx(run["peak_force"], rel=rtol), case


@engine
@pytest.mark.parametrize("timestep", [0.002, 0.001, 0.0005])
@pytest.mark.parametrize("solref", SOLREFS)
def test_flat_impedance_agrees_with_mujoco_per_phase(solref, timestep):
    _agree(solref, FLAT, 1.0, 0.0, timestep, 1e-9)
    _agree(solref, FLAT, 2.0, 9.81, timestep, 1e-9, max_steps=3000)


@engine
@pytest.mark.parametrize("timestep", [0.002, 0.001, 0.0005])
@pytest.mark.parametrize("solref", SOLREFS)
def test_default_solimp_agrees_with_mujoco_per_phase(solref, timestep):
    _agree(solref, DEFAULT, 1.0, 0.0, timestep, 1e-6)
    _agree(solref, DEFAULT, 2.0, 9.81, timestep, 1e-6, max_steps=3000)


@engine
def test_stick_verdicts_agree_with_mujoco():
    from impactsym.engines.drivers import mujoco_steps

    # (solref, solimp, speed): the force comes back inside the overlap, or never ends
    cases = [
        ((0.02, 0.5372), FLAT, 0.691, 0.45),
        ((0.02, 1.0), FLAT, 1.0, 0.7),
        ((0.02, 1.0), DEFAULT, 1.0, 0.3),
        ((0.02, 0.25), FLAT, 1.0, 0.3),  # bounces
    ]
    verdicts = []
    for solref, solimp, speed, phase in cases:
        model = _model(solref, solimp, speed, 9.81, 0.002, phase)
        run = mujoco_steps(
            solref=solref,
            solimp=solimp,
            speed=speed,
            gravity=9.81,
            timestep=0.002,
            integrator="rk4",
            phase=phase,
            max_steps=5000,
        )
        assert bool(model.sticks) == run["sticks"], (solref, solimp, speed, phase)
        verdicts.append((bool(model.sticks), int(model.steps)))
    came_back, never, _, bounce = verdicts
    assert came_back[0]
    assert came_back[1] >= 0  # ended by a force zero, then re-engaged
    assert never == (True, -1)
    assert verdicts[2][0]
    assert not bounce[0]
