"""damping_for: the designs deliver their target through impact(), and refuse the rest.

Checked independently: the Hunt–Crossley designs against the published ``lambda v0``
table and the integrated (not closed-form) restitution; every other design through
:func:`impact`, whose numbers ``test_contact_nonlinear.py`` checks against SciPy.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.contact import damping_for, impact
from impactsym.contact.lawkernel import integrate

KW = {"stiffness": 2000.0, "mass": 0.5, "speed": 1.5}


def test_hunt_crossley_designs_match_the_table_and_the_integration():
    e = np.array([0.2, 0.4, 0.6, 0.8, 0.9, 0.95])
    lam = damping_for("hunt-crossley", restitution=e, condition="position", **KW)
    np.testing.assert_allclose(lam * KW["speed"], [4.919, 2.083, 0.975, 0.373, 0.1665, 0.0789],
                               rtol=6e-4)  # fmt: skip
    run = integrate("hunt-crossley", lam * KW["speed"], np.zeros(6), np.full(6, 1.5),
                    condition="force")  # fmt: skip
    np.testing.assert_allclose(run.e, e, atol=1e-10)


@pytest.mark.parametrize(
    ("law", "condition", "force"),
    [
        ("linear", "force", 0.0),
        ("linear", "position", 5.0),
        ("hertz-linear", "force", 5.0),
        ("hunt-crossley", "position", 5.0),
        ("tsuji", "force", 5.0),
        ("viscoelastic", "position", 5.0),
        ("linear", "clipped", 5.0),
        ("tsuji", "clipped", 5.0),
        ("tsuji", "clipped", 0.0),
    ],
)
def test_designs_deliver_their_target(law, condition, force):
    targets = np.array([0.35, 0.85])
    damping = damping_for(law, restitution=targets, force=force, condition=condition, **KW)
    got = impact(law, damping=damping, force=force, condition=condition, **KW)
    np.testing.assert_allclose(got.restitution, targets, atol=1e-10)


def test_clipped_tsuji_reaches_low_targets_only_over_damped():
    alpha = damping_for("tsuji", restitution=[0.1, 0.3], condition="force", **KW)
    zeta = np.asarray(alpha) / np.sqrt(5.0)
    assert zeta[0] > 1.0 > zeta[1]  # below e^-2 = 0.135 the design is over-damped
    got = impact("tsuji", damping=alpha, condition="force", **KW)
    np.testing.assert_allclose(got.restitution, [0.1, 0.3], atol=1e-12)


def test_a_target_below_the_stick_jump_is_refused_with_the_reason():
    with pytest.raises(ValueError, match="sticks for damping numbers above .*position condition"):
        damping_for("tsuji", restitution=0.05, force=5.0, condition="force", **KW)


def test_full_restitution_needs_no_damping():
    assert damping_for("viscoelastic", restitution=1.0, condition="force", **KW) == 0.0


@pytest.mark.parametrize("law", ["linear", "tsuji"])
def test_clipped_reaches_targets_the_force_condition_cannot(law):
    """Under a pressing force the clipped restitution falls continuously to 0 at its stick
    boundary (the coast's departure speed vanishes there): e = 0.05 is designable where
    the force condition refuses it."""
    if law == "linear":  # (tsuji: test_a_target_below_the_stick_jump_is_refused_with_the_reason)
        with pytest.raises(ValueError, match="out of reach"):
            damping_for(law, restitution=0.05, force=5.0, condition="force", **KW)
    c = damping_for(law, restitution=0.05, force=5.0, condition="clipped", **KW)
    got = impact(law, damping=c, force=5.0, condition="clipped", **KW)
    assert got.restitution == pytest.approx(0.05, abs=1e-10)
