"""Benchmark of the bounce sequence until rest (paper section 2, impactsym.contact.bounce).

Prints, measured in one run:
  * bounce_map for 10^5 random (D, f), D in [0, 2], f in [0, 1], per condition, with
    max_contacts = 100 (target < 5 s each; also the first call, which derives and
    compiles the closed forms), and the contacts computed;
  * the same 10^5 points as padded per-contact sequences (starts, speeds, deflections);
  * speed-up per sequence over the event-driven scipy reference (tests/references/bounce.py);
  * max deviation of start times and speeds from that reference on a random sample;
  * a huge cap on short sequences: bounce_map(linspace(.1, 1, 100), .2, "force",
    max_contacts=10**6) (at most 9 contacts each), time and peak traced memory against the
    same map with max_contacts = 100 (was 32 s and 4 GB: tables sized by the cap).

Run: PYTHONPATH=. python benchmarks/bench_bounce.py (from the repository root)
"""

from __future__ import annotations

import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from references.bounce import simulate

from impactsym.contact import bounce_sequence
from impactsym.contact.bounce import bounce_map
from impactsym.contact.loop import run_sequences

CONDITIONS = ("position", "force")
N = 100_000


def main() -> None:
    rng = np.random.default_rng(2026)
    D, f = rng.uniform(0.0, 2.0, N), rng.uniform(0.0, 1.0, N)
    map_time = {}
    for condition in CONDITIONS:
        start = time.perf_counter()
        bounce_map(D, f, condition=condition)
        cold = time.perf_counter() - start  # includes the SymPy derivation and codegen
        start = time.perf_counter()
        result = bounce_map(D, f, condition=condition)
        elapsed = map_time[condition] = time.perf_counter() - start
        print(
            f"bounce_map, {N:.0e} sequences, {condition:8s}: {elapsed:.2f} s (target < 5 s; "
            f"{cold:.2f} s on first use, with the symbolic derivation), "
            f"{result.n_contacts.sum()} contacts, max {result.n_contacts.max()} per sequence, "
            f"{(~result.sticks).sum()} not at rest within 100 contacts"
        )
        start = time.perf_counter()
        run_sequences(D, f, 100, condition=condition)
        print(f"  per-contact tables for all of them: {time.perf_counter() - start:.2f} s")

    sample = rng.uniform([0.02, 0.02], [1.5, 0.6], size=(12, 2))
    for condition in CONDITIONS:
        ours, ref, worst_t, worst_v = 0.0, 0.0, 0.0, 0.0
        for d, fr in sample:
            t0 = time.perf_counter()
            seq = bounce_sequence(d, fr, condition=condition)
            ours += time.perf_counter() - t0
            t0 = time.perf_counter()
            rows, _ = simulate(d, fr, condition)
            ref += time.perf_counter() - t0
            n = min(len(rows), seq.n_contacts)
            worst_t = max(worst_t, np.max(np.abs(seq.start[:n] - rows[:n, 0])))
            worst_v = max(worst_v, np.max(np.abs(seq.arrival_velocity[:n] - rows[:n, 2])))
        print(
            f"{condition:8s}: one sequence {1e3 * ours / len(sample):.2f} ms vs scipy events "
            f"{1e3 * ref / len(sample):.1f} ms; vectorized per sequence "
            f"{ref / len(sample) / (map_time[condition] / N):.0f}x faster; max |start - ref| = "
            f"{worst_t:.1e}, max |arrival velocity - ref| = {worst_v:.1e}"
        )

    huge_cap(np.linspace(0.1, 1.0, 100))


def huge_cap(damping: np.ndarray) -> None:
    """Time and peak memory of a map whose cap is far above the contacts that occur."""
    figures = {}
    for cap in (100, 10**6):
        tracemalloc.start()
        start = time.perf_counter()
        result = bounce_map(damping, 0.2, condition="force", max_contacts=cap)
        elapsed = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        figures[cap] = (elapsed, peak, result)
    (t_small, m_small, small), (t_huge, m_huge, huge) = figures[100], figures[10**6]
    print(
        f"bounce_map, {damping.size} points of at most {huge.n_contacts.max()} contacts: "
        f"max_contacts=10**6 {t_huge:.2f} s, peak {m_huge / 1e6:.2f} MB; max_contacts=100 "
        f"{t_small:.2f} s, peak {m_small / 1e6:.2f} MB (ratio {t_huge / t_small:.2f} in time, "
        f"{m_huge / m_small:.2f} in memory; same result: {huge == small})"
    )


if __name__ == "__main__":
    main()
