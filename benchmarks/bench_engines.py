"""Benchmark of the engine bridge: design throughput and engine agreement.

Prints, measured in one run:
  * designs per second of vectorized ``mujoco.solref_for`` at flat impedance
    (target: 1e5 targets in under 1 s), with and without gravity;
  * discrete designs at MuJoCo's default dt = 0.002 (Euler, phase mean; targets 1e5 in
    1 s flat with gravity, 2 s with a contact time, 3 s with the default solimp), each
    measured on 1e5 targets (wall and CPU time); and the per-phase agreement table of
    those designs with MuJoCo (drivers.mujoco_phases over 64 touch phases);
  * the engine-vs-prediction table: MuJoCo (flat and default solimp, gravity on/off,
    both solref forms, a multibody contact) and LAMMPS (with/without limit_damping),
    each with the textbook formula's achieved restitution beside it.

Measured here (2-core machine, load 1-5 from other jobs; CPU seconds per 1e5 targets at
1 m/s, restitution 0.3 .. 0.9), ``throughput(100000)`` and ``discrete_throughput()``:

  ============================================  ======  ======
  design                                        CPU s   target
  ============================================  ======  ======
  continuous, flat, gravity 0                   0.10    1
  continuous, flat, gravity 9.81                0.21    1
  continuous, flat, contact_time 0.02 s         0.39    2
  continuous, default solimp, gravity 9.81      1.01    3
  continuous, default solimp, contact_time      0.64    2
  dt = 0.002, flat, gravity 9.81                0.35    1
  dt = 0.002, flat, contact_time 0.02 s         0.29    2
  dt = 0.002, default solimp, gravity 9.81      1.22    3
  ============================================  ======  ======

The continuous default-solimp designs took 3.06 and 2.12 s before their targets started
from a table of node designs (``impactsym.engines.mujoco.varying_design``). The discrete
default-solimp designs went from 0.95 to 1.22 s when the phase means began to cut the
pieces at the impedance's kinks (their mean restitution had been up to 4e-4 off).

Run: python benchmarks/bench_engines.py [--quick]
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from timing import best_of

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's package
from impactsym.engines import lammps, mujoco
from impactsym.engines.drivers import fine_timestep, lammps_collision, mujoco_drop, mujoco_phases

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = mujoco.DEFAULT_SOLIMP


def throughput(n):
    """Continuous designs (``timestep=None``): CPU time per ``n`` targets and the ratio to
    issue 18's targets for 1e5 (restitution 0.3 .. 0.9 at 1 m/s; time.process_time, the
    figure that counts on a shared machine; after one small warm-up call)."""
    cases = (
        ("flat, gravity 0", 1.0, {"gravity": 0.0, "solimp": FLAT}),
        ("flat, gravity 9.81", 1.0, {"gravity": 9.81, "solimp": FLAT}),
        (
            "flat, gravity 9.81, contact_time 0.02 s",
            2.0,
            {"gravity": 9.81, "solimp": FLAT, "contact_time": 0.02},
        ),
        ("default solimp, gravity 9.81", 3.0, {"gravity": 9.81, "solimp": DEFAULT}),
        (
            "default solimp, gravity 9.81, contact_time 0.02 s",
            2.0,
            {"gravity": 9.81, "solimp": DEFAULT, "contact_time": 0.02},
        ),
    )
    targets = np.linspace(0.3, 0.9, n)
    for name, target, options in cases:
        mujoco.solref_for(restitution=targets[:: max(n // 20, 1)], speed=1.0, **options)
        start = time.process_time()
        mujoco.solref_for(restitution=targets, speed=1.0, **options)
        cpu = time.process_time() - start
        scaled = cpu * 1e5 / n
        print(
            f"solref_for (continuous), {n} targets, {name}: {cpu:.3f} s CPU "
            f"({n / cpu:,.0f} designs/s; per 1e5 {scaled:.3g} s, target {target:g} s: "
            f"ratio {scaled / target:.3g})"
        )


def discrete_throughput():
    """Discrete designs at dt = 0.002 (Euler): figures and ratios to the 1e5 targets.

    After one warm-up call (SymPy's lambdified kernels), each case measured on 1e5
    targets directly (their cost is not linear in the count: many targets of one contact
    share one tabulated phase mean, or one curve of contact-time designs), as wall time
    and as CPU time of this process (the figure that counts on a shared machine).
    Targets from 0.3: e = 0.2 at 1 m/s under gravity sticks at some touch phase at
    dt = 0.002.
    """
    dt, n = 0.002, 100_000
    for options in ({"gravity": 9.81, "solimp": FLAT}, {"contact_time": 0.02, "solimp": FLAT}):
        mujoco.solref_for(restitution=np.linspace(0.3, 0.9, 20), speed=1.0, timestep=dt, **options)
    cases = (
        ("flat, gravity 9.81", 1.0, {"gravity": 9.81, "solimp": FLAT}),
        ("flat, contact_time 0.02 s", 2.0, {"contact_time": 0.02, "solimp": FLAT}),
        ("default solimp, gravity 9.81", 3.0, {"gravity": 9.81, "solimp": DEFAULT}),
    )
    for name, target, options in cases:
        e = np.linspace(0.3, 0.9, n)
        cpu = time.process_time()
        t, _ = best_of(
            1,
            lambda o=options, e=e: mujoco.solref_for(restitution=e, speed=1.0, timestep=dt, **o),
        )
        cpu = time.process_time() - cpu
        print(
            f"solref_for at dt = {dt} (Euler), {n} targets, {name}: {t:.3f} s wall, "
            f"{cpu:.3f} s CPU (target {target:g} s: ratio {cpu / target:.3g} in CPU)"
        )


def discrete_rows():
    """MuJoCo per phase and in the phase mean against the discrete model at dt = 0.002."""
    dt, phases = 0.002, (np.arange(64) + 0.5) / 64
    rows = []
    for integrator in ("euler", "implicitfast"):
        for solimp, name in ((FLAT, "flat"), (DEFAULT, "default")):
            for gravity in (0.0, 9.81):
                for e in (0.3, 0.5, 0.8):
                    des = mujoco.solref_for(
                        restitution=e, speed=1.0, gravity=gravity, solimp=solimp,
                        timestep=dt, integrator=integrator,
                    )  # fmt: skip
                    sr = tuple(float(v) for v in des.solref)
                    mj = mujoco_phases(
                        solref=sr, solimp=solimp, speed=1.0, gravity=gravity, timestep=dt,
                        integrator=integrator, phases=phases,
                    )  # fmt: skip
                    per = mujoco.predict(
                        solref=sr, solimp=solimp, speed=1.0, gravity=gravity, timestep=dt,
                        integrator=integrator, phase=phases,
                    )  # fmt: skip
                    dev = np.abs(np.asarray(per.restitution) / mj["restitution"] - 1).max()
                    lo, hi = des.restitution_range
                    rows.append(
                        (f"{integrator} {name} g={gravity}", e, mj["restitution"].mean(), dev,
                         float(lo), float(hi))
                    )  # fmt: skip
    return rows


def print_discrete_rows(rows):
    print()
    print(
        f"{'dt = 0.002, design for the phase mean':34s} {'target':>7s} {'MuJoCo mean':>11s} "
        f"{'mean err':>9s} {'per-phase':>10s} {'range':>17s}"
    )
    for case, e, mean, dev, lo, hi in rows:
        print(
            f"{case:34s} {e:7.3f} {mean:11.5f} {mean / e - 1:+9.3%} {dev:10.1e} {lo:8.4f}..{hi:.4f}"
        )


def mujoco_rows(targets):
    rows = []
    for solimp, name in ((FLAT, "flat"), (DEFAULT, "default")):
        for gravity in (0.0, 9.81):
            for form in ("timeconst", "stiffness"):
                for e in targets:
                    if gravity and e < 0.2:
                        continue  # in the restitution gap at 1 m/s (refused by solref_for)
                    des = mujoco.solref_for(
                        restitution=e, speed=1.0, gravity=gravity, solimp=solimp, form=form
                    )
                    sr = des.solref
                    e_eng, t_eng = mujoco_drop(
                        solref=sr,
                        solimp=solimp,
                        speed=1.0,
                        gravity=gravity,
                        timestep=fine_timestep(sr, 1.0, gravity),
                    )
                    text = (mujoco.DEFAULT_TIMECONST, float(lammps.textbook_damping_ratio(e)))
                    e_text, _ = mujoco_drop(
                        solref=text,
                        solimp=solimp,
                        speed=1.0,
                        gravity=gravity,
                        timestep=fine_timestep(text, 1.0, gravity),
                    )
                    rows.append(
                        (
                            f"MuJoCo {name} g={gravity} {form}",
                            e,
                            e_eng,
                            t_eng / des.contact_time - 1,
                            e_text,
                        )
                    )
    return rows


def lammps_rows(targets):
    rows = []
    m_eff = 4 / 3 * math.pi * 0.1**3 * 1000 / 2
    for limit in (True, False):
        for e in targets:
            c = lammps.hooke_for(
                restitution=e, contact_time=0.01, mass=m_eff, speed=1.0, limit_damping=limit
            )
            e_eng, t_eng, _ = lammps_collision(
                kn=c.kn, damping=c.damping, limit_damping=limit, speed=1.0
            )
            e_text, _, _ = lammps_collision(
                kn=c.kn,
                damping=e,
                limit_damping=limit,
                speed=1.0,
                damping_style="coeff_restitution",
            )
            rows.append((f"LAMMPS limit_damping={limit}", e, e_eng, t_eng / 0.01 - 1, e_text))
    return rows


def main(quick=False):
    throughput(10_000 if quick else 100_000)
    discrete_throughput()
    print_discrete_rows(discrete_rows())
    targets = (0.1, 0.5, 0.9) if quick else (0.1, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95)
    rows = mujoco_rows(targets) + lammps_rows(targets)
    print()
    print(
        f"{'engine / case':40s} {'target':>7s} {'achieved':>9s} {'e err':>8s} "
        f"{'t_c err':>8s} {'textbook':>9s} {'tb err':>8s}"
    )
    worst = {}
    for case, e, e_eng, t_err, e_text in rows:
        err = e_eng / e - 1
        print(
            f"{case:40s} {e:7.3f} {e_eng:9.4f} {err:+8.2%} {t_err:+8.2%} "
            f"{e_text:9.4f} {e_text / e - 1:+8.1%}"
        )
        worst[case] = max(worst.get(case, 0.0), abs(err))
    print()
    for case, w in worst.items():
        print(f"worst |e error| {case}: {w:.3%}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
