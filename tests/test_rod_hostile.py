"""Hostile input to the rod wing (:mod:`impactsym.rod`): every probe is refused early by
a ``ValueError`` or ``TypeError`` whose message names the argument, before any work is
done (checked structurally: the solvers are replaced by traps), and memory follows what
happens, never a cap."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

import impactsym.rod.sequence as sequence_module
import impactsym.rod.sequence_elastic as elastic_module
import impactsym.rod.sequence_rigid as rigid_module
from impactsym.rod import (
    contact_force,
    contact_time,
    contact_time_map,
    displacement,
    impact_sequence,
    time_history,
)
from impactsym.rod.api import MAX_CONTACTS
from impactsym.rod.history import MAX_POINTS
from impactsym.rod.sequence import follow


@pytest.fixture
def no_work(monkeypatch):
    """Replace the sequence's step models and event loop by traps: a refusal must come
    before any of them is built or run."""

    def trap(*args, **kwargs):
        raise AssertionError("work started before the input was checked")

    monkeypatch.setattr(sequence_module, "follow", trap)
    monkeypatch.setattr(rigid_module, "RigidStep", trap)
    monkeypatch.setattr(elastic_module, "ElasticStep", trap)


SEQUENCE_PROBES = [
    # (keyword arguments over alpha=1, f=0.5; error; name in the message)
    ({"kappa": 1e300}, ValueError, "kappa"),  # was 107 s and 8.4 GB before the error
    ({"kappa": 1e9}, ValueError, "kappa"),  # beyond contact_time's rule as well
    ({"kappa": 0.0}, ValueError, "kappa"),
    ({"kappa": -1.0}, ValueError, "kappa"),
    ({"kappa": -math.inf}, ValueError, "kappa"),
    ({"kappa": math.nan}, ValueError, "kappa"),
    ({"kappa": "10"}, TypeError, "kappa"),
    ({"kappa": np.array([1.0, 2.0])}, TypeError, "kappa"),
    ({"alpha": 1e300}, ValueError, "alpha"),  # was accepted
    ({"alpha": 2e6}, ValueError, "alpha"),
    ({"alpha": 1e-11}, ValueError, "alpha"),
    ({"alpha": 0.0}, ValueError, "alpha"),
    ({"alpha": -1.0}, ValueError, "alpha"),
    ({"alpha": math.nan}, ValueError, "alpha"),
    ({"alpha": math.inf}, ValueError, "alpha"),
    ({"alpha": "1"}, TypeError, "alpha"),
    ({"alpha": None}, TypeError, "alpha"),
    ({"alpha": [1.0, 2.0]}, TypeError, "alpha"),
    ({"f": -0.1}, ValueError, "f must"),
    ({"f": math.nan}, ValueError, "f must"),
    ({"f": math.inf}, ValueError, "f must"),
    ({"f": 1e155}, ValueError, "f must"),  # energies ~f^2 overflowed silently
    ({"f": "0.5"}, TypeError, "f must"),
    ({"t_max": -1.0}, ValueError, "t_max"),
    ({"t_max": math.nan}, ValueError, "t_max"),
    ({"t_max": math.inf}, ValueError, "t_max"),
    ({"t_max": 1e5}, ValueError, "t_max"),
    ({"t_max": "40"}, TypeError, "t_max"),
    ({"t_max": 4.0, "t_end": 4.0}, TypeError, "t_max"),
    ({"max_contacts": 0}, ValueError, "max_contacts"),
    ({"max_contacts": -3}, ValueError, "max_contacts"),
    ({"max_contacts": np.int64(0)}, ValueError, "max_contacts"),
    ({"max_contacts": MAX_CONTACTS + 1}, ValueError, "max_contacts"),
    ({"max_contacts": 10**9}, ValueError, "max_contacts"),
    ({"max_contacts": 10**400}, ValueError, "max_contacts"),
    ({"max_contacts": np.uint64(2**63)}, ValueError, "max_contacts"),
    ({"max_contacts": 5.0}, TypeError, "max_contacts"),
    ({"max_contacts": math.inf}, TypeError, "max_contacts"),
    ({"max_contacts": True}, TypeError, "max_contacts"),
    ({"max_contacts": np.True_}, TypeError, "max_contacts"),
    ({"max_contacts": "10"}, TypeError, "max_contacts"),
    ({"max_contacts": None}, TypeError, "max_contacts"),
    ({"max_contacts": np.array([5])}, TypeError, "max_contacts"),
]


@pytest.mark.parametrize(("kwargs", "error", "name"), SEQUENCE_PROBES)
def test_impact_sequence_refuses_before_any_work(no_work, kwargs, error, name):
    args = {"alpha": 1.0, "f": 0.5, **kwargs}
    alpha, f = args.pop("alpha"), args.pop("f")
    with pytest.raises(error, match=name):
        impact_sequence(alpha, f, **args)


@pytest.mark.parametrize("count", [np.int64(7), np.int32(7), np.uint8(7), 7])
def test_max_contacts_takes_any_integer_type(count):
    """np.int64 was refused; every integral type gives the same sequence."""
    seq = impact_sequence(1.0, 0.5, t_max=10.0, max_contacts=count)
    assert seq == impact_sequence(1.0, 0.5, t_max=10.0, max_contacts=7)
    with pytest.raises(RuntimeError, match="max_contacts=1 contacts"):
        impact_sequence(1.0, 0.5, t_max=40.0, max_contacts=np.int16(1))


def test_memory_follows_the_contacts_not_the_cap():
    """The largest cap allocates nothing more than a small one: the lists grow with the
    contacts that occur (peak traced memory, not time)."""

    def peak(cap):
        tracemalloc.start()
        try:
            seq = impact_sequence(1.0, 0.5, t_max=20.0, max_contacts=cap)
            return seq, tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    small, small_peak = peak(100)
    large, large_peak = peak(MAX_CONTACTS)
    assert small == large
    assert large_peak < 1.5 * small_peak + 1e5


@pytest.mark.parametrize("kappa", [math.inf, 10.0])
def test_piece_budget_bounds_the_memory(kappa):
    """A run that would need more pieces of g than the budget is refused by name."""
    if math.isinf(kappa):
        model = rigid_module.RigidStep(1.0, 0.5, t_max=40.0)
    else:
        model = elastic_module.ElasticStep(1.0, 0.5, kappa=kappa, t_max=40.0)
    with pytest.raises(ValueError, match="more than 50 pieces of g before t = .* lower t_max"):
        follow(model, t_max=40.0, max_contacts=2000, max_pieces=50)


def test_a_finite_kappa_has_its_own_piece_budget(monkeypatch):
    """The budget impact_sequence gives follow: 20000 pieces for a contact spring (a
    light striker on a soft spring asked for 60000, minutes of work), MAX_PIECES rigid."""
    seen = []
    real = sequence_module.follow

    def spy(model, **kwargs):
        seen.append(kwargs["max_pieces"])
        return real(model, **kwargs)

    monkeypatch.setattr(sequence_module, "follow", spy)
    monkeypatch.setattr(elastic_module, "follow", spy)
    impact_sequence(1.0, 0.5, kappa=10.0, t_max=2.0)
    impact_sequence(1.0, 0.5, t_max=2.0)
    assert seen == [elastic_module.MAX_SPRING_PIECES, sequence_module.MAX_PIECES]
    assert elastic_module.MAX_SPRING_PIECES == 20_000


def test_the_stiffness_rule_is_contact_times():
    """Sequences refuse a spring exactly where contact_time does (fastest pole 1e8)."""
    for kappa in (1e8 + 10.0, 1e12):  # fastest pole kappa - 1 + ... at alpha = 1
        with pytest.raises(ValueError, match="kappa"):
            contact_time(1.0, 0.0, condition="force", kappa=kappa)
        with pytest.raises(ValueError, match="kappa"):
            impact_sequence(1.0, 0.0, kappa=kappa)


VECTOR_PROBES = [
    (lambda v: displacement(v, 1.0, 0.0), "t"),
    (lambda v: displacement(1.0, v, 0.0), "alpha"),
    (lambda v: displacement(1.0, 1.0, v), "f"),
    (lambda v: contact_force(1.0, 1.0, 0.0, kappa=v), "kappa"),
    (lambda v: contact_time(v, 0.0, condition="force"), "alpha"),
    (lambda v: contact_time(1.0, v, condition="position"), "f"),
    (lambda v: contact_time(1.0, 0.0, condition="force", kappa=v), "kappa"),
    (lambda v: contact_time_map(v, [0.0]), "alpha"),
    (lambda v: contact_time_map([1.0], v), "f"),
]


@pytest.mark.parametrize(("call", "name"), VECTOR_PROBES)
@pytest.mark.parametrize("bad", [[1.0, math.nan], [1.0, -math.inf], [2.0, -1.0], ["1", "2"]])
def test_vectorized_functions_name_the_bad_array(call, name, bad):
    if name == "t" and bad == [2.0, -1.0]:
        return  # a negative time is before the impact: y = 0 there
    error = TypeError if isinstance(bad[0], str) else ValueError
    with pytest.raises(error, match=f"^{name} "):
        call(np.array(bad, dtype=object if error is TypeError else float))


@pytest.mark.parametrize(("call", "name"), VECTOR_PROBES[:7])
def test_empty_arrays_give_empty_results(call, name):
    assert np.asarray(call(np.array([]))).shape == (0,)


def test_empty_map_axes_give_empty_maps():
    study = contact_time_map([], [0.0, 1.0])
    assert study.force.shape == study.position.shape == (2, 0)
    assert contact_time_map([0.5], []).force.shape == (0, 1)


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"kappa": "x"}, TypeError, "kappa"),  # was an anonymous ufunc error
        ({"kappa": [1.0, 2.0]}, TypeError, "kappa"),  # was "truth value ... ambiguous"
        ({"kappa": 1e300}, ValueError, "kappa"),
        ({"kappa": math.nan}, ValueError, "kappa"),
        ({"t_max": math.nan}, ValueError, "t_max"),
        ({"t_max": 1e300}, ValueError, "t_max"),
    ],
)
def test_contact_time_map_names_its_scalars(kwargs, error, name):
    with pytest.raises(error, match=name):
        contact_time_map([1.0], [0.0], **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"n_points": 10**12}, ValueError, "n_points"),  # was a 7 TiB MemoryError
        ({"n_points": MAX_POINTS + 1}, ValueError, "n_points"),
        ({"n_points": 10**400}, ValueError, "n_points"),
        ({"n_points": True}, ValueError, "n_points"),
        ({"t_max": 1e300}, ValueError, "t_max"),  # was "Maximum allowed size exceeded"
        ({"t_max": math.inf}, ValueError, "t_max"),
        ({"kappa": 20.0, "t_max": 30.0}, ValueError, "t_max"),
        ({"kappa": [1.0, 2.0]}, TypeError, "kappa"),
        ({"kappa": 1e300}, ValueError, "kappa"),
        ({"alpha": 1e300}, ValueError, "alpha"),
        ({"f": math.nan}, ValueError, "f must"),
    ],
)
def test_time_history_refuses_before_sampling(monkeypatch, kwargs, error, name):
    import impactsym.rod.history as history

    def trap(*args, **kw):
        raise AssertionError("sampled before the input was checked")

    monkeypatch.setattr(history, "_sample_times", trap)
    args = {"alpha": 1.0, "f": 0.0, **kwargs}
    alpha, f = args.pop("alpha"), args.pop("f")
    with pytest.raises(error, match=name):
        time_history(alpha, f, **args)


def test_time_history_takes_numpy_integers():
    h = time_history(1.0, 0.0, t_max=4.0, n_points=np.int64(20))
    assert h == time_history(1.0, 0.0, t_max=4.0, n_points=20)


def test_a_nan_energy_residual_is_refused(monkeypatch):
    """check_balance refused residuals above the bound but passed NaN ones (an
    overflowing f came back as a result)."""
    seq = impact_sequence(1.0, 0.5, t_max=6.0)

    class Broken:
        def balance_and_work(self, t):
            return np.full(np.shape(t), np.nan), np.zeros(np.shape(t))

    monkeypatch.setattr(type(seq), "energy", property(lambda self: Broken()))
    with pytest.raises(ValueError, match="no longer exact"):
        sequence_module.check_balance(seq)


def test_time_histories_compare_by_value_and_hash():
    a = time_history(0.5, 0.0, t_max=4.0, n_points=30)
    b = time_history(0.5, 0.0, t_max=4.0, n_points=30)
    assert a == b
    assert hash(a) == hash(b)
    assert a != time_history(0.5, 0.0, t_max=4.0, n_points=31)
