"""The bounce event loop (impactsym.contact.loop): the re-contact root against mpmath,
memory that follows the contacts that occur, the energy cap on departure speeds."""

from __future__ import annotations

import tracemalloc

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impactsym.contact.loop import (
    MAX_CONTACTS,
    check_max_contacts,
    chi_functions,
    recontact,
    run_sequences,
)


# -- the re-contact root --------------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(st.floats(0.0, 60.0))
def test_chi_numeric_matches_the_integral_and_the_bracket_lemma(xv):
    """chi(x) = x psi(x), psi(x) = int_0^1 (1 - t) exp(-x t) dt (mpmath quadrature)."""
    chi, chi_dot = chi_functions()
    with mp.workdps(30):
        y = mp.mpf(xv)
        psi = mp.quad(lambda t: (1 - t) * mp.exp(-y * t), [0, 1])
        psi_dot = mp.quad(lambda t: -t * (1 - t) * mp.exp(-y * t), [0, 1])
    assert float(chi(xv)) == pytest.approx(float(y * psi), rel=1e-13, abs=1e-300)
    assert float(chi_dot(xv)) == pytest.approx(float(psi + y * psi_dot), rel=1e-11)
    assert float(psi) >= 0.5 - xv / 6  # lower end of the bracket
    if xv > 0:
        assert float(psi) < 1 / xv  # upper end of the bracket
        assert float(psi_dot) < 0  # psi strictly decreasing: the root is unique


def test_chi_has_no_overflow_for_huge_arguments():
    chi, chi_dot = chi_functions()
    big = np.array([1e10, 1e200, 1e300])
    np.testing.assert_allclose(chi(big), 1 - 1 / big, rtol=1e-15)
    assert np.all(np.isfinite(chi_dot(big)))


def test_recontact_root_against_mpmath():
    """psi(x*) - r at 50 digits over the slope psi'(x*): the error of x* (psi monotone)."""
    ratio = np.array([1e-300, 1e-9, 1e-3, 0.1, 0.3, 0.45, 0.499, 0.5 - 1e-9])
    roots = recontact(ratio)
    for q, root in zip(ratio, roots, strict=True):
        with mp.workdps(50):
            y, q = mp.mpf(root), mp.mpf(q)
            residual = (y - 1 + mp.exp(-y)) / y**2 - q
            slope = (2 - y - (2 + y) * mp.exp(-y)) / y**3
            # near r = 1/2 the float r itself fixes x* = 6 (1/2 - r) + ... only to ~6 ulp(1/2)
            assert abs(residual / slope) <= 1e-13 * y + 1e-14


# -- memory follows the contacts that occur ------------------------------------------------
def test_a_huge_cap_costs_nothing_when_the_sequences_are_short():
    """100 points of at most 9 contacts with max_contacts = 10^6: the tables were sized
    5 x points x max_contacts up front (4 GB, 32 s); now memory follows the contacts."""
    from references.bounce import simulate

    from impactsym.contact import bounce_map

    damping = np.linspace(0.1, 1.0, 100)
    tracemalloc.start()
    try:
        huge = bounce_map(damping, 0.2, condition="force", max_contacts=10**6)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6
    assert huge.n_contacts.max() <= 9
    assert huge.sticks.all()
    assert huge == bounce_map(damping, 0.2, condition="force", max_contacts=100)
    for i in (0, 40):  # against the event-driven reference
        rows, sticks = simulate(damping[i], 0.2, "force")
        assert (huge.n_contacts[i], bool(huge.sticks[i])) == (len(rows), sticks)
        assert huge.time_to_rest[i] == pytest.approx(rows[-1, 0], rel=1e-8)


def test_recorded_rows_grow_with_the_contacts_and_regroup_point_by_point():
    """Several points of different lengths in one loop: each point's rows are its own
    sequence (the one-point run), in contact order, whatever the cap."""
    from impactsym.contact import bounce_sequence

    damping, force = np.array([0.05, 2.0, 0.3, 0.1]), np.array([0.1, 0.3, 0.2, 0.0])
    for condition in ("position", "force"):
        tracemalloc.start()
        try:
            many = run_sequences(damping, force, MAX_CONTACTS, condition=condition)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 5e6
        assert many.rows.shape == (many.n_contacts.sum(), 5)
        for i in range(damping.size):
            seq = bounce_sequence(damping[i], force[i], condition=condition)
            table = many.table(i)
            np.testing.assert_array_equal(table["start"], seq.start)
            np.testing.assert_array_equal(table["start"] + table["duration"], seq.end)
            np.testing.assert_array_equal(table["arrival"], seq.arrival_velocity)
            np.testing.assert_array_equal(table["departure"], seq.departure_speed)


@pytest.mark.parametrize("cap", [MAX_CONTACTS + 1, 10**9, 10**400])
def test_a_cap_beyond_any_meaningful_bound_is_refused_by_name(cap):
    with pytest.raises(ValueError, match=r"^max_contacts must be <= 1e\+07"):
        check_max_contacts(cap)
    assert check_max_contacts(np.int64(MAX_CONTACTS)) == MAX_CONTACTS
