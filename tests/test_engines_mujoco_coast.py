"""The closed-form coast (impactsym.engines.mujoco.coast) against RK4 free flight stepped
stage by stage."""

from __future__ import annotations

import numpy as np

from impactsym.engines.mujoco.coast import coast_steps


def _brute(x, v, g, b, k, h, limit=5000):
    """First step at which the state has left (x < 0) or a stage may push, by stepping."""
    for n in range(limit):
        if n and x < 0:
            return n
        stages = [(x, v)]
        for c in (0.5, 0.5, 1.0):
            stages.append((x + c * h * stages[-1][1], v + c * h * g))
        if n and any(xs >= 0 and g + b * vs + k * xs > 0 for xs, vs in stages):
            return n
        vs = [s[1] for s in stages]
        x, v = x + h * (vs[0] / 6 + vs[1] / 3 + vs[2] / 3 + vs[3] / 6), v + h * g
    return np.inf


def test_coast_steps_is_the_first_step_that_leaves_or_may_push():
    rng = np.random.default_rng(3)
    size = 300
    x = rng.uniform(0, 2e-4, size)
    v = -rng.uniform(0.001, 0.2, size)
    g = rng.choice([0.0, 9.81, 30.0], size)
    b = rng.uniform(10, 300, size)
    k = rng.uniform(1e2, 1e4, size)
    h = rng.choice([2e-3, 1e-4], size)
    # only states that coast: the force term is not positive at the start
    ok = g + b * v + k * x <= 0
    n = coast_steps(x[ok], v[ok], g[ok], b[ok], k[ok], h[ok])
    brute = [_brute(*args) for args in zip(x[ok], v[ok], g[ok], b[ok], k[ok], h[ok], strict=True)]
    assert ok.sum() > 50
    assert max(brute) > 100  # long coasts are among them
    np.testing.assert_array_equal(n, brute)
