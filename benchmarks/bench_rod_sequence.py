"""Benchmark of the continued rod impact: 10**3 sequences to t = 40.

Run ``python benchmarks/bench_rod_sequence.py [--n 1000] [--seed 10] [--processes 1]``.
Draws ``alpha`` log-uniformly in [0.1, 10] and ``f`` uniformly in [0, 1] (half of the
draws with ``f = 0``, Saint-Venant's problem), follows each rigid-contact impact to
``t = 40`` with :func:`impactsym.rod.impact_sequence`, and prints the total time
(target < 5 s) with the process's CPU time, the time per sequence for ``f = 0`` and
``f > 0``, the number of contacts and the largest energy-balance residual on a
2001-point grid of each sequence.

``--n-kappa 40`` more sequences with a finite contact stiffness (``kappa`` log-uniform in
[1, 1e4], same ``alpha`` and ``f`` draws) print their time per sequence and residual
(no target; reported so that a regression shows).

The library runs in one process. ``--processes 2`` spreads the sequences over worker
processes (the total is then the wall time of the pool, start-up included); the
residuals are computed afterwards, outside the timing, in a second pass.

Figures (``--n-kappa 0``, CPU time of the process; the wall time on the shared
2-core machine mostly measures its load). Before the cheaper root search,
certificates and piece integrals: 5.12 s on the idle machine (load 0.5; f = 0:
0.6 ms, f > 0: 9.7 ms per sequence), 5.66-5.93 s at load 3.7-4.0. After: 4.86-4.99 s
at load 3.7-4.0 (f > 0: 12-19 ms wall per sequence there), about 15 % less CPU time
in alternating runs; the instructions executed (callgrind, the first 120 draws) fell
by 11 %, from 7.82 to 6.95 billion. Where the rest goes (f > 0, timers around each
part): certified root searches 27 % (a quarter of it the Newton polish), the
certificates of the pieces that hold no event 20 %, the event loop's own arithmetic
35 %, the tables, the stress maximum and the energy check 16 %. Every contact time,
separation velocity and stress maximum of the 1000 draws is bit for bit the same as
before; the energy residuals move by less than 1e-14 (benchmarks/compare_rod_sequence.py
compares two checkouts on these draws). The piece integrals are Horner's rule again (one
matrix product over the powers lost 1.3 digits where a piece's terms cancel, found by
review; ~0.1 s): 4.74 and 4.86 s CPU on the idle machine (load 0.7), under the target.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's package
from impactsym.rod import impact_sequence


def timed(cases: list[tuple[float, float]]) -> list[tuple[float, int]]:
    """Time of each sequence and its number of contacts."""
    out = []
    for alpha, f in cases:
        t0 = time.perf_counter()
        seq = impact_sequence(alpha, f, t_max=40.0)
        out.append((time.perf_counter() - t0, len(seq.contacts)))
    return out


def residual(cases: list[tuple[float, float]]) -> float:
    """Largest energy-balance residual of the sequences on a 2001-point grid."""
    t = np.linspace(0.0, 40.0, 2001)[:-1]
    worst = 0.0
    for alpha, f in cases:
        balance = impact_sequence(alpha, f, t_max=40.0).energy.balance(t)
        worst = max(worst, float(np.abs(balance).max()))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=10)
    parser.add_argument("--processes", type=int, default=1)
    parser.add_argument("--n-kappa", type=int, default=40)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    alpha = np.exp(rng.uniform(np.log(0.1), np.log(10.0), args.n))
    f = np.where(rng.random(args.n) < 0.5, 0.0, rng.uniform(0.0, 1.0, args.n))
    cases = list(zip(alpha.tolist(), f.tolist(), strict=True))
    chunks = [cases[k :: args.processes] for k in range(args.processes)]
    order = np.concatenate([np.arange(args.n)[k :: args.processes] for k in range(args.processes)])
    impact_sequence(1.0, 0.5, t_max=4.0)  # imports outside the timing
    start, cpu = time.perf_counter(), time.process_time()
    if args.processes == 1:
        results = timed(cases)
    else:
        with ProcessPoolExecutor(args.processes) as pool:
            results = [r for part in pool.map(timed, chunks) for r in part]
    total, cpu = time.perf_counter() - start, time.process_time() - cpu
    times, contacts = np.empty(args.n), np.empty(args.n, int)
    times[order], contacts[order] = np.array(results).T
    if args.processes == 1:
        worst = residual(cases)
    else:
        with ProcessPoolExecutor(args.processes) as pool:
            worst = max(pool.map(residual, chunks))
    zero = f == 0.0
    where = "" if args.processes == 1 else f" ({args.processes} processes)"
    print(f"{args.n} rod sequences to t = 40{where}: {total:.2f} s (target < 5 s)")
    if args.processes == 1:  # on a loaded machine the wall time says more about the load
        print(f"  CPU time of this process: {cpu:.2f} s")
    print(
        f"  f = 0: {zero.sum()} sequences, {times[zero].mean() * 1e3:.1f} ms each, "
        f"{contacts[zero].mean():.1f} contacts on average"
    )
    print(
        f"  f > 0: {(~zero).sum()} sequences, {times[~zero].mean() * 1e3:.1f} ms each, "
        f"{contacts[~zero].mean():.1f} contacts on average, slowest {times.max():.2f} s "
        f"(alpha = {alpha[times.argmax()]:.3g}, f = {f[times.argmax()]:.3g})"
    )
    print(f"largest energy-balance residual: {worst:.1e}")
    finite_kappa(rng, args.n_kappa)


def finite_kappa(rng: np.random.Generator, n: int) -> None:
    """Time per finite-kappa sequence to t = 40 and the largest relative residual."""
    if n <= 0:
        return
    alpha = np.exp(rng.uniform(np.log(0.1), np.log(10.0), n))
    f = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0.0, 1.0, n))
    kappa = np.exp(rng.uniform(0.0, np.log(1e4), n))
    t = np.linspace(0.0, 40.0, 2001)
    times, worst, refused = [], 0.0, 0
    for a, ff, k in zip(alpha, f, kappa, strict=True):
        t0 = time.perf_counter()
        try:
            seq = impact_sequence(a, ff, kappa=k, t_max=40.0)
        except ValueError:  # refused: float64 no longer exact before t = 40
            refused += 1
            continue
        times.append(time.perf_counter() - t0)
        balance = seq.energy.balance(t) / (0.5 * a + np.abs(seq.energy.work(t)))
        worst = max(worst, float(np.abs(balance).max()))
    times = np.array(times)
    print(
        f"{n} finite-kappa sequences to t = 40 (kappa in [1, 1e4]): "
        f"{np.median(times) * 1e3:.0f} ms median, {times.mean() * 1e3:.0f} ms mean, "
        f"slowest {times.max():.2f} s; {refused} refused; "
        f"largest relative energy-balance residual {worst:.1e}"
    )


if __name__ == "__main__":
    main()
