"""The continuous varying-impedance contact (``continuous.varying_phase`` with the closed-form
passage beyond the impedance width, ``beyond_width.passage``) against SciPy's event
integration of the same law (``tests/references/mujoco_law.py``, DOP853 at rtol 1e-12)."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines.mujoco import predict
from impactsym.engines.mujoco.beyond_width import passage
from tests.references.mujoco_law import mujoco_contact

DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


@pytest.mark.parametrize(
    ("dampratio", "speed", "gravity"),
    [
        (0.05, 1.0, 9.81),  # stiff: most of the contact inside the width
        (0.3, 1.0, 0.0),
        (0.3, 30.0, 9.81),  # fast: the width crossed within one step (old: 8e-6 off)
        (1.2, 30.0, 0.0),
        (0.05, 0.01, 9.81),  # never reaches the width, released by position
    ],
)
def test_varying_phase_matches_event_integration(dampratio, speed, gravity):
    e, t_c, by_pos = mujoco_contact((0.02, dampratio), DEFAULT, speed, gravity)
    p = predict(solref=(0.02, dampratio), speed=speed, gravity=gravity)
    assert abs(p.restitution - e) < 5e-8
    assert p.contact_time == pytest.approx(t_c, rel=5e-8)
    assert bool(p.released_by_position) == by_pos


def test_passage_is_the_linear_solution():
    # from x0 = 2 mm, v0 = 0.3 m/s beyond a 1 mm width, omega = 100, D = 0.3, g = 9.81:
    # the closed form of x'' + 2 D omega x' + omega^2 x = (1 - d') g, sampled densely
    omega, D, g, dp, x0, v0, w = 100.0, 0.3, 9.81, 0.9, 2e-3, 0.3, 1e-3
    p = passage(
        omega=np.array([omega]), D=np.array([D]), gravity=np.array([g]), dp=np.array([dp]),
        x0=np.array([x0]), v0=np.array([v0]), width=np.array([w]),
    )  # fmt: skip
    x_s = (1 - dp) * g / omega**2
    mu = np.sqrt(1 - D * D) * omega
    t = np.linspace(0.0, 0.2, 2_000_001)
    u0, du0 = x0 - x_s, v0
    env = np.exp(-D * omega * t)
    x = x_s + env * (u0 * np.cos(mu * t) + (du0 + D * omega * u0) / mu * np.sin(mu * t))
    v = np.gradient(x, t)
    force = g + 2 * D * omega / dp * v + omega**2 / dp * x  # g + b v + d kbar x
    end = np.flatnonzero((force <= 0) | (x <= w))[0]
    assert p.duration[0] == pytest.approx(t[end], abs=2e-7)
    assert bool(p.released[0]) == bool(force[end] <= 0)
    assert p.max_penetration[0] == pytest.approx(x[:end].max(), rel=1e-6)
