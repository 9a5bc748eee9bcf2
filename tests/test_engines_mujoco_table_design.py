"""Many restitution designs of one contact (table_design): the tabulated, inverted phase
mean gives the designs the target-by-target search gives, and they hit their targets in
the general phase summary (an algorithm that shares nothing with the table)."""

import numpy as np
import pytest

from impactsym.engines import mujoco
from impactsym.engines.mujoco import discrete
from impactsym.engines.mujoco.euler import euler_contact
from impactsym.engines.mujoco.model import coefficients

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


@pytest.mark.parametrize(("gravity", "speed"), [(9.81, 1.0), (0.0, 0.5)])
def test_table_designs_equal_the_target_by_target_ones(gravity, speed):
    targets = np.linspace(0.3, 0.85, 200)  # >= 128 targets of one contact: the table
    many = mujoco.solref_for(
        restitution=targets, speed=speed, gravity=gravity, timestep=0.002, solimp=FLAT
    )
    few = np.concatenate(
        [
            mujoco.solref_for(
                restitution=part, speed=speed, gravity=gravity, timestep=0.002, solimp=FLAT
            ).solref[1]
            for part in np.array_split(targets, 4)  # 50 each: the search per target
        ]
    )
    # both hit the phase mean to 1e-9 or better: the dampratios agree to a few 1e-9
    np.testing.assert_allclose(many.solref[1], few, rtol=1e-7)
    pick = np.arange(0, 200, 23)
    c = coefficients((many.solref[0][pick], many.solref[1][pick]), FLAT, 0.002)
    n = pick.size
    ref = discrete._split_and_integrate(
        euler_contact, "euler", FLAT, c.damping, c.stiffness, np.ones(n),
        np.full(n, gravity), np.full(n, speed), np.full(n, 0.002),
    )  # fmt: skip
    np.testing.assert_allclose(ref[0], targets[pick], rtol=0, atol=2e-9)


def test_targets_of_several_contacts_share_no_table():
    """Two speeds, 150 targets each: one table per contact, each design its own."""
    targets = np.tile(np.linspace(0.35, 0.8, 150), 2)
    speeds = np.repeat([0.7, 1.4], 150)
    d = mujoco.solref_for(
        restitution=targets, speed=speeds, gravity=9.81, timestep=0.002, solimp=FLAT
    )
    np.testing.assert_allclose(d.prediction.restitution, targets, rtol=0, atol=2e-9)
    assert not np.allclose(d.solref[1][:150], d.solref[1][150:])
