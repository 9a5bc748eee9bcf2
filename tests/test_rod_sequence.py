"""Tests of the rod impact sequence's event loop, result objects and energy,
:mod:`impactsym.rod.sequence` (through :func:`impactsym.rod.impact_sequence`), rigid contact
and a contact spring alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym.rod import ElasticRodImpactSequence, RodImpactSequence, impact_sequence
from impactsym.rod.sequence import ElasticSequenceEnergy, RodSequenceEnergy

CASES = [(0.3, 0.0), (1.0, 0.0), (20.0, 0.0), (1.0, 0.5), (0.3, 1.0), (2.0, 0.3)]


@pytest.mark.parametrize(("alpha", "f"), [*CASES, (0.05, 0.3)])
def test_energy_stays_balanced(alpha, f):
    """Striker kinetic energy + rod energy = initial energy + work of f, where the rod
    energy is the integral of (w_t^2 + w_xi^2)/2 over the rod."""
    seq = impact_sequence(alpha, f, t_max=40.0 if alpha > 0.1 else 12.0)
    t = np.linspace(0.0, seq.t_max, 20001)[:-1]
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t)).max()
    assert np.abs(seq.energy.balance(t)).max() < 1e-10 * max(scale, 1.0)
    assert np.all(seq.energy.rod(t) >= -1e-14)


def test_long_horizons_are_refused_not_silently_wrong():
    """Where the float64 pieces do cancel (a heavy, pressed striker by t ~ 258): refused,
    naming the inputs and the time reached; a horizon short of that time is accepted,
    and its balance holds there."""
    alpha, f = 40.0, 2.0
    with pytest.raises(ValueError, match=rf"alpha={alpha}, f={f}, t_max=300.0\).* t = ") as err:
        impact_sequence(alpha, f, t_max=300.0)
    reached = float(str(err.value).split("trusted up to t = ")[1].split(",")[0])
    assert 100.0 <= reached < 300.0
    seq = impact_sequence(alpha, f, t_max=reached)
    t = np.linspace(0.0, reached, 4001)[1:-1]
    scale = 0.5 * alpha + f * np.abs(seq.displacement(t))
    ok = np.abs(seq.energy.balance(t)) < 1e-8 * scale
    assert ok.mean() > 0.99  # a sample may land on an event, where limits differ


def test_a_leaving_striker_runs_to_long_horizons():
    """f = 0: once the striker has left, the rod vibrates freely (no growth)."""
    for alpha in (0.3, 1.0, 20.0):
        seq = impact_sequence(alpha, 0.0, t_max=1000.0)
        assert seq.final
        assert seq.restitution == impact_sequence(alpha, 0.0, t_max=60.0).restitution
        t = np.linspace(900.0, 1000.0, 1001)
        assert np.abs(seq.energy.balance(t)).max() < 1e-12 * max(alpha, 1.0)


def test_a_piece_degree_overflow_names_the_inputs():
    with pytest.raises(ValueError, match=r"alpha=10000.0, f=0.0, t_max=400.0\).*t = .*degree"):
        impact_sequence(1e4, 0.0, t_max=400.0)


def test_rod_energy_is_the_integral_over_the_rod():
    """E_rod = int_0^1 (w_t^2 + w_xi^2)/2 from w = phi(t - xi) - phi(t + xi - 2),
    by quadrature of the wave at the rod's points."""
    seq = impact_sequence(1.0, 0.5, t_max=12.0)
    t, n = 9.3, 10**6
    xi = (np.arange(n) + 0.5) / n  # midpoint rule: g jumps inside the rod
    g = seq._tables.g
    w_t = g(t - xi) - g(t + xi - 2)
    w_x = -g(t - xi) - g(t + xi - 2)
    quad = 0.5 * np.mean(w_t**2 + w_x**2)
    assert quad == pytest.approx(seq.energy.rod(t), rel=1e-5)


def test_restitution_is_final_and_later_time_changes_nothing():
    short = impact_sequence(1.0, 0.0, t_max=20.0)
    long = impact_sequence(1.0, 0.0, t_max=200.0)
    assert short.final
    assert long.contacts == short.contacts
    assert long.restitution == short.restitution
    assert 0.0 < short.restitution < 1.0


def test_invalid_input_is_refused():
    with pytest.raises(ValueError, match="alpha"):
        impact_sequence(0.0, 0.0)
    with pytest.raises(ValueError, match="f must"):
        impact_sequence(1.0, -0.1)
    with pytest.raises(ValueError, match="t_max"):
        impact_sequence(1.0, 0.0, t_max=-1.0)
    with pytest.raises(TypeError, match="alpha"):
        impact_sequence("1", 0.0)
    assert impact_sequence(1.0, 0.0, kappa=100.0, t_max=5.0).kappa == 100.0  # finite kappa
    with pytest.raises(ValueError, match="max_contacts"):
        impact_sequence(1.0, 0.0, max_contacts=0)
    with pytest.raises(RuntimeError, match="max_contacts=5 contacts"):
        impact_sequence(1.0, 0.5, max_contacts=5)
    seq = impact_sequence(1.0, 0.0, t_max=5.0)
    with pytest.raises(ValueError, match="t_max"):
        seq.fixed_end_stress([1.0, 6.0])
    with pytest.raises(ValueError, match="t must be finite"):
        seq.energy.rod(np.nan)


def test_result_plots_itself():
    import matplotlib

    matplotlib.use("Agg")
    ax = impact_sequence(1.0, 0.5, t_max=6.0).plot()
    assert len(ax.lines) == 3


def test_one_pass_energy_balance_of_the_check_is_the_sum_of_its_parts():
    seq = impact_sequence(1.0, 0.5, t_max=12.0)
    t = np.linspace(0.0, 12.0, 501)
    e = seq.energy
    balance, work = e.balance_and_work(t)
    assert np.array_equal(balance, e.striker(t) + e.rod(t) - e.work(t) - 0.5)
    assert np.array_equal(balance, e.balance(t))
    assert np.array_equal(work, e.work(t))


def test_result_type_and_attributes():
    seq = impact_sequence(1.0, 0.0, kappa=50.0, t_max=10.0)
    assert isinstance(seq, ElasticRodImpactSequence)
    assert seq.kappa == 50.0
    assert seq.t_max == 10.0
    assert seq.contacts[0][0] == 0.0
    assert seq.contact_force(0.0) == 0.0  # the spring starts unloaded
    assert seq.velocity(0.0) == pytest.approx(1.0, abs=1e-15)
    with pytest.raises(ValueError, match="t_max"):
        seq.fixed_end_stress(11.0)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"kappa": 0.0}, ValueError, "kappa"),
        ({"kappa": -1.0}, ValueError, "kappa"),
        ({"kappa": math.nan}, ValueError, "kappa"),
        ({"kappa": np.array([1.0, 2.0])}, TypeError, "kappa"),
        ({"kappa": "10"}, TypeError, "kappa"),
        ({"kappa": 10.0, "t_max": -1.0}, ValueError, "t_max"),
        ({"kappa": 10.0, "t_end": -1.0}, ValueError, "t_max"),
        ({"kappa": 10.0, "max_contacts": 0}, ValueError, "max_contacts"),
    ],
)
def test_bad_input_is_refused(kwargs, error, match):
    with pytest.raises(error, match=match):
        impact_sequence(1.0, 0.0, **kwargs)


def test_chatter_limit_raises():
    with pytest.raises(RuntimeError, match="max_contacts"):
        impact_sequence(0.3, 0.3, kappa=100.0, t_max=20.0, max_contacts=3)


def test_plot_shows_the_spring_energy():
    ax = impact_sequence(1.0, 0.3, kappa=50.0, t_max=6.0).plot()
    labels = [line.get_label() for line in ax.lines]
    assert any("spring" in label for label in labels)
    assert r"\kappa = 50" in ax.get_title()


@pytest.mark.parametrize("kappa", [math.inf, 2.0])
def test_time_functions_at_t_end_are_left_limits(kappa):
    # a wave front reaches the struck end exactly at t_end = 40 (g' jumps at every even
    # s); evaluating g(t_end) from the last piece but g(t_end - 2) from the piece that
    # starts there mixed one-sided limits and broke the energy balance by 4e-3
    seq = impact_sequence(1.0, 0.5, kappa=kappa, t_max=40.0)
    before = 40.0 - 1e-9
    for name in ("velocity", "displacement", "contact_force"):
        at_end, left = getattr(seq, name)(40.0), getattr(seq, name)(before)
        assert abs(at_end - left) < 1e-7, name
    assert abs(seq.energy.balance(40.0)) < 1e-11


def test_t_end_is_the_former_name_of_t_max():
    """``t_end=`` is still accepted (keyword only) and gives the same sequence; giving
    both is refused; the result's ``t_end`` reads ``t_max``."""
    for kappa in (math.inf, 20.0):
        new = impact_sequence(1.0, 0.5, kappa=kappa, t_max=8.0)
        old = impact_sequence(1.0, 0.5, kappa=kappa, t_end=8.0)
        assert old.contacts == new.contacts
        assert old.separation_velocities == new.separation_velocities
        assert old.separation_speeds == old.separation_velocities  # former name, readable
        assert old.t_max == old.t_end == 8.0
    assert impact_sequence(1.0, 0.0).t_max == 40.0
    with pytest.raises(TypeError, match="t_max or its former name t_end"):
        impact_sequence(1.0, 0.0, t_max=5.0, t_end=5.0)
    with pytest.raises(TypeError):
        impact_sequence(1.0, 0.0, math.inf, 5.0)  # keyword only


def test_result_classes_and_energies_by_contact_law():
    rigid, spring = (
        impact_sequence(1.0, 0.0, t_max=5.0),
        impact_sequence(1.0, 0.0, kappa=9.0, t_max=5.0),
    )
    assert type(rigid) is RodImpactSequence
    assert type(rigid.energy) is RodSequenceEnergy
    assert type(spring) is ElasticRodImpactSequence
    assert type(spring.energy) is ElasticSequenceEnergy
    t = np.linspace(0.0, 4.9, 50)
    balance, work = spring.energy.balance_and_work(t)
    assert np.array_equal(balance, spring.energy.balance(t))
    assert np.array_equal(work, spring.energy.work(t))


@pytest.mark.parametrize("kappa", [math.inf, 20.0])
def test_results_compare_by_value_and_hash(kappa):
    """== raised on the arrays inside (truth value ambiguous) and hash on the lists: now
    == compares values, NaN equal to NaN (restitution is NaN for f > 0), and equal
    results hash alike."""
    a = impact_sequence(1.0, 0.5, kappa=kappa, t_max=10.0)
    b = impact_sequence(1.0, 0.5, kappa=kappa, t_max=10.0)
    assert a is not b
    assert math.isnan(a.restitution)
    assert a == b
    assert (a != b) is False
    assert hash(a) == hash(b)
    assert len({a, b}) == 1
    assert a.energy == b.energy
    assert hash(a.energy) == hash(b.energy)
    other = impact_sequence(1.0, 0.4, kappa=kappa, t_max=10.0)
    assert a != other
    assert a != impact_sequence(1.0, 0.5, kappa=kappa, t_max=9.0)
    assert a != "a sequence"
    assert a.energy != a


def test_value_equality_sees_every_field():
    from impactsym.records import values_equal

    tables = impact_sequence(1.0, 0.0, t_max=10.0)._tables
    changed = tables.__class__(**{**vars(tables), "p": np.nextafter(tables.p, np.inf)})
    assert values_equal(tables, changed) is False  # a change in the last place counts
    assert values_equal(tables, tables.__class__(**vars(tables)))
    assert values_equal([1.0, (2.0, math.nan)], [1.0, (2.0, math.nan)])
    assert not values_equal([1.0, 2.0], (1.0, 2.0))  # a list is no tuple
    assert not values_equal(np.zeros((2, 1)), np.zeros(2))
