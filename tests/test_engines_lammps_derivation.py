"""The closed forms of the LAMMPS modules against the SymPy derivation of LAMMPS's update."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from impactsym.engines.lammps.derivation import VerletHooke
from impactsym.engines.lammps.hooke import coast
from impactsym.engines.lammps.verlet import StepMap, at_step, stability_limit

VH = VerletHooke()


def test_step_map_and_its_powers_are_the_derived_update():
    rng = np.random.default_rng(3)
    for _ in range(20):
        D, tau, L = rng.uniform(0, 2), rng.uniform(0.01, 0.5), rng.uniform(0, 0.5)
        sub = {VH.D: D, VH.tau: tau, VH.load: L}
        M = np.array(VH.matrix.subs(sub).evalf(), dtype=float)
        m = StepMap(np.array([D]), np.array([tau]))
        assert np.allclose([[m.m11[0], m.m12[0]], [m.m21[0], m.m22[0]]], M, rtol=1e-14)
        assert float(VH.fixed_point[VH.x].subs(sub)) == pytest.approx(L)
        if tau < 0.8 * min(stability_limit(D), 0.5 / max(D, 1e-9)):
            # the closed-form n-th state is the derived step applied n times
            p, n = rng.uniform(0, 1), int(rng.integers(1, 30))
            x, w = (float(c.subs({**sub, VH.p: p})) for c in VH.first_state)
            step = sp.lambdify((VH.x, VH.w), [c.subs(sub) for c in VH.step_normalized])
            for _ in range(n):
                x, w = step(x, w)
            xn, wn, _ = at_step(D, L, tau, p, n)
            assert float(xn) == pytest.approx(x, abs=1e-11)
            assert float(wn) == pytest.approx(w, abs=1e-11)


def test_stability_limit_is_jury():
    for D in (0.0, 0.3, 1.0, 5.0):
        assert float(VH.stability_limit.subs(VH.D, D)) == pytest.approx(
            float(stability_limit(D)), rel=1e-14
        )


def test_coast_band_and_departure_are_derived():
    e, D, L = 0.4, 0.3, np.array([0.1, 0.3, 0.5])
    dep, band = coast(D, L, np.full(3, e), np.zeros(3, bool), True)
    for i, load in enumerate(L):
        sub = {sp.Symbol("e", positive=True): e, VH.D: D, VH.load: load}
        sticks = float(VH.coast["overlap_there"].subs(sub)) > 0
        assert bool(band[i]) == sticks
        if not sticks:
            assert dep[i] == pytest.approx(np.sqrt(float(VH.coast["departure"].subs(sub))))
