"""The tables of the pressed impact (impactsym.contact.lawpressed, nonlinear.pressed_table)
against an independent integration, and the two-variable Chebyshev machinery
(impactsym.contact.lawpatch) on known functions.

The reference integrates the normalized equation ``z'' = f - phi(z, z')``, ``z(0) = 0``,
``z'(0) = 1`` with SciPy's ``solve_ivp`` (DOP853, ``rtol = 1e-13``), each law written out
by hand (``tests/references/contact_laws.py``): position condition, the terminal event
``z = 0``; force condition, the zero of a function with the sign of the force. Maximum
penetration is the first event ``z' = 0``, the peak force the dense output maximized. A
body that does not leave within the run sticks; under the position condition its energy
``z'^2/2 + V(z) - f z`` is then checked below 0, from where it can never reach ``z = 0``.
At random pressed elements (across the table, near its stick boundary on both sides, near
``f = 0`` and near the top of its range) the tables agree with it to 1e-10 (relative;
restitution absolute).
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from impactsym.contact import damping_for, impact
from impactsym.contact import lawpressed as lp
from impactsym.contact.lawpatch import build
from impactsym.contact.nonlinear import PRESSED_MIN, integrated_impact, pressed_table
from tests.references.contact_laws import P, impact_ivp, peak_force

LAWS = ("hertz-linear", "hunt-crossley", "tsuji", "viscoelastic")


def reference(law: str, d: float, f: float, condition: str):
    """(contact time, restitution, maximum penetration, peak force), normalized; contact
    time ``inf`` where the body has not left by the end of the run."""
    sol = impact_ivp(law, d, f, condition, 400.0)
    sticks = sol.status == 0
    t_c, e = (np.inf, 0.0) if sticks else (sol.t[-1], -sol.y[1, -1])
    z_max = sol.y_events[1][0][0] if len(sol.t_events[1]) else float(np.max(sol.y[0]))
    peak = peak_force(law, sol, d, 40001)
    energy = None
    if sticks:  # the state at the end of the run: trapped for good?
        z, w = sol.y[:, -1]
        energy = 0.5 * w * w + max(z, 0.0) ** (P + 1) / (P + 1) - f * z
    return t_c, e, z_max, peak, energy


def elements(law: str, condition: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Random pressed elements of the table's range: a quarter each across it, next to
    the boundary (both sides, 10^-3.5 to 10^-1.5 of it), near f = 0 and near f = F_TOP."""
    rng = np.random.default_rng(zlib.crc32(f"pressed {law} {condition}".encode()))
    delta = np.exp(rng.uniform(np.log(lp.DELTA_LOW), np.log(lp.DELTA_TOP), n))
    boundary = pressed_table(law, P, condition=condition, part="boundary")
    F = lp.boundary_values(boundary, np.arcsinh(delta / lp.SCALE))
    kind = np.arange(n) % 4
    side = np.where(rng.uniform(size=n) < 0.5, -1.0, 1.0)
    f = np.select(
        [kind == 0, kind == 1, kind == 2],
        [
            rng.uniform(0.0, lp.F_TOP, n),
            F * (1.0 + side * 10.0 ** rng.uniform(-3.5, -1.5, n)),
            10.0 ** rng.uniform(-6.0, -2.0, n),
        ],
        lp.F_TOP * (1.0 - 10.0 ** rng.uniform(-6.0, -2.0, n)),
    )
    keep = (f > 0) & (f <= lp.F_TOP) & np.isfinite(f)
    return delta[keep], f[keep]


def tabled(law: str, condition: str, delta: np.ndarray, f: np.ndarray):
    parts = {p: pressed_table(law, P, condition=condition, part=p)
             for p in ("boundary", "ends", "extrema")}  # fmt: skip
    return lp.pressed_values(delta, f, **parts)


@pytest.mark.parametrize("condition", ["position", "force"])
@pytest.mark.parametrize("law", LAWS)
def test_pressed_tables_agree_with_an_independent_integration_to_1e_10(law, condition):
    delta, f = elements(law, condition, 12)
    values, inside = tabled(law, condition, delta, f)
    assert inside.mean() >= 0.75  # the band and left-out patches are thin
    checked = 0
    for i in np.flatnonzero(inside):
        t_c, e, z_max, peak, energy = reference(law, float(delta[i]), float(f[i]), condition)
        case = (law, condition, float(delta[i]), float(f[i]))
        if np.isinf(values[0, i]):
            assert values[1, i] == 0.0
            if condition == "position":  # trapped: it can never reach z = 0 again
                assert energy is not None, case
                assert energy < 0, case
            else:
                assert np.isinf(t_c), case
        else:
            assert values[0, i] == pytest.approx(t_c, rel=1e-10), case
            assert values[1, i] == pytest.approx(e, abs=1e-10), case
        assert values[2, i] == pytest.approx(z_max, rel=1e-10), case
        assert values[3, i] == pytest.approx(peak, rel=1e-10), case
        checked += 1
    assert checked >= 9


@pytest.mark.parametrize("condition", ["position", "force"])
def test_impact_reads_pressed_elements_from_the_tables_and_agrees_with_the_integration(
    condition,
):
    rng = np.random.default_rng(11)
    n = PRESSED_MIN
    alpha = rng.uniform(0.05, 1.5, n)
    force = rng.uniform(0.0, 1.0, n)
    kw = {"stiffness": 1.0, "mass": 1.0, "speed": 1.0, "condition": condition}
    looked_up = pressed_table.cache_info()
    big = impact("tsuji", damping=alpha, force=force, **kw)
    assert pressed_table.cache_info().hits > looked_up.hits  # the tables served
    exact = integrated_impact("tsuji", alpha[:40], force[:40], np.full(40, P),
                              condition=condition)  # fmt: skip
    np.testing.assert_allclose(big.contact_time[:40], exact[0], rtol=1e-10)
    np.testing.assert_allclose(big.restitution[:40], exact[1], rtol=0, atol=1e-10)
    np.testing.assert_allclose(big.max_penetration[:40], exact[2], rtol=1e-10)
    np.testing.assert_allclose(big.peak_force[:40], exact[3], rtol=1e-10)
    small = impact("tsuji", damping=alpha[:3], force=force[:3], **kw)  # integrated
    np.testing.assert_allclose(small.restitution, exact[1][:3], rtol=0, atol=1e-14)


def test_a_large_pressed_design_call_inverts_the_table_and_agrees_with_the_integrated_design():
    rng = np.random.default_rng(3)
    kw = {"stiffness": 1.0, "mass": 1.0, "speed": 1.0, "force": 0.05, "condition": "force"}
    delta = rng.uniform(0.05, 1.0, PRESSED_MIN)
    e = impact("viscoelastic", damping=delta / 1.5, **kw).restitution
    big = damping_for("viscoelastic", restitution=e, **kw)
    np.testing.assert_allclose(big * 1.5, delta, rtol=1e-9)
    small = damping_for("viscoelastic", restitution=e[:2], **kw)  # integrated
    np.testing.assert_allclose(big[:2], small, rtol=1e-9)


def test_pressed_values_leave_the_band_and_the_outside_to_the_integration():
    boundary = pressed_table("hunt-crossley", P, condition="position", part="boundary")
    ends = pressed_table("hunt-crossley", P, condition="position", part="ends")
    delta = np.array([0.3, 0.3, 0.3, 0.005, 3.0, 0.3])
    F = lp.boundary_values(boundary, np.arcsinh(delta / lp.SCALE))
    f = np.array([F[0] * (1 + 0.5 * lp.GAP), F[0] * 0.5, F[0] * 1.5, 0.1, 0.1, 2.5])
    values, inside = lp.pressed_values(delta, f, boundary=boundary, ends=ends, extrema=None)
    assert inside.tolist() == [False, True, True, False, False, False]
    assert np.isinf(values[0, 2])
    assert values[1, 2] == 0.0
    assert np.isnan(values[2:]).all()  # no extrema asked


def test_patch_table_resolves_a_kink_across_one_axis_only():
    def fn(u, v):
        return np.stack((np.abs(u - 0.3) + np.exp(v), np.sin(u) * np.cos(v)))

    table = build(fn, (0.0, 0.0), (1.0, 2.0), min_width=(1e-6, 1e-3))
    width_u = table.boxes[:, 1] - table.boxes[:, 0]
    width_v = table.boxes[:, 3] - table.boxes[:, 2]
    narrow = width_u < 1e-4  # next to the kink: halved across it, not along it
    assert narrow.any()
    assert np.all(width_v[narrow] >= 0.1)
    rng = np.random.default_rng(0)
    u, v = rng.uniform(0.0, 1.0, 2000), rng.uniform(0.0, 2.0, 2000)
    values, inside = table(u, v)
    assert np.all(np.abs(u[~inside] - 0.3) < 1e-5)
    np.testing.assert_allclose(values[:, inside], fn(u[inside], v[inside]), rtol=1e-12, atol=1e-14)


def test_patch_table_skips_what_nobody_asks_for_and_breaks_at_roots():
    calls = []

    def fn(u, v):
        calls.append(u.size)
        return np.stack((u + v,))

    table = build(fn, (0.0, 0.0), (1.0, 1.0), min_width=(0.1, 0.1),
                  skip=lambda boxes: boxes[:, 0] >= 0.25, roots=np.array([0.25]))  # fmt: skip
    assert calls == [400]  # one patch evaluated: [0, 0.25] x [0, 1]
    values, inside = table(np.array([0.1, 0.6, 0.2]), np.array([0.1, 0.2, 0.9]))
    assert inside.tolist() == [True, False, True]
    np.testing.assert_allclose(values[0, inside], [0.2, 1.1], rtol=1e-14)


def test_patch_table_refuses_a_bad_rectangle():
    with pytest.raises(ValueError, match="lo < hi"):
        build(lambda u, v: u[None], (1.0, 0.0), (0.0, 1.0), min_width=(0.1, 0.1))
    with pytest.raises(ValueError, match="min_width"):
        build(lambda u, v: u[None], (0.0, 0.0), (1.0, 1.0), min_width=(0.0, 0.1))


def test_pressed_table_refuses_what_it_does_not_hold():
    with pytest.raises(ValueError, match="laws"):
        pressed_table("linear", 1.0, condition="position", part="ends")
    with pytest.raises(ValueError, match="'position' or 'force'"):
        pressed_table("tsuji", 1.5, condition="clipped", part="ends")
    with pytest.raises(ValueError, match="part"):
        pressed_table("tsuji", 1.5, condition="force", part="all")
    with pytest.raises(TypeError, match="exponent"):
        pressed_table("tsuji", "1.5", condition="force", part="ends")
