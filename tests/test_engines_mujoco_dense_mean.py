"""MuJoCo's Euler phase mean at a varying ``solimp`` against a dense midpoint mean.

The contacts an independent investigation found off (scripts of a dense midpoint mean
over 2^14 phases): Gauss-Legendre across the phases where a state crosses a kink of the
impedance (up to 7.4e-5 in the mean restitution; `impactsym.engines.mujoco.euler_kinks`)
and end-step changes hidden inside one grid interval (up to 1.75e-2 steps in the mean
contact time). The reference samples the per-phase model (itself checked against MuJoCo
and a plain loop in `test_engines_mujoco_discrete.py`) at the midpoints of 2^14 cells,
and the cells where the end step changes at 2^10 midpoints each; its error bound is
computed alongside.
"""

from __future__ import annotations

import numpy as np
import pytest

from impactsym.engines import mujoco
from impactsym.engines.mujoco.discrete import step_contact
from impactsym.engines.mujoco.model import DEFAULT_SOLIMP, check_solimp, coefficients

DEFAULT = DEFAULT_SOLIMP  # (0.9, 0.95, 0.001, 0.5, 2)


def _dense_mean(solref, speed, gravity, dt, solimp=DEFAULT, n=2**14, m=2**10):
    """Midpoint means over the phase of restitution and contact time (steps) from the
    per-phase model, the cells where the end step changes redone with ``m`` midpoints;
    and the bound on their error: per cell ``|second difference| / 24`` (smooth) or
    the end-step and restitution jumps over ``2 m`` (a cell with a change)."""
    simp = check_solimp(solimp)
    c = coefficients(solref, simp, dt)

    def run(p):
        r = step_contact(c, simp, 1.0, gravity, speed, dt, p, integrator="euler")
        t = r.contact_time / dt
        assert not r.sticks.any()
        return r.restitution, t, np.rint(t - p)

    p = (np.arange(n) + 0.5) / n
    e, t, key = run(p)
    edges = np.concatenate([[1e-300], np.arange(1, n) / n, [np.nextafter(1.0, 0.0)]])
    _, _, key_edge = run(edges)
    changed = np.flatnonzero(key_edge[:-1] != key_edge[1:])
    changed = np.union1d(changed, np.flatnonzero(key != key_edge[:-1]))
    e_cell, t_cell = e.copy(), t.copy()
    # smooth cells: |second difference| / 24; next to a change (no smooth triple) the
    # largest of those
    bound = np.zeros(n)
    smooth = (key[:-2] == key[1:-1]) & (key[1:-1] == key[2:])
    bound[1:-1] = np.where(smooth, np.abs(np.diff(e, 2)) / 24.0, np.nan)
    bound[[0, -1]] = bound[[1, -2]]
    bound = np.where(np.isnan(bound), np.nanmax(bound), bound)
    sub = (np.arange(m) + 0.5) / m
    for i in changed:
        es, ts, ks = run((i + sub) / n)
        e_cell[i], t_cell[i] = es.mean(), ts.mean()
        jumps = np.flatnonzero(ks[1:] != ks[:-1])
        bound[i] = (np.abs(es[jumps + 1] - es[jumps]).sum() + jumps.size) / (2 * m)
    return e_cell.mean(), t_cell.mean(), bound.sum() / n


OTHER = (0.5, 0.99, 0.01, 0.3, 3.0)  # a wider, cubic impedance


@pytest.mark.parametrize(
    ("solref", "speed", "gravity", "dt", "solimp"),
    [
        # 7.4e-5 in e before: the kinks of the first state in the first grid cell
        ((0.03983713160728383, 0.18858158549730225), 4.796796172383586, 9.81, 0.01, DEFAULT),
        ((0.028929455888798045, 0.3149149594834228), 2.6591509850016326, 0.0, 0.01, DEFAULT),
        # end step 3 -> 2 -> 3 -> 2 in the first grid cell: 1.75e-2 steps off before
        ((0.022914556416744388, 0.5488991515373116), 4.430008325332154, 9.81, 0.01, DEFAULT),
        # 4 -> 5 -> 4 in it: 3.8e-3 steps off before
        ((0.028064687511759747, 0.5370509861658027), 1.9253745430890092, 9.81, 0.01, DEFAULT),
        # another solimp: 2.45e-2 steps and 8.9e-4 in e, 7.5e-3 steps and 9.4e-4 before
        ((0.037886624313443126, 0.6068297066952789), 2.71098844660873, 9.81, 0.01, OTHER),
        ((0.021772034978625926, 0.3457845588123717), 0.7828534778314574, 9.81, 0.01, OTHER),
        # two jumps about 1/2000 of a phase apart: 1.96e-4 steps off while the finer
        # grids stopped at 512 intervals (found by review)
        (
            (0.01726865978920799, 0.24454090019819963),
            0.35320674222928133,
            9.81,
            0.005,
            (0.2, 0.9, 0.002, 0.7, 2.0),
        ),
    ],
)
def test_phase_mean_against_a_dense_midpoint_mean(solref, speed, gravity, dt, solimp):
    got = mujoco.predict(
        solref=solref, solimp=solimp, speed=speed, gravity=gravity, timestep=dt,
        integrator="euler",
    )  # fmt: skip
    e_ref, t_ref, bound = _dense_mean(solref, speed, gravity, dt, solimp)
    assert bound < 2e-7  # the reference resolves what is checked
    assert abs(got.restitution - e_ref) <= bound + 1e-9
    assert abs(got.contact_time / dt - t_ref) <= bound + 1e-9
