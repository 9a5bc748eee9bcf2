"""LAMMPS at the user's timestep: speed of the discrete prediction and design.

Prints seconds for ``lammps.predict`` on 10^5 contacts at a timestep (phase mean and
range), ``lammps.hooke_for`` on 10^4 targets at a timestep, and ``timestep_for`` on one
design. Run: ``python benchmarks/bench_lammps_timestep.py``.
"""

from __future__ import annotations

import time

import numpy as np

from impactsym.engines import lammps


def _timed(label: str, fn) -> float:
    start = time.perf_counter()
    fn()
    seconds = time.perf_counter() - start
    print(f"{label:<60s} {seconds:8.3f} s")
    return seconds


def main() -> None:
    rng = np.random.default_rng(0)
    n = 100_000
    e = rng.uniform(0.1, 0.9, n)
    c = lammps.hooke_for(restitution=e, contact_time=1e-2, mass=1.0)
    for limit in (True, False):
        d = (
            c
            if limit
            else lammps.hooke_for(restitution=e, contact_time=1e-2, mass=1.0, limit_damping=False)
        )
        for gravity in (0.0, 9.81):
            _timed(
                f"predict, 1e5 contacts, t_c/50, limit={limit}, g={gravity}",
                lambda d=d, g=gravity, lim=limit: lammps.predict(
                    kn=d.kn,
                    damping=d.damping,
                    mass=1.0,
                    speed=1.0,
                    gravity=g,
                    limit_damping=lim,
                    timestep=2e-4,
                ),
            )
    _timed(
        "predict, 1e5 contacts, continuous",
        lambda: lammps.predict(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0),
    )
    m = 10_000
    for steps in (10, 50):
        _timed(
            f"hooke_for, 1e4 targets, t_c/{steps}",
            lambda s=steps: lammps.hooke_for(
                restitution=e[:m], contact_time=1e-2, mass=1.0, timestep=1e-2 / s
            ),
        )
    _timed(
        "timestep_for, one design",
        lambda: lammps.timestep_for(
            kn=float(c.kn[0]),
            damping=float(c.damping[0]),
            mass=1.0,
            speed=1.0,
            limit_damping=True,
        ),
    )


if __name__ == "__main__":
    main()
