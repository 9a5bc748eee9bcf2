"""Tests of the rod impact continued past separation, :mod:`impactsym.rod.continuation`."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from references.rod_characteristics import Characteristics, UnilateralGrid

from impactsym.numeric.exppoly import exp_poly_roots
from impactsym.rod import contact_force, displacement, impact_sequence

CASES = [(0.3, 0.0), (1.0, 0.0), (20.0, 0.0), (1.0, 0.5), (0.3, 1.0), (2.0, 0.3)]


@pytest.mark.parametrize(("alpha", "f"), CASES)
def test_events_agree_with_a_grid_solver_of_the_characteristics(alpha, f):
    """Every contact interval and separation speed within a few grid steps (step 1.25e-4;
    the grid is first order at the jumps of the incoming wave)."""
    seq = impact_sequence(alpha, f, t_end=20.0)
    ref = UnilateralGrid(alpha, f, 20.0, steps_per_transit=8000)
    assert len(seq.contacts) == len(ref.contacts)
    assert np.abs(np.array(seq.contacts) - np.array(ref.contacts)).max() < 1e-3
    n = min(len(seq.separation_speeds), len(ref.separation_speeds))
    assert n == len(seq.separation_speeds)
    got, want = np.array(seq.separation_speeds[:n]), np.array(ref.separation_speeds[:n])
    assert np.abs(got - want).max() < 3e-3
    t = np.linspace(0.0, 20.0, 4001)
    stress = np.abs(seq.fixed_end_stress(t) - ref.fixed_end_stress(t))
    assert np.median(stress) < 1e-3  # off the jumps, which the grid smears over a step


def test_random_sequences_agree_with_the_grid_solver():
    """Seeded random (alpha, f), chattering ones included, to t = 12."""
    rng = np.random.default_rng(2026)
    for alpha, f in zip(np.exp(rng.uniform(-2.5, 2.0, 6)), rng.uniform(0.0, 1.5, 6), strict=True):
        seq = impact_sequence(alpha, f, t_end=12.0)
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
    seq = impact_sequence(alpha, 0.0, t_end=10.0)
    assert seq.contacts[0][1] == pytest.approx(2.0 + alpha * (1.0 + e / 2), abs=1e-13)
    speed = -2.0 * math.exp(-1.0 - e / 2)
    assert seq.separation_speeds[0] == pytest.approx(speed, abs=1e-13)
    # the classical fixed-end stress: twice the impact stress, and after the
    # reflection 2 (1 + e), when the returning wave superposes
    assert seq.max_fixed_end_stress == pytest.approx(2.0 * (1.0 + e), abs=1e-13)
    assert seq.fixed_end_stress(3.0) == pytest.approx(2.0 * (1.0 + e), abs=1e-13)
    assert seq.fixed_end_stress(1.0) == pytest.approx(2.0, abs=1e-15)


@pytest.mark.parametrize("alpha", [1e-2, 1e-4, 1e-6])
def test_light_striker_restitution_tends_to_two_over_e(alpha):
    """Also where exp(-t/alpha) underflows long before the reflection returns."""
    seq = impact_sequence(alpha, 0.0, t_end=10.0)
    assert seq.final
    assert len(seq.contacts) == 1
    assert seq.restitution == pytest.approx(2.0 / math.e, abs=1e-15)


@pytest.mark.parametrize(("alpha", "f"), [(0.3, 0.0), (2.0, 0.0), (20.0, 0.0), (1.0, 0.5)])
def test_agrees_with_persistent_contact_until_the_first_separation(alpha, f):
    seq = impact_sequence(alpha, f, t_end=30.0)
    end = seq.contacts[0][1]
    t = np.linspace(0.0, end, 997)[:-1]
    assert np.abs(seq.contact_force(t) - contact_force(t, alpha, f)).max() < 1e-11
    assert np.abs(seq.displacement(t) - displacement(t, alpha, f)).max() < 1e-11
    ref = Characteristics(alpha, f, int(end / 2) + 1)  # Chebyshev collocation, persistent
    inner = t[np.abs(t / 2 - np.round(t / 2)) > 1e-3]
    assert np.abs(seq.contact_force(inner) - ref.N(inner)).max() < 1e-9


@pytest.mark.parametrize(("alpha", "f"), [*CASES, (0.05, 0.3)])
def test_energy_stays_balanced(alpha, f):
    """Striker kinetic energy + rod energy = initial energy + work of f, where the rod
    energy is the integral of (w_t^2 + w_xi^2)/2 over the rod."""
    seq = impact_sequence(alpha, f, t_end=40.0 if alpha > 0.1 else 12.0)
    t = np.linspace(0.0, seq.t_end, 20001)[:-1]
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t)).max()
    assert np.abs(seq.energy.balance(t)).max() < 1e-10 * max(scale, 1.0)
    assert np.all(seq.energy.rod(t) >= -1e-14)


@pytest.mark.parametrize(("alpha", "f"), [(10.0, 5.0), (3.0, 1.0)])
def test_long_chattering_sequences_stay_exact(alpha, f):
    """With the antiderivative summed from the top, chattering sequences that the
    derivative-by-derivative sum lost near t ~ 57 and 61 (energy off by 89 at t = 100
    before the balance check existed) balance to rounding at t = 100."""
    seq = impact_sequence(alpha, f, t_end=100.0)
    assert len(seq.contacts) > 50
    t = np.linspace(0.0, 100.0, 4001)
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t))
    assert np.abs(seq.energy.balance(t) / scale).max() < 1e-10


def test_long_horizons_are_refused_not_silently_wrong():
    """Where the float64 pieces do cancel (a heavy, pressed striker by t ~ 258): refused,
    naming the inputs and the time reached; a horizon short of that time is accepted,
    and its balance holds there."""
    alpha, f = 40.0, 2.0
    with pytest.raises(ValueError, match=rf"alpha={alpha}, f={f}, t_end=300.0\).* t = ") as err:
        impact_sequence(alpha, f, t_end=300.0)
    reached = float(str(err.value).split("trusted up to t = ")[1].split(",")[0])
    assert 100.0 <= reached < 300.0
    seq = impact_sequence(alpha, f, t_end=reached)
    t = np.linspace(0.0, reached, 4001)[1:-1]
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t))
    ok = np.abs(seq.energy.balance(t)) < 1e-8 * scale
    assert ok.mean() > 0.99  # a sample may land on an event, where limits differ


def test_a_leaving_striker_runs_to_long_horizons():
    """f = 0: once the striker has left, the rod vibrates freely (no growth)."""
    for alpha in (0.3, 1.0, 20.0):
        seq = impact_sequence(alpha, 0.0, t_end=1000.0)
        assert seq.final
        assert seq.restitution == impact_sequence(alpha, 0.0, t_end=60.0).restitution
        t = np.linspace(900.0, 1000.0, 1001)
        assert np.abs(seq.energy.balance(t)).max() < 1e-12 * max(alpha, 1.0)


def test_a_piece_degree_overflow_names_the_inputs():
    with pytest.raises(ValueError, match=r"alpha=10000.0, f=0.0, t_end=400.0\).*t = .*degree"):
        impact_sequence(1e4, 0.0, t_end=400.0)


def test_rod_energy_is_the_integral_over_the_rod():
    """E_rod = int_0^1 (w_t^2 + w_xi^2)/2 from w = phi(t - xi) - phi(t + xi - 2),
    by quadrature of the wave at the rod's points."""
    seq = impact_sequence(1.0, 0.5, t_end=12.0)
    t, n = 9.3, 10**6
    xi = (np.arange(n) + 0.5) / n  # midpoint rule: g jumps inside the rod
    g = seq._tables.g
    w_t = g(t - xi) - g(t + xi - 2)
    w_x = -g(t - xi) - g(t + xi - 2)
    quad = 0.5 * np.mean(w_t**2 + w_x**2)
    assert quad == pytest.approx(seq.energy.rod(t), rel=1e-5)


def test_restitution_is_final_and_later_time_changes_nothing():
    short = impact_sequence(1.0, 0.0, t_end=20.0)
    long = impact_sequence(1.0, 0.0, t_end=200.0)
    assert short.final
    assert long.contacts == short.contacts
    assert long.restitution == short.restitution
    assert 0.0 < short.restitution < 1.0


def test_pressing_force_brings_the_striker_back():
    seq = impact_sequence(1.0, 0.5, t_end=20.0)
    assert len(seq.contacts) > 2
    assert math.isnan(seq.restitution)
    assert not seq.final
    starts = np.array([c[0] for c in seq.contacts[1:]])
    assert np.abs(seq.displacement(starts) - seq.rod_end_displacement(starts)).max() < 1e-10
    flight = 0.5 * (seq.contacts[0][1] + seq.contacts[1][0])
    assert np.all(seq.displacement(flight) <= seq.rod_end_displacement(flight))


def test_tensile_front_ends_contact_by_a_jump():
    """For f > 0 a contact can end with N jumping below zero (a tensile front)."""
    seq = impact_sequence(1.0, 0.5, t_end=20.0)
    before = [seq.contact_force(end - 1e-9) for _, end in seq.contacts[:-1]]
    assert max(before) > 0.5  # compressive just before the end: ended by a jump
    assert min(before) < 1e-6  # others end with N falling continuously to zero


def test_invalid_input_is_refused():
    with pytest.raises(ValueError, match="alpha"):
        impact_sequence(0.0, 0.0)
    with pytest.raises(ValueError, match="f must"):
        impact_sequence(1.0, -0.1)
    with pytest.raises(ValueError, match="t_end"):
        impact_sequence(1.0, 0.0, t_end=-1.0)
    with pytest.raises(TypeError, match="alpha"):
        impact_sequence("1", 0.0)
    assert impact_sequence(1.0, 0.0, kappa=100.0, t_end=5.0).kappa == 100.0  # finite kappa
    with pytest.raises(ValueError, match="max_contacts"):
        impact_sequence(1.0, 0.0, max_contacts=0)
    with pytest.raises(RuntimeError, match="max_contacts=5 contacts"):
        impact_sequence(1.0, 0.5, max_contacts=5)
    seq = impact_sequence(1.0, 0.0, t_end=5.0)
    with pytest.raises(ValueError, match="t_end"):
        seq.fixed_end_stress([1.0, 6.0])
    with pytest.raises(ValueError, match="t must be finite"):
        seq.energy.rod(np.nan)


def test_exp_poly_roots_finds_close_roots_and_exponential_ones():
    roots = [0.3, 0.3 + 1e-6, 0.9, 1.7]
    B = np.polynomial.polynomial.polyfromroots(roots)
    found = exp_poly_roots(np.zeros(0), B, 0.0, 2.0)
    assert np.abs(found - roots).max() < 1e-9
    # e^x - 1 - 2x: zero at 0 (excluded, the left end) and one more, by mpmath
    found = exp_poly_roots(np.array([1.0]), np.array([-1.0, -2.0]), 0.0, 3.0)
    root = mp.findroot(lambda x: mp.exp(x) - 1 - 2 * x, 1.3)
    assert found.size == 1
    assert found[0] == pytest.approx(float(root), abs=1e-14)
    # (x - 1)^2 e^x - 1e-3 has two roots near 1 +- 0.0316
    found = exp_poly_roots(np.array([1.0, -2.0, 1.0]), np.array([-1e-3]), 0.0, 2.0)
    assert found.size == 2
    assert exp_poly_roots(np.array([1.0]), np.array([0.5]), 0.0, 2.0).size == 0


@pytest.mark.parametrize(
    ("A", "B", "lo", "hi"),
    [
        # e^x - e x touches zero at 1 only (its minimum): 1 is a bisection node of [0, 2]
        ([1.0], [0.0, -math.e], 0.0, 2.0),
        ([1.0], [0.0, -math.e], 0.0, 1.7),
        # (x - 1/2)^2 touches at a node of [0, 1], (x - 1/3)^2 off the nodes
        ([], [0.25, -1.0, 1.0], 0.0, 1.0),
        ([], [1.0 / 9.0, -2.0 / 3.0, 1.0], 0.0, 1.0),
    ],
)
def test_exp_poly_roots_a_tangential_touch_is_no_sign_change(A, B, lo, hi):
    # F >= 0 throughout: check by dense sampling that nothing crosses
    x = np.linspace(lo, hi, 10001)
    F = np.exp(x) * np.polynomial.polynomial.polyval(
        x, A or [0.0]
    ) + np.polynomial.polynomial.polyval(x, B)
    assert F.min() > -1e-15
    assert exp_poly_roots(np.array(A), np.array(B), lo, hi).size == 0


def test_exp_poly_roots_a_crossing_on_a_node_is_still_a_root():
    """Simple and triple zeros exactly at the first bisection node 1/2 of [0, 1] change
    sign and are found exactly (first=True included)."""
    simple = np.array([-0.5, 1.0])
    triple = np.polynomial.polynomial.polyfromroots([0.5, 0.5, 0.5])
    for B in (simple, -simple, triple, -triple):
        assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0).tolist() == [0.5]
        assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0, first=True).tolist() == [0.5]
    # a tangency at a node followed by a crossing: only the crossing
    B = np.polynomial.polynomial.polyfromroots([0.5, 0.5, 0.8])
    assert exp_poly_roots(np.zeros(0), B, 0.0, 1.0) == pytest.approx([0.8], abs=1e-15)


def test_quick_reproduction_writes_the_sequence_figures_and_table(tmp_path):
    import csv

    import matplotlib

    matplotlib.use("Agg")
    from impactsym.results import rod_sequence as results

    messages: list[str] = []
    files = results.write(tmp_path, quick=True, progress=messages.append)
    names = {p.name for p in files}
    for stem in ("rod_sequence", "rod_sequence_stress", "rod_restitution"):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    for name in names:
        assert name in results.CAPTIONS or name.rsplit(".", 1)[0] in results.CAPTIONS
    with (tmp_path / "rod_restitution.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    light = rows[0]  # alpha = 0.05: one contact, e -> 2/e
    assert float(light["restitution"]) == pytest.approx(2 / math.e, abs=1e-9)
    assert all(0.0 < float(r["restitution"]) < 1.0 for r in rows)
    assert messages


def test_result_plots_itself():
    import matplotlib

    matplotlib.use("Agg")
    ax = impact_sequence(1.0, 0.5, t_end=6.0).plot()
    assert len(ax.lines) == 3


SHORTCUT_CASES = [(0.3, 0.0), (1.0, 0.5), (0.3, 1.0), (2.0, 0.3), (0.12, 0.6), (5.0, 0.9)]


@pytest.mark.parametrize(("alpha", "f"), SHORTCUT_CASES)
def test_cheap_certificates_change_no_event(alpha, f, monkeypatch):
    """The sequence with every piece searched by exp_poly_roots (the certificate
    exp_poly_positive switched off) and every antiderivative computed afresh (none
    carried over from a flight's copy) is the same, event for event, bit for bit."""
    import impactsym.rod.continuation as continuation

    fast = impact_sequence(alpha, f, t_end=30.0)
    monkeypatch.setattr(continuation, "exp_poly_positive", lambda A, B, hi, **_: False)
    monkeypatch.setattr(continuation, "_REUSE_ANTIDERIVATIVES", False)
    slow = impact_sequence(alpha, f, t_end=30.0)
    assert fast.contacts == slow.contacts
    assert fast.separation_speeds == slow.separation_speeds
    assert fast.max_fixed_end_stress == slow.max_fixed_end_stress
    assert np.array_equal(fast._tables.q, slow._tables.q)
    assert fast._flights == slow._flights


@pytest.mark.parametrize(("alpha", "f"), SHORTCUT_CASES)
def test_pruned_stress_maximum_is_the_exhaustive_one(alpha, f):
    """max_fixed_end_stress against a search of every piece (ends and zeros of
    Q' - Q, none skipped), and never below dense samples of the stress."""
    seq = impact_sequence(alpha, f, t_end=30.0)
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


def test_exp_antiderivative_is_the_exact_sum_to_rounding():
    """R_k = sum_j (k + j)!/k! Q_{k+j} (the coefficients of sum_j Q^(j), in 50-digit
    mpmath) to a few roundings of the terms' size, and int_0^x e^-s Q = R(0) - e^-x R(x)
    (mpmath quadrature)."""
    from impactsym.rod.continuation import _exp_antiderivative, _horner

    rng = np.random.default_rng(11)
    for n in [0, 1, 2, 5, 9, 10, 11, 17, 30, 60]:
        Q = rng.normal(size=n) * 3.0 ** rng.uniform(-3, 3, n) * (-2.0) ** np.arange(n)
        R = _exp_antiderivative(Q.tolist())
        assert len(R) == n
        with mp.workdps(50):
            for k in range(n):
                terms = [
                    mp.factorial(k + j) / mp.factorial(k) * mp.mpf(Q[k + j]) for j in range(n - k)
                ]
                size = float(sum(abs(t) for t in terms))
                assert abs(R[k] - float(mp.fsum(terms))) <= 4 * (n - k) * 2.3e-16 * size
        if n:
            x = 1.3
            exact = mp.quad(lambda s, Q=Q: mp.exp(-s) * mp.polyval(Q[::-1].tolist(), s), [0, x])
            closed = R[0] - math.exp(-x) * _horner(R, x)
            assert closed == pytest.approx(float(exact), rel=1e-12, abs=1e-12 * np.abs(R).max())


def test_one_pass_energy_balance_of_the_check_is_the_sum_of_its_parts():
    seq = impact_sequence(1.0, 0.5, t_end=12.0)
    t = np.linspace(0.0, 12.0, 501)
    e = seq.energy
    balance, work = e._rigid_balance_and_work(t)
    assert np.array_equal(balance, e.striker(t) + e.rod(t) - e.work(t) - 0.5)
    assert np.array_equal(balance, e.balance(t))
    assert np.array_equal(work, e.work(t))


def test_fewer_gauss_nodes_for_low_degree_pieces_change_only_rounding(monkeypatch):
    """Integrals of g and g^2 with 24/32/48 nodes by degree against 48 nodes everywhere,
    and single pieces against mpmath quadrature."""
    import impactsym.rod.continuation as continuation

    t = np.linspace(0.0, 29.9, 3001)
    fast = [impact_sequence(a, f, t_end=30.0) for a, f in SHORTCUT_CASES]
    monkeypatch.setattr(
        continuation, "_GAUSS_BY_DEGREE", [(96, np.polynomial.legendre.leggauss(48))]
    )
    for (alpha, f), seq in zip(SHORTCUT_CASES, fast, strict=True):
        slow = impact_sequence(alpha, f, t_end=30.0)
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
