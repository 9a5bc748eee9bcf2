"""The unpressed impact tables (impactsym.contact.lawtable, nonlinear.free_table) against an
independent integration, and the piecewise Chebyshev machinery on known functions.

The reference integrates the normalized equation ``z'' = -phi(z, z')``, ``z(0) = 0``,
``z'(0) = 1`` with SciPy's ``solve_ivp`` (DOP853, ``rtol = 1e-13``) and terminal events,
each law written out by hand (``tests/references/contact_laws.py``): position condition, the
event ``z = 0``; force condition, the zero of the force's sign function; clipped, the force
condition's end then a free coast at the same speed to ``z = 0``. Maximum penetration is the
event ``z' = 0``, the peak force the dense output maximized. At random damping numbers
between the Chebyshev nodes the tables agree with it to 1e-10 (relative; restitution
absolute).
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from impactsym.contact import impact
from impactsym.contact.lawtable import build
from impactsym.contact.nonlinear import (
    TABLE_MIN,
    TABLE_SCALE,
    free_table,
    integrated_impact,
    normalized_impact,
)
from tests.references.contact_laws import P, impact_ivp, peak_force


def reference(law: str, d: float, condition: str) -> tuple[float, float, float, float]:
    """(contact time, restitution, maximum penetration, peak force), normalized."""
    sol = impact_ivp(law, d, 0.0, condition, 200.0)
    assert sol.status == 1, (law, d, condition)
    t_c, e = sol.t[-1], -sol.y[1, -1]
    z_end = sol.y[0, -1]
    if condition == "clipped" and len(sol.t_events[2]):
        t_c += z_end / e  # the free coast at speed e to z = 0
    z_max = sol.y_events[1][0][0]
    peak = peak_force(law, sol, d, 20001)
    return t_c, e, z_max, peak


#: Damping numbers drawn between the nodes for each law: where it releases under the
#: position condition (the linear, Tsuji and Hertz-linear contacts stick beyond 1, sqrt(5)
#: and 0.564) and across the tables' range otherwise.
RANGES = {
    "linear": (0.003, 0.98),
    "hertz-linear": (0.003, 0.56),
    "hunt-crossley": (0.003, 25.0),
    "tsuji": (0.003, 2.1),
    "viscoelastic": (0.003, 8.0),
}


@pytest.mark.parametrize("condition", ["position", "force", "clipped"])
@pytest.mark.parametrize("law", list(RANGES))
def test_tables_agree_with_an_independent_integration_to_1e_10(law, condition):
    rng = np.random.default_rng(zlib.crc32(f"{law} {condition}".encode()))  # per case, fixed
    lo, hi = RANGES[law]
    delta = np.exp(rng.uniform(np.log(lo), np.log(hi), 2))
    if condition != "position" and law != "linear":
        delta = np.append(delta, rng.uniform(hi, 10.0 if law != "hunt-crossley" else 30.0))
    q = np.ones_like(delta) if law == "linear" else np.full(delta.shape, P)
    key = "position" if condition == "position" or law == "linear" else "force"
    rows = (4, 1, 2, 3) if condition == "clipped" else (0, 1, 2, 3)
    values, inside = free_table(law, float(q[0]), condition=key)(
        np.arcsinh(delta / TABLE_SCALE), rows
    )
    assert inside.all()
    for i, d in enumerate(delta):
        t_c, e, z_max, peak = reference(law, float(d), condition)
        if law != "linear":  # the linear table holds only the extrema (closed forms else)
            assert values[0, i] == pytest.approx(t_c, rel=1e-10), ("tau", d)
            assert values[1, i] == pytest.approx(e, abs=1e-10), ("e", d)
        assert values[2, i] == pytest.approx(z_max, rel=1e-10), ("z_max", d)
        assert values[3, i] == pytest.approx(peak, rel=1e-10), ("peak", d)


@pytest.mark.parametrize(("law", "delta"), [("linear", 1.7), ("hertz-linear", 0.9),
                                            ("tsuji", 3.0)])  # fmt: skip
def test_sticking_pieces_stick_and_keep_their_extrema(law, delta):
    q = 1.0 if law == "linear" else P
    values, inside = free_table(law, q, condition="position")(
        np.arcsinh(np.array([delta]) / TABLE_SCALE)
    )
    exact = integrated_impact(law, np.array([delta]), np.zeros(1), np.array([q]),
                              condition="position")  # fmt: skip
    assert inside.all()
    if law != "linear":
        assert values[0, 0] == np.inf
        assert values[1, 0] == 0.0
    np.testing.assert_allclose(values[2:4, 0], np.concatenate(exact[2:]), rtol=1e-10)


def test_impact_uses_the_table_on_large_calls_and_agrees_with_the_integration():
    rng = np.random.default_rng(5)
    n = TABLE_MIN
    c = rng.uniform(0.05, 0.8, n)
    looked_up = free_table.cache_info()
    big = impact("viscoelastic", stiffness=1e4, damping=c * 0.01, mass=0.2, speed=0.5,
                 condition="force")  # fmt: skip
    asked = free_table.cache_info()
    assert asked.hits + asked.misses > looked_up.hits + looked_up.misses  # the table served
    for i in (0, 500):  # one element alone is integrated
        alone = impact("viscoelastic", stiffness=1e4, damping=c[i] * 0.01, mass=0.2,
                       speed=0.5, condition="force")  # fmt: skip
        after = free_table.cache_info()
        assert after.hits + after.misses == asked.hits + asked.misses  # no table for one
        assert big.contact_time[i] == pytest.approx(alone.contact_time, rel=1e-10)
        assert big.restitution[i] == pytest.approx(alone.restitution, abs=1e-10)
        assert big.max_penetration[i] == pytest.approx(alone.max_penetration, rel=1e-10)
        assert big.peak_force[i] == pytest.approx(alone.peak_force, rel=1e-10)


def test_pressed_and_uncovered_elements_are_integrated():
    n = TABLE_MIN + 1  # TABLE_MIN unpressed elements: the table serves them
    delta = np.full(n, 0.3)
    b = np.zeros(n)
    b[0] = 0.2  # pressed
    delta[1] = 50.0  # beyond the table
    q = np.full(n, P)
    tau, e, z_max, peak = normalized_impact("hertz-linear", delta, b, q, condition="force")
    exact = integrated_impact("hertz-linear", delta[:2], b[:2], q[:2], condition="force")
    third = integrated_impact("hertz-linear", delta[2:3], b[2:3], q[2:3], condition="force")
    table, _ = free_table("hertz-linear", P, condition="force")(
        np.arcsinh(delta[2:3] / TABLE_SCALE)
    )
    for got, ref, tabled in zip((tau, e, z_max, peak), exact, third, strict=True):
        assert got[0] == ref[0]  # integrated: bit for bit
        assert got[1] == ref[1]
        assert got[2] == pytest.approx(tabled[0], rel=1e-10)  # tabled ...
    np.testing.assert_array_equal([tau[2], e[2], z_max[2], peak[2]], table[:4, 0])  # ... here


def test_build_resolves_a_kink_and_leaves_a_gap_only_there():
    table = build(lambda u: np.abs(u - 0.3)[None] + np.exp(u)[None], 0.0, 1.0, min_width=1e-6)
    u = np.linspace(0.0, 1.0, 1001)
    values, inside = table(u)
    assert (~inside).sum() <= 2
    assert np.all(np.abs(u[~inside] - 0.3) < 1e-5)
    np.testing.assert_allclose(values[0, inside], np.abs(u - 0.3)[inside] + np.exp(u[inside]),
                               rtol=1e-13)  # fmt: skip


def test_build_covers_no_release_as_sticking_next_to_a_piece_end():
    """A sticking threshold between a piece's end and its first Chebyshev node (0.501 in
    [0.5, 1], first node 0.5021): every node of that piece sticks, yet the contacts just
    above 0.5 release. The table must give their exact values or leave them out, never
    ``inf`` (the piece's ends are checked, so it is halved towards the threshold)."""
    threshold = 0.501

    def contact_time(u):
        return np.where(u >= threshold, np.inf, 1.0 + u)[None]

    table = build(contact_time, 0.0, 1.0, min_width=1e-7)
    u = np.linspace(0.5, 0.5009, 10)
    values, inside = table(u)
    np.testing.assert_allclose(values[0, inside], 1.0 + u[inside], rtol=1e-13)
    assert inside[:5].all()  # covered up to near the threshold
    above, covered = table(np.array([0.502, 0.75, 1.0]))
    assert covered.all()
    assert np.isinf(above).all()


def test_build_refuses_a_bad_interval():
    with pytest.raises(ValueError, match="lo < hi"):
        build(lambda u: u[None], 1.0, 0.0, min_width=1e-3)
    with pytest.raises(ValueError, match="min_width"):
        build(lambda u: u[None], 0.0, 1.0, min_width=0.0)


def test_a_large_design_call_inverts_the_table_and_agrees_with_the_integrated_design():
    from impactsym.contact import damping_for

    rng = np.random.default_rng(8)
    e = rng.uniform(0.1, 0.9, TABLE_MIN)
    kw = {"stiffness": 1e4, "mass": 0.2, "speed": 0.5, "condition": "position"}
    big = damping_for("viscoelastic", restitution=e, **kw)
    small = damping_for("viscoelastic", restitution=e[:1], **kw)  # integrated
    np.testing.assert_allclose(big[:1], small, rtol=1e-9)
    back = impact("viscoelastic", damping=big, **kw).restitution  # the table again
    np.testing.assert_allclose(back, e, atol=1e-12)


def test_free_table_refuses_a_condition_it_does_not_hold():
    with pytest.raises(ValueError, match="'position' or 'force'"):
        free_table("tsuji", 1.5, condition="clipped")


@pytest.mark.parametrize("condition", ["force", "clipped"])
@pytest.mark.parametrize("law", ["hertz-linear", "tsuji", "viscoelastic"])
def test_the_integration_finds_a_force_zero_just_above_the_exit(law, condition):
    # with little damping the force vanishes just before z = 0 (z = -beta z' for the
    # viscoelastic law); the kernel's early exit once skipped it (3e-7 off at 1e-6)
    delta = np.array([1e-7, 1e-6])
    got = integrated_impact(law, delta, np.zeros(2), np.full(2, P), condition=condition)
    for i, d in enumerate(delta):
        t_c, e, _, _ = reference(law, float(d), condition)
        assert got[0][i] == pytest.approx(t_c, rel=1e-10)
        assert got[1][i] == pytest.approx(e, abs=1e-10)


@pytest.mark.parametrize("exponent", [float("nan"), 0.5, -1.0, float("inf")])
def test_free_table_refuses_a_bad_exponent_by_name(exponent):
    with pytest.raises(ValueError, match="exponent"):
        free_table("hertz-linear", exponent, condition="position")


def test_free_table_refuses_a_string_exponent():
    with pytest.raises(TypeError, match="exponent"):
        free_table("hertz-linear", "1.5", condition="position")


@pytest.mark.parametrize("exponent", [np.array(1.5), [1.5], np.array([1.5])])
def test_free_table_refuses_an_array_exponent_by_name(exponent):
    """Checked before the cache looks it up (an unhashable key was a raw TypeError)."""
    with pytest.raises(TypeError, match="exponent must be a real number"):
        free_table("hertz-linear", exponent, condition="position")


def test_free_table_takes_numpy_integers_as_the_same_table():
    assert free_table("linear", np.int64(2), condition="position") is free_table(
        "linear", 2.0, condition="position"
    )
