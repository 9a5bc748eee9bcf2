"""Compare the rigid rod sequences of two checkouts on the draws of bench_rod_sequence.py.

Run ``PYTHONPATH=CHECKOUT python benchmarks/compare_rod_sequence.py dump OUT.json`` in each
checkout (the package is imported from ``PYTHONPATH``), then
``python benchmarks/compare_rod_sequence.py compare A.json B.json``: it prints the
number of sequences whose contact counts differ, the largest relative difference of
the contact start and end times, of the separation velocities and of the largest
fixed-end stress, and the largest difference of the energy-balance residual (largest
over a 2001-point grid of each sequence). JSON keeps every float exactly.
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def dump(path: str, n: int, seed: int) -> None:
    """The contacts, separation velocities, stress maximum and residual of each draw."""
    from impactsym.rod import impact_sequence

    rng = np.random.default_rng(seed)  # the draws of bench_rod_sequence.py
    alpha = np.exp(rng.uniform(np.log(0.1), np.log(10.0), n))
    f = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0.0, 1.0, n))
    t = np.linspace(0.0, 40.0, 2001)[:-1]
    out = []
    for a, ff in zip(alpha.tolist(), f.tolist(), strict=True):
        seq = impact_sequence(a, ff, t_max=40.0)
        out.append(
            {
                "contacts": seq.contacts,
                "velocities": seq.separation_velocities,
                "stress": seq.max_fixed_end_stress,
                "residual": float(np.abs(seq.energy.balance(t)).max()),
            }
        )
    with open(path, "w") as fh:
        json.dump(out, fh)


def _relative(x: list, y: list) -> float:
    x, y = np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()
    return float((np.abs(x - y) / np.maximum(np.abs(x), 1e-300)).max(initial=0.0))


def compare(path_a: str, path_b: str) -> None:
    """Print the largest differences between two dumps."""
    with open(path_a) as fa, open(path_b) as fb:
        a, b = json.load(fa), json.load(fb)
    counts = times = velocities = stress = residual = 0.0
    for x, y in zip(a, b, strict=True):
        if len(x["contacts"]) != len(y["contacts"]):
            counts += 1
            continue
        times = max(times, _relative(x["contacts"], y["contacts"]))
        velocities = max(velocities, _relative(x["velocities"], y["velocities"]))
        stress = max(stress, _relative([x["stress"]], [y["stress"]]))
        residual = max(residual, abs(x["residual"] - y["residual"]))
    print(
        f"{len(a)} sequences: {int(counts)} with other contact counts; largest relative "
        f"difference of contact times {times:.3g}, separation velocities "
        f"{velocities:.3g}, largest fixed-end stress {stress:.3g}; largest difference "
        f"of the energy residual {residual:.3g}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("dump")
    d.add_argument("out")
    d.add_argument("--n", type=int, default=1000)
    d.add_argument("--seed", type=int, default=10)
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = parser.parse_args()
    if args.command == "dump":
        dump(args.out, args.n, args.seed)
    else:
        compare(args.a, args.b)


if __name__ == "__main__":
    main()
