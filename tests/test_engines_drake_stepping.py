"""Drake's discrete step loop, gathering the live elements only when half have finished,
against the loop that gathers them at every step (tests/references/drake_steps.py): the
same numbers, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from references.drake_steps import step_contact as reference

from impactsym.engines.drake.stepping import step_contact

RNG = np.random.default_rng(1000)


def _contacts(n, tau_max):
    k, d = 10 ** RNG.uniform(3, 5, n), RNG.uniform(0.0, 3.0, n)
    m, v = RNG.uniform(0.05, 2.0, n), RNG.uniform(0.2, 3.0, n)
    g = np.where(RNG.uniform(size=n) < 0.5, 0.0, 9.81)
    p, tau = RNG.uniform(0.0, 1.0, n), RNG.uniform(0.0, tau_max, n)
    return k, d, tau, m, g, v, p


def _same(new, old):
    for name in new.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)


@pytest.mark.parametrize("h", [1e-3, 1e-2])
def test_lazy_gathering_is_the_per_step_gathering(h):
    # sticking, short and long contacts mixed, with and without gravity
    k, d, tau, m, g, v, p = _contacts(1500, 0.0)
    new = step_contact(k, d, tau, m, g, v, h, p, approximation="lagged")
    old = reference(k, d, tau, m, g, v, h, p, approximation="lagged")
    assert old.sticks.any()
    assert not old.sticks.all()
    _same(new, old)


def test_lazy_gathering_under_sap():
    k, d, tau, m, g, v, p = _contacts(400, 2e-3)  # short relaxation times: quick contacts
    _same(step_contact(k, d, tau, m, g, v, 1e-3, p, approximation="sap"),
          reference(k, d, tau, m, g, v, 1e-3, p, approximation="sap"))  # fmt: skip
    one = step_contact(1e4, 0.5, 0.2, 1.0, 0.0, 1.0, 1e-3, [[0.0, 0.5]], approximation="lagged")
    assert one.restitution.shape == (1, 2)
