"""The Hunt-Crossley closed form on arrays: every element iterates on its own (a batch gives
each element's own result), to the digits of a 40-digit mpmath reference."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from impactsym.contact.lawclosed import (
    hunt_crossley_parameter,
    hunt_crossley_restitution,
    linear_damping_ratio,
    linear_free_restitution,
    rho,
)


def restitution_reference(s: float) -> float:
    """e(s) = (1 + W0(-(1+s) e^-(1+s)))/s at 40 digits."""
    with mpmath.workdps(40):
        sv = mpmath.mpf(s)
        return float((1 + mpmath.lambertw(-(1 + sv) * mpmath.exp(-(1 + sv)))) / sv)


def parameter_reference(e: float, start: float) -> float:
    """The s with (1 + W0(-(1+s) e^-(1+s)))/s = e, by mpmath's secant from ``start``."""
    with mpmath.workdps(40):
        ev = mpmath.mpf(e)

        def excess(s):
            return (1 + mpmath.lambertw(-(1 + s) * mpmath.exp(-(1 + s)))).real / s - ev

        return float(mpmath.findroot(excess, mpmath.mpf(start) * (1 + mpmath.mpf("1e-6"))))


def test_restitution_batch_is_elementwise_and_matches_mpmath():
    rng = np.random.default_rng(3)
    s = np.concatenate([np.geomspace(1e-8, 1e3, 60), rng.uniform(0, 12, 400), [0.0]])
    batch = hunt_crossley_restitution(s)
    single = np.array([float(hunt_crossley_restitution(np.array(v))) for v in s])
    np.testing.assert_array_equal(batch, single)
    assert batch[-1] == 1.0
    for value, got in zip(s[:-1:9], batch[:-1:9], strict=True):
        assert got == pytest.approx(restitution_reference(value), rel=2e-14, abs=1e-300)
    assert hunt_crossley_restitution(s.reshape(-1, 1)).shape == (s.size, 1)


def test_parameter_batch_is_elementwise_and_inverts_to_mpmath():
    rng = np.random.default_rng(4)
    e = np.concatenate([rng.uniform(0.01, 0.999, 300), np.geomspace(1e-4, 0.5, 30), [1.0]])
    batch = hunt_crossley_parameter(e)
    single = np.array([float(hunt_crossley_parameter(np.array(v))) for v in e])
    np.testing.assert_array_equal(batch, single)
    assert batch[-1] == 0.0
    for value, got in zip(e[:-1:11], batch[:-1:11], strict=True):
        assert got == pytest.approx(parameter_reference(value, got), rel=1e-13)
    np.testing.assert_allclose(hunt_crossley_restitution(batch[:-1]), e[:-1], rtol=1e-13)


def test_rho_series_and_direct_branches_agree_with_mpmath():
    x = np.array([-0.9, -0.049, -1e-7, 1e-9, 0.0499, 0.05, 3.0])
    with mpmath.workdps(40):
        want = [
            float(mpmath.sign(v) * mpmath.sqrt(2 * (mpmath.mpf(v) - mpmath.log1p(mpmath.mpf(v)))))
            for v in x
        ]
    np.testing.assert_allclose(rho(x), want, rtol=1e-15)
    assert [float(rho(np.array(v))) for v in x] == list(rho(x))


@pytest.mark.parametrize("condition", ["position", "force"])
def test_linear_damping_ratio_inverts_the_linear_contact(condition):
    from impactsym.contact.api import restitution

    rng = np.random.default_rng(5)
    e = np.concatenate([rng.uniform(1e-3, 0.999, 200), [np.exp(-2.0), 1e-8, 1 - 1e-9, 1.0]])
    D = linear_damping_ratio(e, condition=condition)
    assert D[-1] == 0.0
    if condition == "force":  # e = exp(-2) is the critically damped contact; beyond: D > 1
        assert D[-4] == pytest.approx(1.0, rel=1e-14)
        assert D[-3] > 1.0
    np.testing.assert_allclose(restitution(D, 0.0, condition=condition), e, rtol=1e-13)
    single = [float(linear_damping_ratio(np.array(v), condition=condition)) for v in e[::17]]
    np.testing.assert_array_equal(D[::17], single)


def test_linear_damping_ratio_refuses_what_it_cannot_invert():
    with pytest.raises(ValueError, match="condition must be"):
        linear_damping_ratio(np.array(0.5), condition="speed")
    for bad in (0.0, 1.5, np.nan):
        with pytest.raises(ValueError, match="restitution must be in"):
            linear_damping_ratio(np.array([0.5, bad]), condition="force")


@pytest.mark.parametrize("condition", ["position", "force"])
def test_linear_free_restitution_is_the_linear_contact(condition):
    from impactsym.contact.api import restitution

    D = np.concatenate([np.linspace(0, 0.99, 100), [1.0, 1.5, 40.0, np.inf]])
    got = linear_free_restitution(D, condition=condition)
    exact = restitution(D[:-1], 0.0, condition=condition)  # D = inf: refused there
    np.testing.assert_allclose(got[:-1], exact, rtol=1e-13, atol=0)
    assert got[0] == 1.0
    assert (got[100:] == 0).all() if condition == "position" else got[-1] == 0.0
    np.testing.assert_allclose(linear_damping_ratio(got[1:100], condition=condition), D[1:100],
                               rtol=1e-12)  # fmt: skip
