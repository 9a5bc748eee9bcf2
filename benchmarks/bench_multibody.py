"""Benchmark of the multibody reduction (paper section 3).

Prints, measured in one run:
  * reduce_contact for the double pendulum (KanesMethod model and matrices);
  * the reduced verdict and contact time for a 100 x 100 (k, d) grid, per condition,
    and the time per point against one full SciPy simulation (solve_ivp with events);
  * stick_damping for 100 stiffnesses and penalty_for_targets.

Run: python benchmarks/bench_multibody.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from references.multibody_systems import FullSimulation, pendulum_kane

from impactsym.multibody import reduce_contact
from impactsym.multibody.design import penalty_for_targets, stick_damping
from impactsym.multibody.examples import double_pendulum


def timed(fn, *args, **kwargs):
    start = time.perf_counter()
    result = fn(*args, **kwargs)
    return time.perf_counter() - start, result


def main() -> None:
    model, example = pendulum_kane(), double_pendulum()
    t, _ = timed(reduce_contact, model.model, model.g, model.at(0.3), 1e4, 5.0)
    print(f"reduce_contact (KanesMethod, 2 dof):      {t * 1e3:8.1f} ms")
    t, reduced = timed(example.reduce, 1.0, 0.0, 0.3)
    print(f"reduce_contact (matrices, 2 dof):         {t * 1e3:8.1f} ms")

    m_eff = reduced.m_eff
    k = m_eff * np.geomspace(100.0, 3000.0, 100) ** 2
    D = np.geomspace(0.02, 3.0, 100)[:, None]
    d = 2 * D * np.sqrt(k * m_eff)
    sim = FullSimulation(model)
    for condition in ("position", "force"):
        grid = reduced.with_penalty(k, d)
        grid.contact_time(condition)  # compile the section-2 kernels first
        t, times = timed(grid.contact_time, condition)
        t_sim, _ = timed(sim.contact_time, k[50], float(d[20, 50]), 0.3, condition, 1.0)
        print(
            f"reduced {condition:8s} contact time, 10^4 points: {t:6.3f} s "
            f"({np.isinf(times).mean():.0%} stick); speed-up per point over solve_ivp: "
            f"{t_sim / (t / times.size):,.0f}"
        )
    t, _ = timed(stick_damping, reduced, k, condition="force")
    print(f"stick_damping, 100 stiffnesses:           {t:8.3f} s")
    t, (k_d, d_d) = timed(penalty_for_targets, reduced, restitution=0.5, contact_time=2e-3)
    print(f"penalty_for_targets:                      {t:8.3f} s  (k = {k_d:.4g}, d = {d_d:.4g})")


if __name__ == "__main__":
    main()
