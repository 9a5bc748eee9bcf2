"""Contact times, restitution and the stick boundary (paper section 2), checked against
references that share nothing with the derivation: ODE integration with event
detection, a 40-digit matrix-exponential solution, and textbook closed forms."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from conftest import CODE
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from references.oscillator import contact_function, first_root, refine_root, state
from scipy.integrate import solve_ivp

from impactsym import contact_time, restitution, stick_boundary
from impactsym.contact import contact_surface, physical_contact

CONDITIONS = ("position", "force")


def ode_contact(damping: float, force: float, condition: str, t_max: float = 400.0):
    """Contact time and restitution by integrating the ODE with event detection."""

    def rhs(_t, y):
        return [y[1], 2 * damping * force - 2 * damping * y[1] - y[0]]

    def event(_t, y):
        return y[0] if condition == "position" else 2 * damping * y[1] + y[0]

    event.terminal, event.direction = True, -1
    sol = solve_ivp(
        rhs, (0.0, t_max), [0.0, 1.0], method="DOP853", events=event, rtol=1e-12, atol=1e-14
    )
    if sol.t_events[0].size == 0:
        return math.inf, 0.0
    speed = -sol.y_events[0][0][1]
    if abs(speed) < 1e-9:  # a "crossing" of a state decayed to integrator noise
        return math.inf, 0.0
    return sol.t_events[0][0], speed


def random_points_away_from_boundary(condition: str, count: int, seed: int):
    rng = np.random.default_rng(seed)
    damping = np.concatenate([rng.uniform(0, 1, count), rng.uniform(1, 4, count // 2)])
    force = rng.uniform(0, 3, damping.size)
    force[::7] = 0.0
    d_star = stick_boundary(force, condition=condition)
    keep = np.abs(damping - d_star) > 0.02 * np.minimum(d_star, 1.0)
    return damping[keep], force[keep]


@pytest.mark.parametrize("condition", CONDITIONS)
def test_contact_time_and_restitution_match_ode_integration(condition):
    damping, force = random_points_away_from_boundary(condition, 120, seed=7)
    tau_c = contact_time(damping, force, condition=condition)
    e = restitution(damping, force, condition=condition)
    assert np.isfinite(tau_c).sum() > 30  # both outcomes
    assert np.isinf(tau_c).sum() > 30
    for d, fr, t, ei in zip(damping, force, tau_c, e, strict=True):
        t_ref, e_ref = ode_contact(d, fr, condition)
        if math.isinf(t_ref):
            assert math.isinf(t), (d, fr)
            assert ei == 0.0
        else:
            assert t == pytest.approx(t_ref, rel=1e-8), (d, fr)
            assert ei == pytest.approx(e_ref, rel=1e-7, abs=1e-10), (d, fr)


@pytest.mark.parametrize("condition", CONDITIONS)
def test_contact_time_matches_40_digit_reference_to_1e_12(condition):
    damping, force = random_points_away_from_boundary(condition, 60, seed=11)
    tau_c = contact_time(damping, force, condition=condition)
    release = np.isfinite(tau_c)
    for d, fr, t in zip(damping[release], force[release], tau_c[release], strict=True):
        reference = refine_root(t, d, fr, condition)
        assert abs(t - float(reference)) <= 1e-12 * float(reference), (d, fr)


@pytest.mark.parametrize(
    ("d", "fr", "condition"),
    [
        (0.05, 0.3, "force"),
        (0.15, 1.0, "position"),
        (0.7, 0.01, "position"),
        (2.5, 0.0, "force"),
        (1.0, 0.01, "force"),
        (0.7, 0.05, "force"),
        (0.4, 1.0, "position"),
        (1.0, 0.2, "force"),
    ],
)
def test_contact_time_is_the_first_root(d, fr, condition):
    reference = first_root(d, fr, condition, t_max=40.0, samples=400)
    if reference is None:  # no sign change in 40 natural time units: sticking
        assert contact_time(d, fr, condition=condition) == math.inf
    else:
        assert contact_time(d, fr, condition=condition) == pytest.approx(
            float(reference), rel=1e-13
        )


def test_undamped_limit_is_half_a_period_with_full_rebound():
    for condition in CONDITIONS:
        assert contact_time(0.0, [0.0, 1.0, 50.0], condition=condition).tolist() == [math.pi] * 3
        np.testing.assert_allclose(
            restitution(0.0, [0.0, 7.0], condition=condition), 1.0, rtol=1e-14
        )
        # weak damping: tau_c -> pi continuously
        assert contact_time(1e-9, 0.3, condition=condition) == pytest.approx(math.pi, rel=1e-8)


def test_textbook_results_without_pressing_force():
    damping = np.array([0.01, 0.2, 0.5, 0.8, 0.99])
    w = np.sqrt(1 - damping**2)
    # position: z = exp(-D t) sin(w t)/w returns to zero at pi/w, e = exp(-D pi / w)
    np.testing.assert_allclose(
        contact_time(damping, 0.0, condition="position"), np.pi / w, rtol=1e-13
    )
    np.testing.assert_allclose(
        restitution(damping, 0.0, condition="position"), np.exp(-damping * np.pi / w), rtol=1e-12
    )
    # force: 2 D z' + z = 0  <=>  tan(w t) = -2 D w / (1 - 2 D^2)
    expected = (np.pi - np.arctan2(2 * damping * w, 1 - 2 * damping**2)) / w
    np.testing.assert_allclose(contact_time(damping, 0.0, condition="force"), expected, rtol=1e-13)
    # over-damped force condition: exp(2 s t) = (2D^2 - 1 + 2Ds) / (2D^2 - 1 - 2Ds)
    big = np.array([1.5, 3.0, 10.0])
    s = np.sqrt(big**2 - 1)
    ratio = (2 * big**2 - 1 + 2 * big * s) / (2 * big**2 - 1 - 2 * big * s)
    np.testing.assert_allclose(
        contact_time(big, 0.0, condition="force"), np.log(ratio) / (2 * s), rtol=1e-12
    )
    # critically and over-damped bodies never leave under the position condition
    assert np.isinf(contact_time([1.0, 2.0, 30.0], 0.0, condition="position")).all()


def test_large_damping_keeps_full_accuracy():
    for d in (30.0, 1e3):
        t = contact_time(d, 0.0, condition="force")
        assert abs(t - float(refine_root(t, d, 0.0, "force", dps=60))) <= 1e-12 * t


def boundary_reference(fr: float, condition: str, guess: float) -> float:
    """D at which the first local minimum of g (found at 40 digits) touches zero."""

    def minimum_of_g(d):
        def slope(t):  # g' from the state: z' (position) or 2 D z'' + z' (force)
            z, v = state(t, d, fr)
            return v if condition == "position" else 2 * d * (2 * d * fr - 2 * d * v - z) + v

        h = (mp.pi / mp.sqrt(1 - d**2) if d < 1 else mp.mpf(2)) / 20
        t, previous = h / 100, slope(h / 100)
        for _ in range(400):  # scan g' for its first upward zero, then polish it
            value = slope(t + h)
            if previous < 0 <= value:
                t_min = mp.findroot(slope, (t, t + h), solver="anderson")
                return contact_function(t_min, d, fr, condition)
            t, previous = t + h, value
        raise AssertionError(f"no local minimum of g found for D = {d}")

    with mp.workdps(40):
        return float(
            mp.findroot(
                minimum_of_g,
                (mp.mpf(guess) * (1 - mp.mpf("1e-7")), mp.mpf(guess) * (1 + mp.mpf("1e-7"))),
                solver="secant",
            )
        )


@pytest.mark.parametrize("condition", CONDITIONS)
def test_stick_boundary_matches_40_digit_reference(condition):
    for fr in (0.01, 0.5, 10.0):
        d_star = stick_boundary(fr, condition=condition)
        assert abs(d_star - boundary_reference(fr, condition, d_star)) <= 1e-12 * d_star


def test_stick_boundary_limits_at_zero_pressing_force():
    assert stick_boundary(0.0, condition="position") == 1.0
    assert stick_boundary(0.0, condition="force") == math.inf
    small = np.array([1e-2, 1e-4, 1e-8, 1e-20, 1e-50, 1e-100])
    position = stick_boundary(small, condition="position")
    force = stick_boundary(small, condition="force")
    assert np.all(np.diff(position) > 0)
    assert np.all(position < 1)
    assert np.all(np.diff(force) > 0)
    # position: the first minimum 2Df - O(exp(-pi/omega)) touches zero when
    # exp(-pi/omega) ~ f, so 1 - D* ~ pi^2 / (2 ln^2(1/f)) -> 0, slowly
    ratio = (1 - position) * np.log(1 / small) ** 2 / (np.pi**2 / 2)
    assert np.all((ratio[2:] > 0.8) & (ratio[2:] < 1.3))
    # force: D* grows without bound like 1/(2 f^(1/4))
    np.testing.assert_allclose(force[2:] * small[2:] ** 0.25, 0.5, rtol=2e-3)


@settings(max_examples=60, deadline=None)
@given(
    fr=st.floats(1e-3, 50.0),
    side=st.sampled_from([-1, 1]),
    rel=st.floats(1e-6, 0.5),
    condition=st.sampled_from(CONDITIONS),
)
def test_sticks_exactly_beyond_the_boundary(fr, side, rel, condition):
    d_star = stick_boundary(fr, condition=condition)
    d = d_star * (1 + side * rel)
    tau_c = contact_time(d, fr, condition=condition)
    assert math.isinf(tau_c) == (side > 0)
    assert (restitution(d, fr, condition=condition) == 0.0) == (side > 0)


@settings(max_examples=40, deadline=None)
@given(fr=st.floats(0.0, 0.02), eps=st.floats(1e-12, 1e-6))
def test_force_contact_time_is_continuous_across_critical_damping(fr, eps):
    at_one = contact_time(1.0, fr, condition="force")
    assert math.isfinite(at_one)
    for d in (1 - eps, 1 + eps):
        assert contact_time(d, fr, condition="force") == pytest.approx(
            at_one, rel=20 * eps, abs=1e-12
        )


@settings(max_examples=40, deadline=None)
@given(d=st.floats(0.0, 20.0), fr=st.floats(0.0, 20.0), condition=st.sampled_from(CONDITIONS))
def test_contact_time_is_positive_and_restitution_in_unit_interval(d, fr, condition):
    t = contact_time(d, fr, condition=condition)
    e = restitution(d, fr, condition=condition)
    assert t > 0
    assert 0.0 <= e <= 1.0 + 1e-12


def test_position_contact_grows_without_bound_towards_critical_damping():
    times = contact_time(1 - np.logspace(-2, -10, 5), 0.0, condition="position")
    assert np.all(np.diff(times) > 0)
    assert times[-1] > 1e4


def test_broadcasting_shapes_and_scalar_types():
    out = contact_time(np.array([[0.1], [0.2]]), np.array([0.0, 0.5, 1.0]), condition="force")
    assert out.shape == (2, 3)
    assert out.dtype == np.float64
    assert isinstance(contact_time(0.1, 0.2, condition="force"), float)
    assert isinstance(restitution(0.1, 0.2, condition="force"), float)
    assert isinstance(stick_boundary(0.3, condition="force"), float)
    assert stick_boundary([0.1, 0.2], condition="force").shape == (2,)
    assert contact_time(np.zeros((0,)), 0.2, condition="force").shape == (0,)


@pytest.mark.parametrize("function", [contact_time, restitution])
def test_bad_input_is_rejected_with_the_argument_named(function):
    with pytest.raises(ValueError, match="D must be >= 0, got -0.1"):
        function(-0.1, 0.2, condition="force")
    with pytest.raises(ValueError, match="f must be finite, got nan"):
        function(0.1, float("nan"), condition="force")
    with pytest.raises(ValueError, match="D must be finite, got inf"):
        function(np.inf, 0.2, condition="force")
    with pytest.raises(ValueError, match=r"f must be >= 0, got -1.0 \(at index \(1,\)"):
        function(0.1, [0.0, -1.0], condition="force")
    with pytest.raises(TypeError, match="D must be a real number"):
        function("0.1", 0.2, condition="force")
    with pytest.raises(TypeError, match="f must be a real number"):
        function(0.1, 1 + 2j, condition="force")
    with pytest.raises(TypeError, match="f must be a real number"):
        function(0.1, None, condition="force")
    with pytest.raises(ValueError, match="condition must be 'position' or 'force'"):
        function(0.1, 0.2, condition="Force")
    with pytest.raises(TypeError, match="condition must be the string"):
        function(0.1, 0.2, condition=1)


def test_stick_boundary_rejects_bad_input():
    with pytest.raises(ValueError, match="f must be >= 0"):
        stick_boundary(-1.0, condition="force")
    with pytest.raises(ValueError, match="f must be finite"):
        stick_boundary(np.inf, condition="force")
    with pytest.raises(ValueError, match="condition"):
        stick_boundary(0.5, condition="speed")


def test_physical_contact_scales_with_units():
    base = physical_contact(m=2.0, k=50.0, d=3.0, v0=0.7, F=4.0, condition="force")
    assert base.omega0 == pytest.approx(5.0)
    assert pytest.approx(3.0 / (2 * 10.0)) == base.D
    assert base.f == pytest.approx(4.0 / (3.0 * 0.7))
    assert base.contact_time == pytest.approx(
        contact_time(base.D, base.f, condition="force") / 5.0, rel=1e-15
    )
    # the same impact with time measured in milliseconds (lengths and masses unchanged):
    # k -> k/lam^2, d -> d/lam, v0 -> v0/lam, F -> F/lam^2 leave D, f unchanged, t_c -> lam t_c
    lam = 1e3
    scaled = physical_contact(
        m=2.0, k=50.0 / lam**2, d=3.0 / lam, v0=0.7 / lam, F=4.0 / lam**2, condition="force"
    )
    assert scaled.contact_time == pytest.approx(base.contact_time * lam, rel=1e-12)
    assert scaled.restitution == pytest.approx(base.restitution, rel=1e-12)


def test_physical_contact_matches_ode_in_physical_units():
    m, k, d, v0, F = 1.5, 200.0, 6.0, 0.8, 1.0  # D = 0.17 < D*(f = 0.21)

    def rhs(_t, y):
        return [y[1], (F - d * y[1] - k * y[0]) / m]

    for condition in CONDITIONS:

        def event(_t, y, c=condition):
            return y[0] if c == "position" else d * y[1] + k * y[0]

        event.terminal, event.direction = True, -1
        sol = solve_ivp(
            rhs, (0, 10), [0.0, v0], events=event, rtol=1e-12, atol=1e-14, method="DOP853"
        )
        result = physical_contact(m, k, d, v0, F, condition=condition)
        assert result.contact_time == pytest.approx(sol.t_events[0][0], rel=1e-8)
        assert result.restitution == pytest.approx(-sol.y_events[0][0][1] / v0, rel=1e-7)
        assert not result.sticks


def test_undamped_contact_with_pressing_force_is_solved_in_closed_form():
    m, k, v0, F = 1.0, 4.0, 0.5, 3.0
    result = physical_contact(m, k, 0.0, v0, F, condition="force")
    assert result.D == 0.0
    assert result.f == math.inf
    assert result.restitution == 1.0
    sol = solve_ivp(
        lambda _t, y: [y[1], (F - k * y[0]) / m],
        (0, 20),
        [0.0, v0],
        events=lambda _t, y: y[0],
        rtol=1e-12,
        atol=1e-14,
        method="DOP853",
    )
    assert result.contact_time == pytest.approx(sol.t_events[0][1], rel=1e-9)  # [0] is the impact


def test_physical_contact_broadcasts_and_validates():
    result = physical_contact(1.0, 1.0, np.array([0.0, 0.5, 40.0]), 1.0, 0.1, condition="force")
    assert result.sticks.tolist() == [False, False, True]
    with pytest.raises(ValueError, match="m must be > 0, got 0.0"):
        physical_contact(0.0, 1.0, 1.0, 1.0, condition="force")
    with pytest.raises(ValueError, match="k must be > 0"):
        physical_contact(1.0, -1.0, 1.0, 1.0, condition="force")
    with pytest.raises(ValueError, match="d must be >= 0"):
        physical_contact(1.0, 1.0, -1.0, 1.0, condition="force")
    with pytest.raises(ValueError, match="v0 must be > 0"):
        physical_contact(1.0, 1.0, 1.0, 0.0, condition="force")
    with pytest.raises(ValueError, match="F must be finite"):
        physical_contact(1.0, 1.0, 1.0, 1.0, np.nan, condition="force")
    with pytest.raises(ValueError, match="condition"):
        physical_contact(1.0, 1.0, 1.0, 1.0, 0.0, condition="none")


# -- hostile input: every argument named, every limit right, no string run as code ----------
SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def _attempt(call):
    """``(value, None)``, or ``(None, error)`` for a ``ValueError``."""
    try:
        return call(), None
    except ValueError as exc:
        return None, exc


SECTION2 = {
    "contact_time": lambda D, f: contact_time(D, f, condition="force"),
    "restitution": lambda D, f: restitution(D, f, condition="position"),
    "contact_surface": lambda D, f: contact_surface(D, f, condition="force"),
}


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize("function", sorted(SECTION2))
@pytest.mark.parametrize(
    ("D", "f", "error", "pattern"),
    [
        (math.nan, 0.5, ValueError, "^D must be finite, got nan"),
        (0.5, math.inf, ValueError, "^f must be finite, got inf"),
        (-1.0, 0.5, ValueError, "^D must be >= 0, got -1.0"),
        (0.5, -1e-300, ValueError, "^f must be >= 0"),
        (CODE, 0.5, TypeError, "^D must be a real number"),
        (0.5, True, TypeError, "^f must be a real number"),
        (0.5, 1j, TypeError, "^f must be a real number"),
        (None, 0.5, TypeError, "^D must be a real number"),
        ([0.1, 0.2, 0.3], [0.1, 0.2], ValueError, r"^D \(shape \(3,\)\) and f \(shape \(2,\)\)"),
        ([0.1, math.nan], 0.5, ValueError, r"D must be finite, got nan \(at index \(1,\)"),
    ],
)
def test_section2_functions_name_the_bad_argument(function, D, f, error, pattern):
    with pytest.raises(error, match=pattern):
        SECTION2[function](D, f)


@pytest.mark.usefixtures("no_code_runs")
def test_condition_must_be_named_and_keyword_only():
    with pytest.raises(ValueError, match="condition must be 'position' or 'force'"):
        contact_time(0.5, 0.5, condition=CODE)
    with pytest.raises(TypeError):
        contact_time(0.5, 0.5, "force")  # keyword-only


@SETTINGS
@given(
    log_f=st.floats(-320, 300),
    condition=st.sampled_from(["force", "position"]),
    side=st.sampled_from([1 - 1e-3, 1 + 1e-3, 0.5, 3.0]),
)
def test_stick_boundary_and_contact_time_never_contradict(log_f, condition, side):
    f = 10.0**log_f
    if f == 0.0:
        f = 5e-324
    d_star = stick_boundary(f, condition=condition)
    assert d_star > 0
    D = d_star * side
    tau, error = _attempt(lambda: contact_time(D, f, condition=condition))
    if error is not None:  # a point double precision cannot decide is refused by name
        assert str(error).startswith(f"D = {D!r}, f = {f!r}")
        return
    if side > 1:
        assert tau == math.inf
    else:
        assert 0 < tau < math.inf


@SETTINGS
@given(
    log_D=st.floats(-320, 307),
    log_f=st.floats(-320, 307),
    condition=st.sampled_from(["force", "position"]),
)
def test_extreme_magnitudes_give_a_value_in_range_or_a_named_refusal(log_D, log_f, condition):
    D, f = 10.0**log_D, 10.0**log_f
    tau, error = _attempt(lambda: contact_time(D, f, condition=condition))
    if error is not None:
        assert str(error).startswith(f"D = {D!r}, f = {f!r}")
        return
    e = restitution(D, f, condition=condition)
    assert tau > 0
    assert not math.isnan(tau)
    assert 0.0 <= e <= 1.0
    assert (e == 0.0) == (tau == math.inf) or e < 1e-300  # e underflows for D > 1e154


def test_the_special_points_work():
    assert (
        contact_time(1e100, 0.0, condition="force") < 1e-97
    )  # f = 0 always releases under the force condition
    assert contact_time(1.0, 0.0, condition="force") == pytest.approx(2.0, rel=1e-12)
    assert stick_boundary(0.0, condition="force") == math.inf
    assert stick_boundary(0.0, condition="position") == 1.0
    assert contact_time(0.0, 1e300, condition="force") == pytest.approx(
        math.pi, rel=1e-15
    )  # D = 0: 2Df = 0
    assert contact_time(1.0, 1e300, condition="force") == math.inf
    assert restitution(0.0, 1e300, condition="force") == 1.0


def test_stick_boundary_for_large_force_is_the_asymptote_and_the_kernel_agrees():
    f = 2e12
    d_star = stick_boundary(f, condition="force")
    assert d_star == pytest.approx((16 * math.pi * f**2) ** (-1 / 3), rel=5e-9)
    assert contact_time(d_star * (1 - 1e-6), f, condition="force") < math.inf
    assert contact_time(d_star * (1 + 1e-6), f, condition="force") == math.inf
    with pytest.raises(ValueError, match=r"^D = .*, f = 1e\+50: the static penetration"):
        contact_time(stick_boundary(1e50, condition="force") * 0.999, 1e50, condition="force")


@pytest.mark.parametrize(
    ("inputs", "names"),
    [
        ({"m": 1.0, "k": 1.0, "d": 1e-300, "v0": 1e-300, "F": 1.0}, "F, d, v0"),
        ({"m": 1e-308, "k": 1e-308, "d": 1e308, "v0": 1.0}, "d, k, m"),
        ({"m": 1e308, "k": 1e-308, "d": 0.0, "v0": 1.0}, "m, k"),
    ],
)
def test_physical_contact_overflow_names_the_inputs(inputs, names):
    with pytest.raises(ValueError, match=f"the inputs {names} are too extreme"):
        physical_contact(**inputs, condition="force")


@pytest.mark.parametrize(
    "inputs",
    [
        {"m": 1e-300, "k": 1.0, "d": 1.0, "v0": 1.0},
        {"m": 1.0, "k": 1e-300, "d": 1.0, "v0": 1.0},
        {"m": 1e300, "k": 1e-300, "d": 1.0, "v0": 1.0},
        {"m": 1.0, "k": 1e300, "d": 1e-300, "v0": 1.0},
        {"m": 1.0, "k": 1.0, "d": 1e-320, "v0": 1.0, "F": 0.5},
        {"m": 1e-300, "k": 1e-300, "d": 1e-300, "v0": 1e-300, "F": 1e-300},
    ],
)
def test_physical_contact_extreme_inputs_are_consistent(inputs):
    c = physical_contact(**inputs, condition="force")
    assert c.sticks == math.isinf(c.normalized_contact_time)
    assert math.isinf(c.contact_time) == math.isinf(c.normalized_contact_time)
    if not c.sticks:
        assert c.contact_time > 0
        expected = c.normalized_contact_time / math.sqrt(inputs["k"]) * math.sqrt(inputs["m"])
        assert c.contact_time == pytest.approx(expected, rel=1e-14)
    assert 0.0 <= c.restitution <= 1.0


_LOG = st.floats(-300, 300)
_LOG_OR_ZERO = st.one_of(st.just(None), st.floats(-320, 300))


@SETTINGS
@given(
    log_m=_LOG,
    log_k=_LOG,
    log_v0=_LOG,
    log_d=_LOG_OR_ZERO,
    log_F=_LOG_OR_ZERO,
    condition=st.sampled_from(["force", "position"]),
)
def test_physical_contact_at_any_magnitude_is_consistent_or_names_its_inputs(
    log_m, log_k, log_v0, log_d, log_F, condition
):
    m, k, v0 = 10.0**log_m, 10.0**log_k, 10.0**log_v0
    d = 0.0 if log_d is None else 10.0**log_d
    F = 0.0 if log_F is None else 10.0**log_F
    c, error = _attempt(lambda: physical_contact(m, k, d, v0, F, condition=condition))
    if error is not None:
        assert "the inputs " in str(error)
        return
    assert c.sticks == math.isinf(c.contact_time) == math.isinf(c.normalized_contact_time)
    assert c.sticks or c.contact_time > 0
    assert 0.0 <= c.restitution <= 1.0


def test_physical_contact_vanishing_damping_is_the_undamped_limit():
    # d too small to matter: z'' + z = b with b = F / (sqrt(k m) v0) = 0.5
    c = physical_contact(m=1.0, k=1.0, d=1e-320, v0=1.0, F=0.5, condition="force")
    z = lambda tau: 0.5 * (1 - math.cos(tau)) + math.sin(tau)  # noqa: E731
    assert abs(z(c.normalized_contact_time)) < 1e-14
    assert c.restitution == 1.0


def test_physical_contact_names_mismatched_shapes():
    with pytest.raises(ValueError, match=r"m \(shape \(2,\)\) and k \(shape \(3,\)\)"):
        physical_contact([1.0, 2.0], [1.0, 2.0, 3.0], 0.1, 1.0, condition="force")
