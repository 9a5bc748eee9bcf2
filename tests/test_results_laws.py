"""The reproduce step of the contact laws: quick outputs written with their captions, and
what the CSV files hold checked against solve_ivp, Lambert W and the linear closed forms."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import lambertw

from impactsym.contact import stick_boundary
from impactsym.contact.laws import LAWS
from impactsym.reproduce import STEPS
from impactsym.results import laws
from impactsym.results.report import caption

P = 1.5
CONDITIONS_INDEX = {"position": 0, "force": 1}


def _phi(law, delta):
    """Normalized contact force and its reduced force (sign of the force), written out."""
    if law == "hunt-crossley":
        return (lambda z, w: z**P * (1 + delta * w)), (lambda z, w: 1 + delta * w)
    if law == "tsuji":
        return (
            lambda z, w: z**P + delta * z ** ((P - 1) / 2) * w,
            lambda z, w: delta * w + z ** ((P + 1) / 2),
        )
    if law == "viscoelastic":
        return (lambda z, w: z**1.5 + delta * np.sqrt(z) * w), (lambda z, w: z + delta * w)
    assert law == "hertz-linear"
    return (lambda z, w: z**P + 2 * delta * w), (lambda z, w: z**P + 2 * delta * w)


def _solve(law, delta, f, t_max):
    phi, _ = _phi(law, delta)

    def rhs(t, y):
        return [y[1], f - phi(max(y[0], 0.0), y[1])]

    def exit_(t, y):
        return y[0]

    exit_.terminal, exit_.direction = True, -1
    return solve_ivp(rhs, (0.0, t_max), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14,
                     dense_output=True, events=exit_)  # fmt: skip


def releases_ivp(law, delta, f, condition, t_max=40.0):
    """Whether the body of z'' = f - phi(z, z'), z(0) = 0, z'(0) = 1 leaves the contact:
    DOP853 with a terminal event at z = 0; under the force condition the reduced force is
    also sampled finely on the dense output (an event test at step ends could miss a dip
    below zero inside one step, near the boundary)."""
    sol = _solve(law, delta, f, t_max)
    if sol.t_events[0].size:
        return True
    if condition == "position":
        return False
    _, reduced = _phi(law, delta)
    t = np.linspace(1e-3, sol.t[-1], 400_001)
    z, w = sol.sol(t)
    return bool(reduced(np.maximum(z, 0.0), w).min() < 0)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("laws")
    messages = []
    files = laws.write(out, quick=True, progress=messages.append)
    return out, files, messages


def _rows(path):
    with path.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


def test_quick_writes_every_file_with_its_caption_and_reports_each_law(quick):
    out, files, messages = quick
    figures = [
        f"{stem}.{ext}"
        for stem in ("law_stick_boundaries", "law_restitution", "law_contact_map")
        for ext in ("png", "pdf")
    ]
    tables = ["law_contact_map.csv", "law_restitution.csv", "law_stick_boundary.csv"]
    assert sorted(p.name for p in files) == sorted(figures + tables)
    assert all(p.is_file() and p.parent == out for p in files)
    for path in files:
        key = path.name if path.suffix == ".csv" else path.stem
        assert key in laws.CAPTIONS, path.name
        assert caption(path, laws.CAPTIONS) == laws.CAPTIONS[key]
    for names in laws.DATA.values():
        assert all(name in laws.CAPTIONS for name in names)
    for law in LAWS:  # progress per law
        assert any(m.startswith(f"{law}: stick/release") for m in messages), law
        assert any(m.startswith(f"{law}: restitution") for m in messages), law
    assert ("nonlinear contact laws: stick boundaries, restitution", laws.__name__) in STEPS


def test_the_boundaries_hold_against_solve_ivp(quick):
    out, _, _ = quick
    header, rows = _rows(out / "law_stick_boundary.csv")
    assert header == ["law", "damping_number", "f_star_position", "f_star_force"]
    table = {(r[0], float(r[1])): (float(r[2]), float(r[3])) for r in rows}
    assert sorted({law for law, _ in table}) == sorted(LAWS)
    for law in LAWS:
        expected = laws.boundary_damping(law, quick=True)
        assert sorted(d for name, d in table if name == law) == expected.tolist()
    # the linear law: the paper's closed-form boundary D*(f*) gives back D
    for (law, d), (f_pos, f_force) in table.items():
        if law == "linear":
            for condition, f_star in (("position", f_pos), ("force", f_force)):
                back = stick_boundary(f_star, condition=condition)
                assert back == pytest.approx(d, rel=laws.RTOL)
    # the nonlinear laws: releases just below f*, sticks just above (width 1e-4)
    checks = [("hunt-crossley", 0, "position"), ("tsuji", 1, "force"),
              ("viscoelastic", 0, "force"), ("hertz-linear", 0, "position")]  # fmt: skip
    for law, index, condition in checks:
        d = laws.boundary_damping(law, quick=True)[index]
        f_star = table[law, d][CONDITIONS_INDEX[condition]]
        assert 0.0 < f_star < np.inf
        assert releases_ivp(law, d, f_star * (1 - 1e-4), condition), (law, d, condition)
        assert not releases_ivp(law, d, f_star * (1 + 1e-4), condition), (law, d, condition)


def test_the_restitution_curves_meet_the_closed_forms(quick):
    out, _, _ = quick
    header, rows = _rows(out / "law_restitution.csv")
    assert header[:4] == ["law", "damping_number", "restitution_position", "restitution_force"]
    values = {law: np.array([r[1:] for r in rows if r[0] == law], float) for law in LAWS}
    # Hunt-Crossley: Lambert W, both conditions (the force never turns tensile)
    s, e_pos, e_force = values["hunt-crossley"][1:, :3].T
    closed = (1 + lambertw(-(1 + s) * np.exp(-(1 + s))).real) / s
    np.testing.assert_allclose(e_pos, closed, rtol=1e-10)
    np.testing.assert_allclose(e_force, closed, rtol=1e-10)
    # Tsuji, position condition: the linear contact at zeta = alpha/sqrt(5)
    alpha, e_pos = values["tsuji"][:, 0], values["tsuji"][:, 1]
    zeta = alpha / np.sqrt(5)
    under = zeta < 1
    linear = np.exp(-np.pi * zeta[under] / np.sqrt(1 - zeta[under] ** 2))
    np.testing.assert_allclose(e_pos[under], linear, rtol=1e-10)
    assert np.all(e_pos[~under] == 0.0)
    # no damping: the restitution is one under both conditions for every law
    for law in LAWS:
        assert values[law][0, 0] == 0.0
        np.testing.assert_allclose(values[law][0, 1:3], 1.0, rtol=1e-10)


def test_the_contact_map_agrees_with_solve_ivp(quick):
    out, _, _ = quick
    header, rows = _rows(out / "law_contact_map.csv")
    assert header == ["damping_number", "f", "contact_time", "restitution"]
    grid = np.array(rows, float)
    assert grid.shape == (48, 4)
    finite = grid[np.isfinite(grid[:, 2]) & (grid[:, 0] > 0)]
    assert finite.size
    assert np.isinf(grid[:, 2]).any()
    alpha, f, tau_c, e = finite[len(finite) // 2]
    # the Tsuji force condition: contact ends where the reduced force crosses zero
    phi, reduced = _phi("tsuji", alpha)

    def rhs(t, y):
        return [y[1], f - phi(max(y[0], 0.0), y[1])]

    def end(t, y):
        return reduced(max(y[0], 0.0), y[1]) if t > 1e-6 else 1.0

    end.terminal, end.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 40.0), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=end)  # fmt: skip
    assert sol.t_events[0].size == 1
    assert tau_c == pytest.approx(sol.t_events[0][0], rel=1e-8)
    assert e == pytest.approx(-sol.y_events[0][0][1], rel=1e-7)
