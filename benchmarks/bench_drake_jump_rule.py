"""The Gauss rule of ``drake.jump_means``: the pieces' integrals of its
rule against an independent reference, the summary against ``phase_summary``, and the
CPU of ``jump_summary``.

Run ``PYTHONPATH=. python benchmarks/bench_drake_jump_rule.py [--count N]``. Designs:
``drake.point_contact_for`` of random targets (``e`` 0.25-0.55, 10-70 steps, 0.1 kg at
1 m/s; ``g = 0`` and ``9.81``, steps ``1e-3`` and ``1e-4``) at their own contact time,
and random contacts (10-70 steps, ``d v`` 0-3, mass 0.05-2 kg, speed 0.2-3 m/s, ``e``
0.25-0.75) at their own phase mean, where ``jump_summary`` holds the structure. For
each it prints

* the node integral (``JumpMeans.fixed``, the two pieces' integrals: what the rule
  changes) of ``jump_means(..., nodes=5)`` (the change tables' rule) against the same
  integrals by Gauss-Legendre with 16 nodes on each of three panels (the longer piece
  halved), computed here from ``stepping.end_state`` alone, and that reference's own
  spread (20 nodes a panel); also the former layout (5 nodes on each of three panels)
  and 4 nodes a panel, by the same code as the reference;
* the summary's fields against ``phases.phase_summary`` (``jump_summary``'s tests'
  tolerances: the mean restitution, the contact times relative, the overlap relative,
  the restitution's range one-sided);
* CPU seconds of ``jump_summary(..., nodes=5)`` per ``10^5`` designs.

Figures (stop 39, ``--count 3000``: 21392 held contacts, load ~2): the node integral of
the rule (5 nodes on the shorter piece, 7 on the longer) within ``1.9e-15`` of the
reference, ``7e-16`` above 15 steps; the former 5 nodes on each of three panels
``4.2e-15`` and ``4.4e-16``, 4 on each ``2.1e-12`` and ``2.6e-13``; the reference's
spread ``3.3e-16``. Against ``phase_summary``: the restitution to ``2.2e-14``, the
contact times to ``5.5e-14`` relative, the overlap equal, the range short by
``3.3e-15`` at most. ``jump_summary``: 0.8-0.9 s of CPU per 10^5 designs (the former
layout's 0.9-1.2 s, on the benchmark's 4*10^5 designs of the lagged cases).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from impactsym.engines import drake
from impactsym.engines.drake.jump_means import jump_means, jump_summary
from impactsym.engines.drake.phases import phase_summary
from impactsym.engines.drake.stepping import end_state
from impactsym.engines.phase_pieces import gauss_legendre

NODES = 5


def _designed(n, g, h, rng):
    """``(k, d, m, g, v, q)``: designs of random targets at their contact time."""
    e, steps = rng.uniform(0.25, 0.55, n), rng.uniform(10.0, 70.0, n)
    c = drake.point_contact_for(restitution=e, contact_time=steps * h, speed=1.0, mass=0.1,
                                gravity=g, time_step=h)  # fmt: skip
    one = np.ones(n)
    return c.point_contact_stiffness, c.hunt_crossley_dissipation, 0.1 * one, g * one, one, steps


def _random(n, g, h, rng):
    """``(k, d, m, g, v, q)``: random contacts at their own phase mean."""
    m, v = rng.uniform(0.05, 2.0, n), rng.uniform(0.2, 3.0, n)
    k = m * (np.pi / rng.uniform(10.0, 70.0, n) / h) ** 2
    d, gg = rng.uniform(0.0, 3.0, n) / v, np.full(n, g)
    ex = phase_summary(k, d, 0.0, m, gg, v, h, approximation="lagged", bounds=False)
    q = ex.contact_time / h
    keep = np.isfinite(q) & (ex.restitution > 0.25) & (ex.restitution < 0.75)
    keep &= (q >= 10.0) & (q <= 70.0)
    return tuple(a[keep] for a in (k, d, m, gg, v, q))


def _panels_integral(rows, h, q, nodes):
    """The pieces' integrals by Gauss-Legendre with ``nodes`` on each of three panels,
    the longer piece halved (the former layout), from ``end_state`` alone."""
    k, d, m, g, v = rows
    base = np.floor(q - 0.5)
    phi, base = q - 0.5 - base, base.astype(np.int64)
    long_left, n = phi > 0.5, phi.size
    cuts = [np.zeros(n), np.where(long_left, 0.5 * phi, phi),
            np.where(long_left, phi, 0.5 * (1.0 + phi)), np.ones(n)]  # fmt: skip
    states = [base + 1, np.where(long_left, base + 1, base), base]
    x01, w01 = gauss_legendre(nodes)
    x01, w01 = 0.5 * (x01 + 1.0), 0.5 * w01
    total = np.zeros(n)
    for a, b, state in zip(cuts[:-1], cuts[1:], states, strict=True):
        p = a[:, None] + (b - a)[:, None] * x01
        r = np.repeat(np.arange(n), nodes)
        _, u, _, _ = end_state(k[r], d[r], m[r], g[r], v[r], h, p.ravel(), np.repeat(state, nodes))
        total += (b - a) * ((-u / v[r]).reshape(n, nodes) @ w01)
    return total


def _check(label, rows, h, q):
    """Print the rule's and the summary's figures for the contacts ``rows`` at ``q``."""
    s, held = jump_summary(*rows, h, q, nodes=NODES)
    rows, q = tuple(a[held] for a in rows), q[held]
    fixed = jump_means(*rows, h, q, nodes=NODES).fixed
    ref = _panels_integral(rows, h, q, 16)
    spread = np.max(np.abs(_panels_integral(rows, h, q, 20) - ref))
    errors = {"this rule": np.abs(fixed - ref)}
    for nodes in (NODES, 4):
        errors[f"{nodes} a panel"] = np.abs(_panels_integral(rows, h, q, nodes) - ref)
    long = q >= 15.0
    print(f"{label}: {held.sum()} held of {held.size}, {q.min():.0f}-{q.max():.0f} steps")
    print("  node integral vs 16 a panel (over 15 steps):", ", ".join(
        f"{name} {err.max():.1e} ({err[long].max():.1e})" for name, err in errors.items()),
        f"; the reference's spread {spread:.1e}")  # fmt: skip
    ex = phase_summary(*rows[:2], 0.0, *rows[2:], h, approximation="lagged")
    s = type(s)(*(np.asarray(f)[held] for f in s.stacked()))
    rel = max(np.max(np.abs(getattr(s, f) / getattr(ex, f) - 1.0))
              for f in ("contact_time", "contact_time_min", "contact_time_max"))  # fmt: skip
    e_off = np.max(np.abs(s.restitution - ex.restitution))
    x_off = np.max(np.abs(s.max_penetration / ex.max_penetration - 1.0))
    short = max(np.max(s.restitution_min - ex.restitution_min),
                np.max(ex.restitution_max - s.restitution_max))  # fmt: skip
    print(f"  vs phase_summary: restitution {e_off:.1e}, times {rel:.1e} rel, overlap "
          f"{x_off:.1e} rel, range short by {short:.1e}")  # fmt: skip


def _cpu(count):
    """CPU of ``jump_summary`` on designs of the benchmark's lagged targets by contact time."""
    rng = np.random.default_rng(20)
    e, t = rng.uniform(0.3, 0.6, count), rng.uniform(2e-2, 4e-2, count)
    for g in (0.0, 9.81):
        c = drake.point_contact_for(restitution=e, contact_time=t, speed=1.0, mass=0.1, gravity=g,
                                    time_step=1e-3)  # fmt: skip
        one = np.ones(count)
        rows = (c.point_contact_stiffness, c.hunt_crossley_dissipation, 0.1 * one, g * one, one)
        start = time.process_time()
        jump_summary(*rows, 1e-3, t / 1e-3, nodes=NODES)
        cpu = (time.process_time() - start) * 1e5 / count
        print(f"jump_summary, g={g}: {cpu:.3f} s of CPU per 10^5 designs")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=1500, help="targets per set")
    args = parser.parse_args()
    rng = np.random.default_rng(39)
    for h in (1e-3, 1e-4):
        for g in (0.0, 9.81):
            k, d, m, gg, v, q = _designed(args.count, g, h, rng)
            _check(f"designs, h={h}, g={g}", (k, d, m, gg, v), h, q)
            k, d, m, gg, v, q = _random(args.count, g, h, rng)
            _check(f"random, h={h}, g={g}", (k, d, m, gg, v), h, q)
    _cpu(100_000)


if __name__ == "__main__":
    main()
