"""Timing shared by the benchmark scripts (run as ``python benchmarks/bench_*.py``, so this
folder is on the import path)."""

from __future__ import annotations

import time


def best_of(repeats, fn, *args, **options):
    """The shortest wall time of ``repeats`` calls ``fn(*args, **options)``, and the result."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn(*args, **options)
        times.append(time.perf_counter() - start)
    return min(times), result
