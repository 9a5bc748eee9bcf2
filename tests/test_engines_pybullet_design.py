"""pybullet.contact_for under gravity at 240 Hz: reachable targets are found.

Under gravity the phases stick above some damping (the pressing weight holds the soft
contact), and the textbook start of the design (the continuous damping ratio of the
target restitution) often lies there: Newton broke off at the start and refused targets
that a scan of ``predict`` over ``(k, zeta)`` reaches with no phase sticking. Each target
here is the prediction of such a scanned, non-sticking pair (independent of the design's
iteration); the design must deliver it, and PyBullet itself (the driver) must run one
design as predicted, phase by phase.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import pybullet as pyb

H = 1 / 240
BASE = {"speed": 1.0, "mass": 0.1, "gravity": 9.81}
# (k, zeta) pairs from the scan whose targets the design used to refuse (no phase sticks)
PAIRS = np.array([[843.1, 0.177], [254.0, 0.161], [509.8, 0.287], [1900.2, 0.248]])


def _targets():
    k, z = PAIRS.T
    c = 2.0 * z * np.sqrt(k * BASE["mass"])
    p = pyb.predict(stiffness=k, damping=c, other_damping=0.0, **BASE)
    assert not np.any(p.sticks)
    return np.asarray(p.restitution), np.asarray(p.contact_time)


def test_scanned_targets_under_gravity_are_designed():
    e, t = _targets()
    assert np.all((t / H > 7) & (t / H < 20))
    assert np.all((e > 0.17) & (e < 0.35))
    d = pyb.contact_for(restitution=e, contact_time=t, other_damping=0.0, **BASE)
    np.testing.assert_allclose(d.restitution, e, rtol=1e-6)
    np.testing.assert_allclose(d.contact_time, t, rtol=1e-6)
    assert not np.any(d.sticks)
    # the design is the scanned pair: along the damping the restitution falls, one root
    np.testing.assert_allclose(d.pair_stiffness, PAIRS[:, 0], rtol=1e-5)


def test_a_refusal_names_a_timestep_and_that_step_delivers():
    # e = 0.3 at 4 steps: no pair at 240 Hz; the message names 1/480 s, checked here
    with pytest.raises(ValueError, match=r"timestep = 0\.00208333 s reaches it"):
        pyb.contact_for(restitution=0.3, contact_time=4 * H, **BASE)
    d = pyb.contact_for(restitution=0.3, contact_time=4 * H, timestep=H / 2, **BASE)
    p = pyb.predict(stiffness=d.stiffness, damping=d.damping, timestep=H / 2, **BASE)
    assert abs(p.restitution / 0.3 - 1.0) < 1e-6
    assert not p.sticks
    assert abs(p.contact_time / (4 * H) - 1.0) < 1e-6


def test_pybullet_runs_a_gravity_design_as_predicted():
    pytest.importorskip("pybullet")
    from impactsym.engines.pybullet.driver import pybullet_steps

    e, t = _targets()
    d = pyb.contact_for(restitution=e[0], contact_time=t[0], **BASE)  # plane keeps 0.1
    phases = np.array([0.0, 0.3, 0.7, 0.999])
    engine = pybullet_steps(stiffness=d.stiffness, damping=d.damping, phase=phases, **BASE)
    model = pyb.predict(stiffness=d.stiffness, damping=d.damping, phase=phases, **BASE)
    assert not engine.sticks.any()
    np.testing.assert_allclose(engine.restitution, model.restitution, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(engine.contact_time, model.contact_time, rtol=1e-12)
