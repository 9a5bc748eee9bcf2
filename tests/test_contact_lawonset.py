"""The multisection of the stick boundary (impactsym.contact.lawonset) on verdicts whose
boundary is known, and the kernel's verdict-only integration (``settle=False``)."""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.contact.lawkernel import integrate
from impactsym.contact.lawonset import stick_onset


def test_stick_onset_finds_a_known_boundary_to_its_tolerance():
    delta = np.array([0.01, 0.3, 2.0, 50.0])
    known = 0.7 / delta**2  # from 7e3 down to 2.8e-4: the scan goes up and down

    def sticks(d, f, q):
        return f >= 0.7 / d**2

    onset = stick_onset(sticks, delta, np.ones(4), floor=1e-12, rtol=1e-11, label="t")
    assert np.all(onset >= known)
    np.testing.assert_allclose(onset, known, rtol=1e-11)


def test_stick_onset_marks_a_boundary_below_the_floor_or_raises_naming_the_caller():
    delta = np.array([1.0, 2.0])

    def sticks(d, f, q):
        return f >= np.where(d > 1.5, 1e-9, 0.25)

    marked = stick_onset(sticks, delta, np.ones(2), floor=1e-6, rtol=1e-10, label="t",
                         below_floor=np.nan)  # fmt: skip
    assert marked[0] == pytest.approx(0.25, rel=1e-10)
    assert np.isnan(marked[1])
    with pytest.raises(ValueError, match="demo: with damping number 2.0 the body still sticks"):
        stick_onset(sticks, delta, np.ones(2), floor=1e-6, rtol=1e-10, label="demo")


@pytest.mark.parametrize("condition", ["position", "force"])
def test_the_verdict_only_integration_gives_the_same_verdict_and_ends(condition):
    rng = np.random.default_rng(4)
    delta, b = rng.uniform(0.05, 1.5, 60), rng.uniform(0.0, 1.0, 60)
    q = np.full(60, 1.5)
    full = integrate("tsuji", delta, b, q, condition=condition)
    quick = integrate("tsuji", delta, b, q, condition=condition, settle=False)
    assert full.sticks.any()
    assert not full.sticks.all()
    np.testing.assert_array_equal(quick.sticks, full.sticks)
    np.testing.assert_allclose(quick.tau_c, full.tau_c, rtol=1e-14)  # the subsets differ
    np.testing.assert_allclose(quick.e, full.e, rtol=0, atol=1e-14)
