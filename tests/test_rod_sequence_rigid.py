"""Tests of the rigid-contact step model of the rod impact sequence,
:mod:`impactsym.rod.sequence_rigid` (through :func:`impactsym.rod.impact_sequence`)."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from references.rod_characteristics import Characteristics, UnilateralGrid
from references.rod_sequence_mp import SequenceMP

from impactsym.numeric.exppoly import exp_poly_bernstein_positive, exp_poly_roots
from impactsym.rod import contact_force, displacement, impact_sequence

CASES = [(0.3, 0.0), (1.0, 0.0), (20.0, 0.0), (1.0, 0.5), (0.3, 1.0), (2.0, 0.3)]


@pytest.mark.parametrize(("alpha", "f"), CASES)
def test_events_agree_with_a_grid_solver_of_the_characteristics(alpha, f):
    """Every contact interval and separation speed within a few grid steps (step 1.25e-4;
    the grid is first order at the jumps of the incoming wave)."""
    seq = impact_sequence(alpha, f, t_max=20.0)
    ref = UnilateralGrid(alpha, f, 20.0, steps_per_transit=8000)
    assert len(seq.contacts) == len(ref.contacts)
    assert np.abs(np.array(seq.contacts) - np.array(ref.contacts)).max() < 1e-3
    n = min(len(seq.separation_velocities), len(ref.separation_speeds))
    assert n == len(seq.separation_velocities)
    got, want = np.array(seq.separation_velocities[:n]), np.array(ref.separation_speeds[:n])
    assert np.abs(got - want).max() < 3e-3
    t = np.linspace(0.0, 20.0, 4001)
    stress = np.abs(seq.fixed_end_stress(t) - ref.fixed_end_stress(t))
    assert np.median(stress) < 1e-3  # off the jumps, which the grid smears over a step


def test_random_sequences_agree_with_the_grid_solver():
    """Seeded random (alpha, f), chattering ones included, to t = 12."""
    rng = np.random.default_rng(2026)
    for alpha, f in zip(np.exp(rng.uniform(-2.5, 2.0, 6)), rng.uniform(0.0, 1.5, 6), strict=True):
        seq = impact_sequence(alpha, f, t_max=12.0)
        ref = UnilateralGrid(alpha, f, 12.0, steps_per_transit=8000)
        assert len(seq.contacts) == len(ref.contacts), (alpha, f)
        assert np.abs(np.array(seq.contacts) - np.array(ref.contacts)).max() < 1e-3


@pytest.mark.parametrize("alpha", [0.05, 0.3, 0.5, 1.0, 1.5])
def test_light_striker_leaves_after_the_first_reflection_returns(alpha):
    """Closed form for f = 0, derived by hand from the delay equation: on [0, 2)
    g = exp(-t/alpha); at t = 2 the reflection (value 1) arrives, g(2+) = 1 + e,
    e = exp(-2/alpha), and alpha g' + g = -2 exp(-tau/alpha) gives
    g = exp(-tau/alpha) (1 + e - 2 tau/alpha), N = exp(-tau/alpha) (2 + e - 2 tau/alpha):
    N = 0 at tau = alpha (1 + e/2) (< 2 for alpha < 1.7), with y' = g - g(t-2) =
    -2 exp(-1 - e/2) there."""
    e = math.exp(-2.0 / alpha)
    seq = impact_sequence(alpha, 0.0, t_max=10.0)
    assert seq.contacts[0][1] == pytest.approx(2.0 + alpha * (1.0 + e / 2), abs=1e-13)
    speed = -2.0 * math.exp(-1.0 - e / 2)
    assert seq.separation_velocities[0] == pytest.approx(speed, abs=1e-13)
    # the classical fixed-end stress: twice the impact stress, and after the
    # reflection 2 (1 + e), when the returning wave superposes
    assert seq.max_fixed_end_stress == pytest.approx(2.0 * (1.0 + e), abs=1e-13)
    assert seq.fixed_end_stress(3.0) == pytest.approx(2.0 * (1.0 + e), abs=1e-13)
    assert seq.fixed_end_stress(1.0) == pytest.approx(2.0, abs=1e-15)


@pytest.mark.parametrize("alpha", [1e-2, 1e-4, 1e-6])
def test_light_striker_restitution_tends_to_two_over_e(alpha):
    """Also where exp(-t/alpha) underflows long before the reflection returns."""
    seq = impact_sequence(alpha, 0.0, t_max=10.0)
    assert seq.final
    assert len(seq.contacts) == 1
    assert seq.restitution == pytest.approx(2.0 / math.e, abs=1e-15)


@pytest.mark.parametrize(("alpha", "f"), [(0.3, 0.0), (2.0, 0.0), (20.0, 0.0), (1.0, 0.5)])
def test_agrees_with_persistent_contact_until_the_first_separation(alpha, f):
    seq = impact_sequence(alpha, f, t_max=30.0)
    end = seq.contacts[0][1]
    t = np.linspace(0.0, end, 997)[:-1]
    assert np.abs(seq.contact_force(t) - contact_force(t, alpha, f)).max() < 1e-11
    assert np.abs(seq.displacement(t) - displacement(t, alpha, f)).max() < 1e-11
    ref = Characteristics(alpha, f, int(end / 2) + 1)  # Chebyshev collocation, persistent
    inner = t[np.abs(t / 2 - np.round(t / 2)) > 1e-3]
    assert np.abs(seq.contact_force(inner) - ref.N(inner)).max() < 1e-9


@pytest.mark.parametrize(("alpha", "f"), [(10.0, 5.0), (3.0, 1.0)])
def test_long_chattering_sequences_stay_exact(alpha, f):
    """With the antiderivative summed from the top, chattering sequences that the
    derivative-by-derivative sum lost near t ~ 57 and 61 (energy off by 89 at t = 100
    before the balance check existed) balance to rounding at t = 100."""
    seq = impact_sequence(alpha, f, t_max=100.0)
    assert len(seq.contacts) > 50
    t = np.linspace(0.0, 100.0, 4001)
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t))
    assert np.abs(seq.energy.balance(t) / scale).max() < 1e-10


def test_pressing_force_brings_the_striker_back():
    seq = impact_sequence(1.0, 0.5, t_max=20.0)
    assert len(seq.contacts) > 2
    assert math.isnan(seq.restitution)
    assert not seq.final
    starts = np.array([c[0] for c in seq.contacts[1:]])
    assert np.abs(seq.displacement(starts) - seq.rod_end_displacement(starts)).max() < 1e-10
    flight = 0.5 * (seq.contacts[0][1] + seq.contacts[1][0])
    assert np.all(seq.displacement(flight) <= seq.rod_end_displacement(flight))


def test_tensile_front_ends_contact_by_a_jump():
    """For f > 0 a contact can end with N jumping below zero (a tensile front)."""
    seq = impact_sequence(1.0, 0.5, t_max=20.0)
    before = [seq.contact_force(end - 1e-9) for _, end in seq.contacts[:-1]]
    assert max(before) > 0.5  # compressive just before the end: ended by a jump
    assert min(before) < 1e-6  # others end with N falling continuously to zero


SHORTCUT_CASES = [(0.3, 0.0), (1.0, 0.5), (0.3, 1.0), (2.0, 0.3), (0.12, 0.6), (5.0, 0.9)]


@pytest.mark.parametrize(("alpha", "f"), SHORTCUT_CASES)
def test_events_agree_with_a_40_digit_reference(alpha, f):
    """Every event (found by the cheap positivity certificate, the certified isolation and
    the antiderivatives carried over from a flight's copy) against the method of steps in
    40-digit arithmetic with events found by sampling and bisection
    (``tests/references/rod_sequence_mp.py``): no event skipped or added, each exact to
    rounding (measured: within 7e-14)."""
    seq = impact_sequence(alpha, f, t_max=20.0)
    ref = SequenceMP(alpha, f, 20.0)
    assert len(seq.contacts) == len(ref.contacts)
    assert np.abs(np.array(seq.contacts) - np.array(ref.contacts)).max() < 1e-12
    assert len(seq.separation_velocities) == len(ref.separation_velocities)
    if seq.separation_velocities:
        got, want = np.array(seq.separation_velocities), np.array(ref.separation_velocities)
        assert np.abs(got - want).max() < 1e-12


@pytest.mark.parametrize(("alpha", "f"), SHORTCUT_CASES)
def test_pruned_stress_maximum_is_the_exhaustive_one(alpha, f):
    """max_fixed_end_stress against a search of every piece (ends and zeros of
    Q' - Q, none skipped), and never below dense samples of the stress."""
    seq = impact_sequence(alpha, f, t_max=30.0)
    tab, s_end = seq._tables, 29.0
    ends = np.r_[tab.start[1:], np.inf]
    best = 0.0
    for i, s0 in enumerate(tab.start):
        if s0 >= s_end or ends[i] <= 0.0:
            continue
        lo, hi = (max(s0, 0.0) - s0) / alpha, (min(ends[i], s_end) - s0) / alpha
        Q = np.trim_zeros(tab.q[i], "b")
        x = [lo, hi]
        if Q.size > 1:
            dQ = np.polynomial.polynomial.polyder(Q)
            x += list(exp_poly_roots(np.zeros(0), np.polynomial.polynomial.polysub(dQ, Q), lo, hi))
        x = np.array(x)
        poly = np.polynomial.polynomial.polyval(x, Q) if Q.size else 0.0 * x
        best = max(best, float((tab.p[i] + np.exp(-x) * poly).max()))
    assert seq.max_fixed_end_stress == pytest.approx(2.0 * best, rel=0, abs=1e-13)
    dense = seq.fixed_end_stress(np.linspace(0.0, 30.0, 60001))
    assert seq.max_fixed_end_stress >= dense.max() - 1e-13


def test_fewer_gauss_nodes_for_low_degree_pieces_change_only_rounding(monkeypatch):
    """Integrals of g and g^2 with 24/32/48 nodes by degree against 48 nodes everywhere,
    and single pieces against mpmath quadrature."""
    import impactsym.rod.sequence_rigid as sequence_rigid

    t = np.linspace(0.0, 29.9, 3001)
    fast = [impact_sequence(a, f, t_max=30.0) for a, f in SHORTCUT_CASES]
    monkeypatch.setattr(
        sequence_rigid, "_GAUSS_BY_DEGREE", [(96, np.polynomial.legendre.leggauss(48))]
    )
    for (alpha, f), seq in zip(SHORTCUT_CASES, fast, strict=True):
        slow = impact_sequence(alpha, f, t_max=30.0)
        assert np.abs(seq.energy.rod(t) - slow.energy.rod(t)).max() < 1e-13
        assert np.abs(seq.rod_end_displacement(t) - slow.rod_end_displacement(t)).max() < 1e-13
    tab = fast[1]._tables  # alpha = 1, f = 0.5
    for i in np.flatnonzero(tab.degree > 0)[:: max(1, int((tab.degree > 0).sum()) // 6)]:
        h = min(tab.start[i + 1] - tab.start[i], 1.0)
        i1, i2 = tab._partial(np.array([i]), np.array([h]))
        Q = tab.q[i][: tab.degree[i] + 1][::-1].tolist()

        def g(s, i=i, Q=Q):
            return tab.p[i] + mp.exp(-s) * mp.polyval(Q, s)

        assert float(i1[0]) == pytest.approx(float(mp.quad(g, [0, h])), abs=1e-13)
        assert float(i2[0]) == pytest.approx(float(mp.quad(lambda s: g(s) ** 2, [0, h])), abs=1e-13)


def test_bernstein_certificate_proves_what_is_true_and_only_that():
    """The event loop's second certificate (before a root search): closed cases, then
    random exponential polynomials sampled on a fine grid (a proof of F > 0 that a
    sampled minimum contradicts fails the test), and it proves cases the one-sided
    Taylor certificate cannot."""
    from impactsym.numeric.exppoly import exp_poly_positive

    prove = exp_poly_bernstein_positive
    assert prove([1.0], [1.0, -2.0], 1.0)  # e^x + 1 - 2x >= 3 - 2 ln 2
    assert not prove([1.0], [-3.0], 2.0)  # e^x - 3 vanishes at ln 3
    assert not prove([], [0.25, -1.0, 1.0], 1.0)  # (x - 1/2)^2: a touch is no proof
    assert prove([1.0], [-1.0], 2.0, rising_from_zero=True)  # e^x - 1 rises from 0
    assert not prove([1.0], [-1.0, -2.0], 2.0, rising_from_zero=True)  # F'(0) = -1
    # 1 - 1.5 x + x^2 >= 7/16 on [0, 1]: the one-sided Taylor bound 1 - 1.5 fails, the
    # Bernstein coefficients 1, 1/4, 1/2 prove it
    assert not exp_poly_positive([], [1.0, -1.5, 1.0], 1.0)
    assert prove([], [1.0, -1.5, 1.0], 1.0)
    rng = np.random.default_rng(7)
    proven = 0
    for _ in range(400):
        A = rng.normal(size=rng.integers(0, 4)).tolist()
        B = rng.normal(size=rng.integers(1, 12)).tolist()
        B[0] = abs(B[0]) + 2.0 * rng.random()
        X = float(rng.uniform(0.01, 2.0))
        rising = bool(rng.random() < 0.3)
        if rising:  # F(0) = 0, F'(0) >= 0
            a0 = A[0] if A else 0.0
            a1 = A[1] if len(A) > 1 else 0.0
            B[0] = -a0
            if len(B) < 2:
                B.append(0.0)
            B[1] = abs(B[1]) - a0 - a1
        if not prove(A, B, X, rising_from_zero=rising):
            continue
        proven += 1
        x = np.linspace(0.0, X, 4001)[1 if rising else 0 :]
        F = np.polynomial.polynomial.polyval(x, B)
        if A:
            F += np.exp(x) * np.polynomial.polynomial.polyval(x, A)
        low = F.min()
        assert low > 0, (A, B, X, rising)
    assert proven > 50


def test_quick_gap_bound_proves_only_open_gaps():
    """The flight's first, quickest test (the gap C(x) + 2 alpha e^-x R(x), R - R' =
    Q_in, bounded below through its slope): where it says open, the gap sampled in
    40-digit arithmetic is positive and the general search finds no zero; it says open
    for a striker far away, not where the gap touches zero at the piece's end, nor for
    an opening gap (zero at x = 0); f = 0 (C linear) and a constant incoming wave
    (Q_in = []) included."""
    from impactsym.numeric.poly import exp_antiderivative, horner
    from impactsym.rod.sequence_rigid import _gap_stays_open

    def gap(C, R, alpha, x):
        with mp.workdps(40):
            x = mp.mpf(x)
            c = sum(mp.mpf(ck) * x**k for k, ck in enumerate(C))
            r = sum(mp.mpf(rk) * x**k for k, rk in enumerate(R))
            return c + 2 * mp.mpf(alpha) * mp.exp(-x) * r

    rng = np.random.default_rng(17)
    proven = 0
    for trial in range(300):
        alpha = float(np.exp(rng.uniform(np.log(0.1), np.log(10.0))))
        n = int(rng.integers(0, 14))
        Q_in = (rng.normal(size=n) * 0.5 ** np.arange(n)).tolist()
        R = exp_antiderivative(Q_in) if Q_in else [0.0]
        X = float(rng.uniform(0.01, 2.0))
        f = 0.0 if trial % 3 == 0 else float(rng.uniform(0.0, 1.0))
        C = [0.0, float(rng.normal()) * alpha, -0.5 * alpha * f]
        far = float(rng.choice([0.0, 1e-3, 0.1, 1.0, 10.0]))
        C[0] = far - 2.0 * alpha * R[0]  # the gap at x = 0
        if trial % 5 == 0:  # the gap closes exactly at X
            C[0] -= float(gap(C, R, alpha, X))
        if not _gap_stays_open(C, Q_in, R, alpha, X):
            continue
        proven += 1
        assert trial % 5 != 0
        assert far > 0.0
        xs = np.linspace(0.0, X, 201)
        assert min(gap(C, R, alpha, x) for x in xs) > 0, (C, Q_in, alpha, X)
        B = [2.0 * alpha * r for r in R]
        assert exp_poly_roots(C, B, 0.0, X).size == 0
        assert horner(C, X) + 2.0 * alpha * math.exp(-X) * horner(R, X) > 0.0
    assert proven > 60
    # a striker far away over a long constant-wave flight: open; an opening gap: no proof
    assert _gap_stays_open([5.0, -1.0, -0.25], [], [0.0], 1.0, 2.0)  # C(2) = 2
    assert not _gap_stays_open([5.0, -1.0, -0.25], [], [0.0], 1.0, 3.0)  # C(3) < 0
    assert not _gap_stays_open([0.0, 1.0, -0.25], [], [0.0], 1.0, 3.0)


def test_piece_integrals_of_high_degree_agree_with_mpmath():
    """The Gauss rules (Q by Horner's rule at all nodes of all pieces): pieces of degree
    9 to 40 (24, 32 and 48 nodes) of a long chattering sequence against mpmath
    quadrature, at their ends and halfway."""
    tab = impact_sequence(3.0, 1.0, t_max=100.0)._tables
    chosen = []
    for low, high in ((1, 8), (9, 16), (17, 96)):
        rows = np.flatnonzero((tab.degree >= low) & (tab.degree <= high))
        chosen += rows[:: max(1, rows.size // 3)][:3].tolist()
    assert int(tab.degree[chosen].max()) > 16  # the 48-node rule is exercised
    h = np.diff(np.append(tab.start, 100.0))[chosen]
    tau = np.concatenate([h, 0.5 * h])
    i1, i2 = tab._partial(np.array(chosen * 2), tau)
    for k, (i, t) in enumerate(zip(chosen * 2, tau, strict=True)):
        Q = tab.q[i][: tab.degree[i] + 1][::-1].tolist()

        def g(s, i=i, Q=Q):
            return tab.p[i] + mp.exp(-s / tab.alpha) * mp.polyval(Q, s / tab.alpha)

        with mp.workdps(30):
            ref1 = mp.quad(g, [0, t])
            ref2 = mp.quad(lambda s, g=g: g(s) ** 2, [0, t])
        assert float(i1[k]) == pytest.approx(float(ref1), abs=1e-13, rel=1e-13)
        assert float(i2[k]) == pytest.approx(float(ref2), abs=1e-13, rel=1e-13)


def test_blocked_matrix_product_is_the_plain_one_to_rounding():
    """The row blocks that keep OpenBLAS on one thread give the plain product (to the
    last bits: a block's kernel may round differently)."""
    from impactsym.rod.sequence_rigid import _small_matmul

    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(3000, 40)), rng.normal(size=(40, 48))  # 23 blocks of 136 rows
    assert np.abs(_small_matmul(a, b) - a @ b).max() < 1e-12
    assert _small_matmul(a[:5], b).shape == (5, 48)


def test_piece_integrals_keep_their_digits_where_the_terms_cancel():
    """Pieces whose terms cancel (sum |Q_k| x^k some 1e4 times |Q|): both integrals to
    1e-14 relative of mpmath's (the power sum (Q_k x^k) zeta^k as one matrix product
    lost 1.3 digits there, 7e-13 on an integral of 10; found by review)."""
    alpha, t_max = 0.34035831729274835, 40.0
    tab = impact_sequence(alpha, 3.4330556507275816, t_max=t_max)._tables
    h = np.diff(np.append(tab.start, t_max))
    powers = np.power.outer(h / alpha, np.arange(tab.q.shape[1], dtype=float))
    with np.errstate(all="ignore"):
        cancel = (np.abs(tab.q) * powers).sum(axis=1) / np.abs((tab.q * powers).sum(axis=1))
    cancel[~np.isfinite(cancel)] = 0.0
    chosen = np.argsort(cancel)[::-1][:4]
    assert cancel[chosen[-1]] > 5e3
    i1, i2 = tab._partial(chosen, h[chosen])
    for k, i in enumerate(chosen):
        Q = tab.q[i][: tab.degree[i] + 1][::-1].tolist()

        def g(s, i=i, Q=Q):
            return tab.p[i] + mp.exp(-s / alpha) * mp.polyval(Q, s / alpha)

        with mp.workdps(40):
            ref1 = mp.quad(g, [0, h[i]])
            ref2 = mp.quad(lambda s, g=g: g(s) ** 2, [0, h[i]])
        assert float(i1[k]) == pytest.approx(float(ref1), abs=1e-14, rel=1e-14)
        assert float(i2[k]) == pytest.approx(float(ref2), abs=1e-14, rel=1e-14)
