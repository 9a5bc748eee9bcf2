"""The NumPy-only source of :func:`impactsym.rod.codegen.numpy_source`: self-contained,
the same numbers as the package, and right against the method of characteristics."""

from __future__ import annotations

import numpy as np
import pytest
from references.rod_characteristics import Characteristics

from impactsym.rod import contact_force, displacement, numpy_source


@pytest.fixture(scope="module")
def generated() -> dict:
    source = numpy_source()
    for word in ("sympy", "mpmath", "impactsym", "scipy"):
        assert f"import {word}" not in source
        assert f"from {word}" not in source
    namespace: dict = {}
    exec(compile(source, "<rod_numpy>", "exec"), namespace)
    return namespace


CASES = ((0.05, 0.0), (1.0, 2.0), (50.0, 5.0))


def test_numpy_source_runs_with_numpy_only_and_matches(generated):
    """The exported module is the package's rigid kernel: the same numbers, bit for bit."""
    tt = np.linspace(-1.0, 100.0, 997)
    for a, force in CASES:
        assert np.array_equal(
            generated["rod_displacement"](tt, a, force), displacement(tt, a, force)
        )
        assert np.array_equal(
            generated["rod_contact_force"](tt, a, force), contact_force(tt, a, force)
        )
    assert "alpha" in generated["rod_displacement"].__doc__
    with pytest.raises(ValueError, match="alpha"):
        generated["rod_contact_force"](1.0, 0.0, 0.0)


def test_numpy_source_agrees_with_the_method_of_characteristics(generated):
    """Against an independent solution (delay equation by Chebyshev collocation, no
    Laplace series), up to ``t = 100``."""
    tt = np.sort(np.random.default_rng(5).uniform(0.0, 100.0, 200))
    for a, force in CASES:
        reference = Characteristics(a, force, 51)
        assert np.max(np.abs(generated["rod_contact_force"](tt, a, force) - reference.N(tt))) < 1e-9
        assert np.max(np.abs(generated["rod_displacement"](tt, a, force) - reference.y(tt))) < 1e-9


def test_numpy_source_contact_time_is_the_package_search(generated):
    """The certified search, exported: the same contact times, bit for bit."""
    from impactsym.rod import contact_time

    rng = np.random.default_rng(11)
    alpha, force = 10 ** rng.uniform(-1.5, 1.5, 16), rng.uniform(0.0, 2.5, 16)
    for condition in ("force", "position"):
        got = generated["rod_contact_time"](alpha, force, condition=condition, t_max=30.0)
        assert np.array_equal(got, contact_time(alpha, force, condition=condition, t_max=30.0))
    # the first release of a light striker against the delay equation's own solution
    reference = Characteristics(0.5, 0.0, 3)
    t_c = generated["rod_contact_time"](0.5, 0.0, condition="force")
    assert isinstance(t_c, float)
    assert abs(reference.N(np.array([t_c]))[0]) < 1e-9


def test_numpy_source_needs_the_condition_and_refuses_a_finite_kappa(generated):
    with pytest.raises(TypeError, match="required keyword-only argument: 'condition'"):
        generated["rod_contact_time"](0.5, 0.0)
    with pytest.raises(ValueError, match="kappa must be inf .* got 2.0"):
        generated["rod_contact_force"](1.0, 0.5, 0.0, kappa=2.0)
    with pytest.raises(ValueError, match="kappa must be inf .* got 2.0"):
        generated["rod_contact_time"](0.5, 0.0, condition="position", kappa=2.0)
    with pytest.raises(ValueError, match="alpha must lie in"):  # the package's own range
        generated["rod_displacement"](1.0, 1e7, 0.0)
