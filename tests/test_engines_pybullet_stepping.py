"""The live-element loop of PyBullet's step map against the loop that steps every element
to the end (tests/references/pybullet_steps.py): the same numbers, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from references.pybullet_steps import step_pattern as reference

from impactsym.engines.pybullet.stepping import step_pattern

RNG = np.random.default_rng(240)


@pytest.mark.parametrize(
    "settings",
    [{}, {"substeps": 2}, {"processing_threshold": 0.0, "slop": 0.0},
     {"velocity_restitution": 0.5}],
)  # fmt: skip
def test_live_loop_is_the_full_loop(settings):
    # sticking, short and long contacts mixed, with and without gravity
    n = 1500
    k, c = 10 ** RNG.uniform(2, 5, n), RNG.uniform(0.0, 30.0, n)
    m, v = RNG.uniform(0.05, 2.0, n), RNG.uniform(0.2, 3.0, n)
    g = np.where(RNG.uniform(size=n) < 0.5, 0.0, 9.81)
    p = RNG.uniform(0.0, 1.0, n)
    new, key = step_pattern(k, c, m, v, g, 1 / 240, p, **settings)
    old, key_old = reference(k, c, m, v, g, 1 / 240, p, **settings)
    assert old.sticks.any()
    assert not old.sticks.all()
    for name in new.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)
    for name in key_old.dtype.names:  # the pattern: every branch count
        np.testing.assert_array_equal(key[name], key_old[name], err_msg=name)
    # shapes pass through
    one, _ = step_pattern(k[:6].reshape(2, 3), 0.5, 0.1, 1.0, 0.0, 1 / 240, 0.3)
    assert one.restitution.shape == (2, 3)


def test_a_processing_threshold_of_minus_inf_processes_no_contact():
    """``processing_threshold=-inf`` (no gap is within it) never applies an impulse, as
    the reference loop's ``-x <= threshold`` says: every body passes through and sticks
    (only ``+inf`` means no threshold at all)."""
    k, c, m = 10 ** RNG.uniform(2, 5, 50), RNG.uniform(0.0, 30.0, 50), RNG.uniform(0.05, 2.0, 50)
    p = RNG.uniform(0.0, 1.0, 50)
    new, key = step_pattern(k, c, m, 1.0, 0.0, 1 / 240, p, processing_threshold=-np.inf)
    _, key_old = reference(k, c, m, 1.0, 0.0, 1 / 240, p, processing_threshold=-np.inf)
    assert new.sticks.all()
    np.testing.assert_array_equal(new.peak_accel, 0.0)
    for name in key_old.dtype.names:
        np.testing.assert_array_equal(key[name], key_old[name], err_msg=name)
