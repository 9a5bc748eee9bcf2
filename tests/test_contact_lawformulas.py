"""The usual damping design formulas and what they deliver (impactsym.contact.lawformulas).

The delivered restitutions are checked against an independent event-terminated
integration (SciPy ``solve_ivp``) of the physical law, not against the module's own
closed forms; the figures quoted in the issue and the docs are checked there too.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.contact.lawformulas import (
    FORMULAS,
    delivered_restitution,
    design,
    flores,
    formula_table,
    gonthier,
    hu_guo,
    hunt_crossley_1975,
    lankarani_nikravesh,
    tsuji_alpha,
    tsuji_beta,
    tsuji_gamma,
)

RTOL = {"rtol": 1e-12, "atol": 1e-14}


def hunt_crossley_ode(lam: float, *, k=1.0, m=1.0, v0=1.0, p=1.5) -> float:
    """Restitution of m d'' = -k d^p (1 + lam d') from d = 0, d' = v0, until d = 0."""

    def rhs(_, y):
        d = max(y[0], 0.0)
        return [y[1], -k * d**p * (1.0 + lam * y[1]) / m]

    def back(_, y):
        return y[0]

    back.terminal, back.direction = True, -1
    t_end = 50.0 * (m / (k * v0 ** (p - 1))) ** (1 / (p + 1))
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, v0], events=back, method="DOP853", **RTOL)
    assert sol.status == 1
    return -sol.y_events[0][0][1] / v0


def tsuji_ode(alpha: float, *, cut: bool, k=1.0, m=1.0, v0=1.0) -> float:
    """Restitution of m d'' = -(k d^1.5 + alpha sqrt(m k) d^0.25 d'): until d = 0 (force
    kept), or until the force first returns to zero (cut; the body then coasts)."""

    def rhs(_, y):
        d = max(y[0], 0.0)
        return [y[1], -(k * d**1.5 + alpha * np.sqrt(m * k) * d**0.25 * y[1]) / m]

    def back(_, y):
        return y[0]

    def force_zero(_, y):  # the force over d^(1/4): positive at touch
        return k * max(y[0], 0.0) ** 1.25 + alpha * np.sqrt(m * k) * y[1]

    event = force_zero if cut else back
    event.terminal, event.direction = True, -1
    t_end = 50.0 * (m / (k * v0**0.5)) ** 0.4
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, v0], events=event, method="DOP853", **RTOL)
    assert sol.status == 1
    return -sol.y_events[0][0][1] / v0


def reference(formula: str, e: float) -> float:
    if formula.startswith("tsuji"):
        return tsuji_ode(float(tsuji_alpha(e)), cut=formula == "tsuji-cut")
    return hunt_crossley_ode(float(design(formula, e)))


@pytest.mark.parametrize(
    ("formula", "target", "quoted"),
    [
        ("lankarani-nikravesh", 0.2, 0.672),
        ("hunt-crossley-1975", 0.2, 0.547),
        ("flores", 0.2, 0.156),
        ("tsuji-cut", 0.5, 0.550),
        ("tsuji-cut", 0.3, 0.397),
        ("tsuji-cut", 0.2, 0.325),
    ],
)
def test_quoted_figures_match_an_event_terminated_integration(formula, target, quoted):
    ode = reference(formula, target)
    assert round(ode, 3) == pytest.approx(quoted, abs=1e-12)
    assert delivered_restitution(formula, target) == pytest.approx(ode, abs=1e-8)


@pytest.mark.parametrize("formula", FORMULAS)
def test_every_formula_delivers_what_the_integration_delivers(formula):
    targets = np.array([0.05, 0.35, 0.8])
    got = delivered_restitution(formula, targets)
    want = [reference(formula, float(e)) for e in targets]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8)


def test_dem_formula_is_exact_with_the_tensile_force_kept_only():
    e = np.linspace(0.05, 0.95, 19)
    np.testing.assert_allclose(delivered_restitution("tsuji-kept", e), e, atol=1e-12)
    cut = delivered_restitution("tsuji-cut", e)
    assert np.all(cut > e)
    assert cut.min() > 0.135


def test_delivered_restitution_does_not_depend_on_stiffness_mass_and_speed():
    for formula in ("flores", "tsuji-cut"):
        base = delivered_restitution(formula, 0.3)
        other = delivered_restitution(formula, 0.3, stiffness=3e5, mass=0.2, speed=2.5)
        assert other == pytest.approx(base, abs=1e-10)
    # and the integration agrees in physical units
    lam = lankarani_nikravesh(0.3, speed=2.5)
    assert hunt_crossley_ode(lam, k=3e5, m=0.2, v0=2.5) == pytest.approx(
        delivered_restitution("lankarani-nikravesh", 0.3), abs=1e-8
    )


def test_formulas_as_published():
    e, v0 = 0.4, 2.0
    assert lankarani_nikravesh(e, speed=v0) == pytest.approx(3 * (1 - e**2) / (4 * v0))
    assert hunt_crossley_1975(e, speed=v0) == pytest.approx(3 * (1 - e) / (2 * v0))
    assert flores(e, speed=v0) == pytest.approx(8 * (1 - e) / (5 * e * v0))
    assert gonthier(e, speed=v0) == pytest.approx((1 - e**2) / (e * v0))
    assert hu_guo(e, speed=v0) == pytest.approx(3 * (1 - e) / (2 * e * v0))
    beta = np.log(e) / np.sqrt(np.log(e) ** 2 + np.pi**2)
    assert tsuji_beta(e) == pytest.approx(beta)
    # gamma_n = -2 sqrt(5/6) beta sqrt(S_n m) with S_n = 2 E* sqrt(R* d), k = 4/3 E* sqrt(R*)
    E, R, d, m = 7e7, 0.01, 1e-5, 0.03
    k = 4.0 / 3.0 * E * np.sqrt(R)
    gamma = tsuji_gamma(e, normal_stiffness=2 * E * np.sqrt(R * d), mass=m)
    assert gamma == pytest.approx(-2 * np.sqrt(5 / 6) * beta * np.sqrt(2 * E * np.sqrt(R * d) * m))
    assert gamma == pytest.approx(tsuji_alpha(e) * np.sqrt(m * k) * d**0.25, rel=1e-12)


def test_formula_table_rows_and_targets():
    table = formula_table()
    assert table.target.tolist() == pytest.approx(np.linspace(0.05, 0.95, 19).tolist())
    assert table.delivered.shape == (len(FORMULAS), 19)
    assert table.formulas == FORMULAS
    np.testing.assert_allclose(table.error()[FORMULAS.index("tsuji-kept")], 0.0, atol=1e-12)
    # Lankarani-Nikravesh delivers more than asked at every target below 1
    assert np.all(table.error()[0] > 0)


@pytest.mark.parametrize("bad", [0.0, -0.2, 1.5, np.nan])
def test_bad_targets_are_refused(bad):
    with pytest.raises(ValueError, match="restitution"):
        delivered_restitution("flores", bad)


def test_unknown_formula_is_refused_with_the_list():
    with pytest.raises(ValueError, match="'lankarani-nikravesh'"):
        design("nikravesh", 0.5)
    with pytest.raises(TypeError, match="formula must be a string"):
        delivered_restitution(3, 0.5)
    with pytest.raises(ValueError, match="speed"):
        flores(0.5, speed=-1.0)
