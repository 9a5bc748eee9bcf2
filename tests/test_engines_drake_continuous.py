"""The continuous Drake contact without gravity: the Chebyshev interpolant of the contact
time against the phase-plane quadrature it replaces, and the designs against it."""

from __future__ import annotations

import numpy as np

from impactsym.engines.drake import point_contact_for
from impactsym.engines.drake.continuous import S_MAX, contact_time_quadrature, hunt_crossley_free

RNG = np.random.default_rng(2020)


def test_interpolated_contact_time_is_the_quadrature():
    # dense in [0, S_MAX], the ends and both sides of the piece edges included
    edges = np.array([0.0, 1.0, 2.0, S_MAX])
    s = np.concatenate([edges, np.nextafter(edges, 1.0)[:-1], np.nextafter(edges, -1.0)[1:],
                        [1e-300, 1e-12, 1e-6], RNG.uniform(0.0, S_MAX, 4000)])  # fmt: skip
    _, tau, _ = hunt_crossley_free(s)
    np.testing.assert_allclose(tau, contact_time_quadrature(s), rtol=3e-14, atol=0)
    assert abs(tau[0] / np.pi - 1) < 1e-14  # undamped: half a period


def test_designs_meet_their_targets_by_the_quadrature():
    # random continuous designs without gravity, checked by the slow path: the midpoint
    # quadrature of the contact time at the designed s = d v and T = sqrt(m / k)
    n = 2000
    e = RNG.uniform(0.31, 0.95, n)
    t = 10 ** RNG.uniform(-4, -1, n)
    m, v = 10 ** RNG.uniform(-2, 1, n), 10 ** RNG.uniform(-1, 1, n)
    d = point_contact_for(restitution=e, contact_time=t, speed=v, mass=m)
    s = d.hunt_crossley_dissipation * v
    slow = contact_time_quadrature(s) * np.sqrt(m / d.point_contact_stiffness)
    np.testing.assert_allclose(slow, t, rtol=1e-12)
    np.testing.assert_allclose(d.contact_time, t, rtol=1e-12)
    np.testing.assert_allclose(d.restitution, e, rtol=1e-12)
