"""Benchmark of the continued rod impact (issue 10, part 2): 10**3 sequences to t = 40.

Run ``python benchmarks/bench_rod_sequence.py [--n 1000] [--seed 10]``. Draws ``alpha``
log-uniformly in [0.1, 10] and ``f`` uniformly in [0, 1] (half of the draws with
``f = 0``, Saint-Venant's problem), follows each rigid-contact impact to ``t = 40`` with
:func:`impactsym.rod.impact_sequence`, and prints the total time (target < 10 s), the
time per sequence for ``f = 0`` and ``f > 0``, the number of contacts and the largest
energy-balance residual on a 2001-point grid of each sequence.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from impactsym.rod import impact_sequence


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=10)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    alpha = np.exp(rng.uniform(np.log(0.1), np.log(10.0), args.n))
    f = np.where(rng.random(args.n) < 0.5, 0.0, rng.uniform(0.0, 1.0, args.n))
    times, contacts, residual = np.empty(args.n), np.empty(args.n, int), 0.0
    start = time.perf_counter()
    sequences = []
    for k in range(args.n):
        t0 = time.perf_counter()
        sequences.append(impact_sequence(alpha[k], f[k], t_end=40.0))
        times[k] = time.perf_counter() - t0
    total = time.perf_counter() - start
    t = np.linspace(0.0, 40.0, 2001)[:-1]
    for k, seq in enumerate(sequences):
        contacts[k] = len(seq.contacts)
        residual = max(residual, float(np.abs(seq.energy.balance(t)).max()))
    zero = f == 0.0
    print(f"{args.n} rod sequences to t = 40: {total:.2f} s (target < 10 s)")
    print(
        f"  f = 0: {zero.sum()} sequences, {times[zero].mean() * 1e3:.1f} ms each, "
        f"{contacts[zero].mean():.1f} contacts on average"
    )
    print(
        f"  f > 0: {(~zero).sum()} sequences, {times[~zero].mean() * 1e3:.1f} ms each, "
        f"{contacts[~zero].mean():.1f} contacts on average, slowest {times.max():.2f} s "
        f"(alpha = {alpha[times.argmax()]:.3g}, f = {f[times.argmax()]:.3g})"
    )
    print(f"largest energy-balance residual: {residual:.1e}")


if __name__ == "__main__":
    main()
