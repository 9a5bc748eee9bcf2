"""impact() on every law against an independent integration of the physical equation.

The reference integrates ``m d'' = F - F_law(d, d')`` in physical units with SciPy's
``solve_ivp`` (DOP853, ``rtol = 1e-13``) and terminal events, the laws written out here by
hand (no normalization, nothing from the package): contact time, restitution, maximum
penetration (event ``d' = 0``) and peak force (the dense output maximized) agree to 1e-10.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from impactsym.contact import impact, physical_contact

M, V0, P = 0.5, 1.5, 1.5
K = {"linear": 2000.0, "hertz-linear": 2000.0, "hunt-crossley": 2000.0, "tsuji": 2000.0,
     "viscoelastic": 2000.0}  # fmt: skip


def law_force(law: str, d, v, c: float, k: float):
    d = np.maximum(d, 0.0)
    if law == "linear":
        return k * d + c * v
    if law == "hertz-linear":
        return k * d**P + c * v
    if law == "hunt-crossley":
        return k * d**P * (1.0 + c * v)
    if law == "tsuji":
        return k * d**P + c * np.sqrt(M * k) * d ** ((P - 1) / 2) * v
    return k * (d**1.5 + 1.5 * c * np.sqrt(d) * v)


def force_sign(law: str, d: float, v: float, c: float, k: float) -> float:
    """A function with the sign of the contact force for d > 0, smooth at d = 0."""
    d = max(d, 0.0)
    return {
        "linear": k * d + c * v,
        "hertz-linear": k * d**P + c * v,
        "hunt-crossley": 1.0 + c * v,
        "tsuji": c * np.sqrt(M * k) * v + k * d ** ((P + 1) / 2),
        "viscoelastic": d + 1.5 * c * v,
    }[law]


def reference(law: str, c: float, F: float, condition: str, t_end: float) -> tuple:
    k = K[law]

    def rhs(t, y):
        return [y[1], (F - law_force(law, y[0], y[1], c, k)) / M]

    def out(t, y):
        return y[0]

    def released(t, y):
        return force_sign(law, y[0], y[1], c, k)

    def top(t, y):
        return y[1]

    out.terminal, out.direction = True, -1
    released.terminal, released.direction = True, -1
    top.direction = -1
    events = [out, top] + ([released] if condition == "force" else [])
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, V0], method="DOP853", rtol=1e-13, atol=1e-18,
                    events=events, dense_output=True)  # fmt: skip
    ended = sol.status == 1
    t_c = sol.t[-1] if ended else np.inf
    e = -sol.y[1, -1] / V0 if ended else 0.0
    d_max = sol.y_events[1][0][0] if len(sol.t_events[1]) else np.max(sol.y[0])
    grid = np.linspace(0.0, sol.t[-1], 40001)
    force = law_force(law, *sol.sol(grid), c, k)
    i = int(np.argmax(force))
    peak = force[i]
    if 0 < i < grid.size - 1:
        best = minimize_scalar(
            lambda t: -float(law_force(law, *sol.sol(t), c, k)),
            bounds=(grid[i - 1], grid[i + 1]),
            method="bounded",
            options={"xatol": 1e-15},
        )
        peak = max(peak, -best.fun)
    return t_c, e, d_max, peak


#: (law, damping parameters, pressing forces): releases and sticks, both conditions
CASES = [
    ("linear", (10.0, 40.0), (0.0, 5.0)),
    ("hertz-linear", (3.0, 12.0), (0.0, 5.0)),
    ("hunt-crossley", (0.3, 1.0), (0.0, 5.0)),
    ("tsuji", (0.3, 1.2), (0.0, 5.0)),
    ("viscoelastic", (0.005, 0.02), (0.0, 5.0)),
]


@pytest.mark.parametrize("condition", ["position", "force"])
@pytest.mark.parametrize(("law", "dampings", "forces"), CASES)
def test_impact_agrees_with_an_independent_integration(law, dampings, forces, condition):
    c = np.array(dampings)[:, None]
    F = np.array(forces)[None, :]
    r = impact(law, stiffness=K[law], damping=c, mass=M, speed=V0, force=F, exponent=P,
               condition=condition)  # fmt: skip
    assert r.restitution.shape == (2, 2)
    for i in range(2):
        for j in range(2):
            T = float(r.time_scale[i, j])
            t_c, e, d_max, peak = reference(law, c[i, 0], F[0, j], condition, 60.0 * T)
            assert np.isinf(r.contact_time[i, j]) == np.isinf(t_c)
            if np.isfinite(t_c):
                assert r.contact_time[i, j] == pytest.approx(t_c, rel=1e-10)
            assert r.restitution[i, j] == pytest.approx(e, abs=1e-10)
            assert r.max_penetration[i, j] == pytest.approx(d_max, rel=1e-10)
            expected = max(peak, F[0, j] * r.sticks[i, j])  # a sticking body ends at force F
            assert r.peak_force[i, j] == pytest.approx(expected, rel=1e-10)


def test_a_pressing_force_makes_some_cases_stick():
    r = impact("tsuji", stiffness=2000.0, damping=1.2, mass=M, speed=0.2, force=30.0,
               condition="force")  # fmt: skip
    assert r.sticks
    assert r.contact_time == np.inf
    assert r.restitution == 0.0


def test_the_linear_law_is_the_linear_contact_bit_for_bit():
    c = np.array([0.0, 5.0, 63.0, 200.0, 1e4])[:, None]
    F = np.array([0.0, 1.0, 30.0])
    for condition in ("position", "force"):
        r = impact("linear", stiffness=1e3, damping=c, mass=1.0, speed=0.7, force=F,
                   exponent=3.0, condition=condition)  # fmt: skip
        ref = physical_contact(1.0, 1e3, c, 0.7, F, condition=condition)
        np.testing.assert_array_equal(r.restitution, ref.restitution)
        np.testing.assert_array_equal(r.contact_time, ref.contact_time)
        np.testing.assert_array_equal(r.sticks, ref.sticks)
        np.testing.assert_array_equal(r.damping_number, ref.D)
        np.testing.assert_array_equal(r.pressing_number, ref.f)


def test_undamped_hertz_contact_time_and_penetration():
    """Elastic Hertz: d_max = (5 m v0^2 / (4 k))^(2/5), t_c = 2.9432 d_max / v0."""
    m, k, v0 = 0.3, 5e5, 0.8
    d_max = (5.0 * m * v0**2 / (4.0 * k)) ** 0.4
    for law in ("hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"):
        r = impact(law, stiffness=k, damping=0.0, mass=m, speed=v0, condition="position")
        assert r.restitution == pytest.approx(1.0, abs=1e-12)
        assert r.max_penetration == pytest.approx(d_max, rel=1e-12)
        assert r.peak_force == pytest.approx(k * d_max**1.5, rel=1e-12)
        assert r.contact_time * v0 / d_max == pytest.approx(2.9432, abs=1e-4)


def test_exponent_is_ignored_where_the_law_has_none():
    for law in ("linear", "viscoelastic"):
        a = impact(law, stiffness=1e4, damping=0.01, mass=1.0, speed=1.0, exponent=1.0,
                   condition="force")  # fmt: skip
        b = impact(law, stiffness=1e4, damping=0.01, mass=1.0, speed=1.0, exponent=2.5,
                   condition="force")  # fmt: skip
        assert a == b


def test_the_clipped_linear_law_is_the_lammps_limit_damping_contact():
    """LAMMPS's continuous Hooke contact with limit_damping and gravity: the body leaves
    the overlap with departure_speed, or sticks in the coast's band."""
    from impactsym.engines.lammps import predict

    kn, m, v, g = 1e5, 0.02, 0.3, 29.43
    eta = np.array([0.0, 1.0, 5.0, 20.0, 40.0, 60.0, 80.0, 120.0, 300.0])
    r = impact("linear", stiffness=kn, damping=eta, mass=m, speed=v, force=m * g,
               condition="clipped")  # fmt: skip
    ref = predict(kn=kn, damping=eta, mass=m, speed=v, gravity=g, limit_damping=True)
    np.testing.assert_array_equal(r.sticks, ref.sticks)
    assert r.sticks[-3:].all()
    assert not r.sticks[:-3].any()
    np.testing.assert_allclose(r.restitution, ref.departure_speed / v, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.max_penetration, ref.max_penetration, rtol=1e-12)
    np.testing.assert_allclose(r.peak_force, ref.peak_force, rtol=1e-12)
    # contact time: LAMMPS's force zero, then the coast 2 D e - e s + b s^2 / 2 to z = 0
    D, b = r.damping_number, m * g / np.sqrt(kn * m) / v
    e = ref.restitution
    with np.errstate(all="ignore"):
        s = (e - np.sqrt(e * e - 4 * D * b * e)) / b
    t_ref = ref.contact_time + s / np.sqrt(kn / m)
    free = ~r.sticks
    np.testing.assert_allclose(r.contact_time[free], t_ref[free], rtol=1e-12)


@pytest.mark.parametrize("law", ["hertz-linear", "tsuji", "viscoelastic", "hunt-crossley"])
def test_clipped_without_pressing_force_is_the_force_release_then_a_free_coast(law):
    kw = {"stiffness": K[law], "damping": 0.4, "mass": M, "speed": V0}
    if law == "hertz-linear":
        kw["damping"] = 10.0
    force = impact(law, condition="force", **kw)
    clipped = impact(law, condition="clipped", **kw)
    assert clipped.restitution == pytest.approx(force.restitution, rel=1e-10)
    assert clipped.max_penetration == force.max_penetration
    assert clipped.peak_force == force.peak_force
    if law == "hunt-crossley":  # its force vanishes only with the overlap
        assert clipped.contact_time == pytest.approx(force.contact_time, rel=1e-10)
    else:
        assert clipped.contact_time > force.contact_time


def test_clipped_impact_in_physical_units_against_solve_ivp():
    """Tsuji under a pressing force: coast inside the overlap, then out; the reference
    switches the force off and on by terminal events (physical units)."""
    k, c, F = K["tsuji"], 0.5, 1.0

    def contact(t, y):
        return [y[1], (F - law_force("tsuji", y[0], y[1], c, k)) / M]

    def sign(t, y):
        return force_sign("tsuji", y[0], y[1], c, k)

    def out(t, y):
        return y[0] if t > 1e-12 else 1.0

    sign.terminal = out.terminal = True
    sign.direction = out.direction = -1
    opts = {"method": "DOP853", "rtol": 1e-13, "atol": 1e-16}
    first = solve_ivp(contact, (0, 1), [0.0, V0], events=[out, sign], **opts)
    assert first.t_events[1].size  # the force vanished inside the overlap
    t1, y1 = first.t_events[1][0], first.y_events[1][0]
    flight = solve_ivp(lambda t, y: [y[1], F / M], (t1, 1), y1, events=[out], **opts)
    r = impact("tsuji", stiffness=k, damping=c, mass=M, speed=V0, force=F, condition="clipped")
    assert r.contact_time == pytest.approx(flight.t_events[0][0], rel=1e-10)
    assert r.restitution == pytest.approx(-flight.y_events[0][0][1] / V0, rel=1e-10)
