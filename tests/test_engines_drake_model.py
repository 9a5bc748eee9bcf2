"""Drake point contact without Drake: the update against its SymPy derivation and a root
finder, the phase statistics against dense sampling, the continuous law against
solve_ivp, and the designs against the predictions."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from impactsym.contact.nonlinear import impact
from impactsym.engines.drake import combine, point_contact_for, predict
from impactsym.engines.drake import derivation as drv
from impactsym.engines.drake.continuous import S_MAX, hunt_crossley_free
from impactsym.engines.drake.stepping import step_contact
from impactsym.engines.drake.update import hunt_crossley_velocity, sap_velocity

RNG = np.random.default_rng(20)


def test_derivation_stable_root_is_the_larger_root_and_the_continuous_law():
    assert drv.hunt_crossley_residual() == 0
    assert (
        sp.simplify(drv.continuous_limit() - (drv.g - drv.k * drv.x * (1 + drv.d * drv.u) / drv.m))
        == 0
    )


def test_update_is_the_derived_root_and_solves_the_clipped_balance():
    n = 40
    x = RNG.uniform(0.0, 1e-2, n)
    u = RNG.uniform(-1.0, 2.0, n)
    k, d = 10 ** RNG.uniform(3, 6, n), RNG.uniform(0.0, 3.0, n)
    m, g, h = RNG.uniform(0.1, 2.0, n), RNG.uniform(0.0, 10.0, n), 10 ** RNG.uniform(-5, -2, n)
    new, impulse = hunt_crossley_velocity(x, u, k, d, m, g, h)
    root = sp.lambdify((drv.x, drv.u, drv.k, drv.d, drv.m, drv.g, drv.h), drv.hunt_crossley_root())
    for i in range(n):

        def balance(w, i=i):
            force = h[i] * k[i] * max(x[i] + h[i] * w, 0.0) * max(1.0 + d[i] * w, 0.0)
            return m[i] * (w - u[i] - h[i] * g[i]) + force

        ref = brentq(balance, -10.0, 10.0, xtol=1e-15, rtol=1e-15)
        assert abs(new[i] - ref) <= 1e-12 * max(1.0, abs(ref))
        if impulse[i] > 0 and d[i] > 0:
            assert abs(new[i] - root(x[i], u[i], k[i], d[i], m[i], g[i], h[i])) < 1e-12
        assert impulse[i] == pytest.approx(m[i] * (u[i] + h[i] * g[i] - new[i]), abs=1e-15)
    # sap: the linear root of the derivation, where the impulse is positive
    tau = RNG.uniform(1e-3, 0.3, n)
    new, impulse = sap_velocity(x, u, k, tau, m, g, h)
    rn = np.maximum(1.0 / (4 * np.pi**2) / m, 1.0 / (h * k * (h + tau)))
    lin = sp.lambdify((drv.x, drv.u, drv.tau, drv.m, drv.g, drv.h, drv.R), drv.sap_root())
    pos = impulse > 0
    np.testing.assert_allclose(new[pos], lin(x, u, tau, m, g, h, rn)[pos], rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(new[~pos], (u + h * g)[~pos])


@pytest.mark.parametrize(
    ("approximation", "gravity", "dissipation"),
    [("lagged", 0.0, 0.5), ("lagged", 9.81, 2.0), ("sap", 0.0, 0.0), ("sap", 9.81, 0.0)],
)
def test_phase_mean_and_range_match_dense_sampling(approximation, gravity, dissipation):
    k, m, v, h, tau = 2e4, 1.0, 0.6, 1e-3, 0.003
    p = predict(stiffness=k, dissipation=dissipation, mass=m, speed=v, gravity=gravity,
                time_step=h, approximation=approximation, relaxation_time=tau)  # fmt: skip
    phases = (np.arange(40000) + 0.5) / 40000
    s = step_contact(k, dissipation, tau, m, gravity, v, h, phases, approximation=approximation)
    # midpoint sampling misses each jump (0.02 in e, one step in t) by up to 1/40000
    assert abs(p.restitution - s.restitution.mean()) < 1e-6
    assert abs(p.contact_time - s.contact_time.mean()) < 5e-8
    lo, hi = p.restitution_range
    assert lo <= s.restitution.min() + 1e-12
    assert s.restitution.max() <= hi + 1e-12
    assert s.restitution.min() - lo < 1e-4
    assert hi - s.restitution.max() < 1e-4


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_continuous_prediction_is_the_clipped_law_integrated(gravity):
    k, d, m, v = 5e4, 0.8, 0.3, 0.7
    p = predict(stiffness=k, dissipation=d, mass=m, speed=v, gravity=gravity)

    def rhs(t, y):
        return [y[1], gravity - k * y[0] * max(0.0, 1.0 + d * y[1]) / m]

    def out(t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, [0, 1], [0.0, v], method="DOP853", rtol=1e-13, atol=1e-16,
                    events=out, dense_output=True)  # fmt: skip
    assert abs(p.restitution + sol.y_events[0][0][1] / v) < 1e-10
    assert abs(p.contact_time / sol.t_events[0][0] - 1.0) < 1e-10


def test_phase_plane_quadrature_is_the_integrated_law():
    # every s in [0, S_MAX], against the order-8 integration of impact()
    s = np.concatenate([[0.0, 1e-9, 1e-4], np.linspace(0.01, S_MAX, 60)])
    e, tau, z_max = hunt_crossley_free(s)
    r = impact("hunt-crossley", stiffness=1.0, damping=s, mass=1.0, speed=1.0, exponent=1.0,
               condition="position")  # fmt: skip
    np.testing.assert_allclose(e, r.restitution, rtol=0, atol=1e-14)
    np.testing.assert_allclose(tau, r.contact_time, rtol=1e-12)
    np.testing.assert_allclose(z_max, r.max_penetration, rtol=1e-12)
    # and predict uses it without gravity, the integration beyond S_MAX: one law
    p = predict(stiffness=4e4, dissipation=[1.0, 5.0], mass=0.2, speed=1.0)
    q = impact("hunt-crossley", stiffness=4e4, damping=[1.0, 5.0], mass=0.2, speed=1.0,
               exponent=1.0, condition="position")  # fmt: skip
    np.testing.assert_allclose(p.contact_time, q.contact_time, rtol=1e-12)


def test_approximations_tamsi_similar_lagged_agree_and_phase_zero_detects():
    base = {"stiffness": 1e4, "dissipation": 0.5, "mass": 1.0, "speed": 1.0, "time_step": 1e-3}
    res = [predict(approximation=a, phase=[0.0, 0.4], **base) for a in ("tamsi", "similar",
                                                                         "lagged")]  # fmt: skip
    for r in res[1:]:
        np.testing.assert_array_equal(r.restitution, res[0].restitution)
    # phase 0: the state at touch already carries the contact (x = 0 is reported)
    assert res[0].contact_time[0] == pytest.approx(round(res[0].contact_time[0] / 1e-3) * 1e-3)


def test_combine_is_series_and_stiffness_weighted():
    k, d = combine(stiffness_a=[2e4, 1e4], dissipation_a=[0.5, 0.2], stiffness_b=[2e4, 3e4],
                   dissipation_b=[1.5, 1.0])  # fmt: skip
    np.testing.assert_allclose(k, [1e4, 7500.0])
    np.testing.assert_allclose(d, [1.0, (3e4 * 0.2 + 1e4 * 1.0) / 4e4])


@pytest.mark.parametrize(
    ("time_step", "approximation", "gravity", "size"),
    [(0.0, None, 0.0, "contact_time"), (0.0, None, 0.0, "max_penetration"),
     (1e-3, "similar", 0.0, "contact_time"), (1e-3, "sap", 9.81, "contact_time")],
)  # fmt: skip
def test_designs_deliver_their_targets(time_step, approximation, gravity, size):
    e = np.array([0.35, 0.7])
    target = np.array([0.03, 0.02]) if size == "contact_time" else np.array([0.01, 0.005])
    c = point_contact_for(restitution=e, speed=1.0, mass=0.5, gravity=gravity,
                          time_step=time_step, approximation=approximation,
                          **{size: target})  # fmt: skip
    np.testing.assert_allclose(c.restitution, e, atol=1e-9)
    np.testing.assert_allclose(getattr(c, size), target, rtol=1e-9)
    if approximation == "sap":
        assert np.all(c.hunt_crossley_dissipation == 0)
        assert np.all(c.relaxation_time > 0)
    else:
        assert c.relaxation_time is None


def test_results_broadcast_and_scalars_stay_scalars():
    p = predict(stiffness=np.array([[1e4], [1e5]]), dissipation=[0.0, 0.5, 3.0], mass=1.0,
                speed=1.0, time_step=1e-3)  # fmt: skip
    assert p.restitution.shape == p.restitution_range[0].shape == p.sticks.shape == (2, 3)
    assert np.all(p.restitution_range[0] <= p.restitution)
    assert np.all(p.restitution <= p.restitution_range[1])
    q = predict(stiffness=1e4, dissipation=0.5, mass=1.0, speed=1.0, time_step=1e-3, phase=0.2)
    assert isinstance(q.restitution, float)
    assert isinstance(q.sticks, bool)
    c = point_contact_for(restitution=0.6, speed=1.0, mass=0.2, contact_time=0.01)
    assert isinstance(c.point_contact_stiffness, float)
    assert isinstance(c.prediction.restitution, float)
