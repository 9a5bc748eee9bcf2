"""Benchmark of the rod impact analysis (issue 3): symbolic inversion and time functions.

Run ``python benchmarks/bench_rod.py``. In one run it prints

* the time to build and invert the first 40 terms of the ``Y`` and ``N`` series with
  symbolic ``alpha``, ``f`` (from a fresh :class:`impactsym.rod.RodImpact`);
* the first 12 terms of eq. (2), each as the paper writes it (rational coefficient
  times its delay ``exp(-T s)``), against Lcapy (if installed; it is no dependency)
  and against SymPy's generic ``inverse_laplace_transform`` with plain symbols
  ``alpha``, ``f`` (each term in a child process with a timeout, stopping at the first
  timeout), with operation counts; ours splits the delay off, inverts the rest and
  shifts it, and that whole step is what is timed;
* the time to evaluate ``y`` and ``N`` at 10**6 points on [0, 100], the speed-up per
  point over ``mpmath.invertlaplace`` (de Hoog, 100 terms), and the maximum error
  against a reference with more than 30 correct digits (the exact inverted terms
  evaluated with mpmath at 60 working digits).

Options: ``--sympy-timeout SECONDS`` (per term, default 60), ``--sympy-budget SECONDS``
(total, default 240), ``--reference-points N`` (default 60 per parameter pair).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp_process
import time

import mpmath as mp
import numpy as np
import sympy as sp

from impactsym.rod import RodImpact, contact_force, displacement
from impactsym.symbolic.laplace import invert_delay_series

PAIRS = ((0.05, 0.0), (1.0, 0.5), (50.0, 5.0))


def _sympy_worker(expr: str, queue) -> None:
    s, t = sp.symbols("s t")
    alpha, f = sp.symbols("alpha f")  # plain symbols, as a user would type them
    F = sp.sympify(expr, locals={"alpha": alpha, "f": f, "s": s})
    start = time.perf_counter()
    g = sp.inverse_laplace_transform(F, s, t)
    queue.put((time.perf_counter() - start, sp.count_ops(g)))


def sympy_generic(F: sp.Expr, timeout: float) -> tuple[float, int] | None:
    """SymPy's inverse_laplace_transform in a fresh child process (cold SymPy caches,
    timed inside the child); None on timeout."""
    context = mp_process.get_context("spawn")
    queue = context.Queue()
    process = context.Process(target=_sympy_worker, args=(sp.srepr(F), queue))
    process.start()
    process.join(timeout)
    if process.is_alive():
        process.terminate()
        process.join()
        return None
    return queue.get() if not queue.empty() else None


def lcapy_inverse(F: sp.Expr) -> tuple[float, int] | None:
    """Lcapy's inverse transform of F (symbols alpha, f, s); None if not installed."""
    try:
        import lcapy
    except ImportError:
        return None
    start = time.perf_counter()
    result = lcapy.expr(str(F))(lcapy.t)
    elapsed = time.perf_counter() - start
    g = result.sympy
    if isinstance(g, sp.Piecewise):  # Lcapy returns Piecewise((g, t >= 0))
        g = g.args[0][0]
    return elapsed, sp.count_ops(g)


def symbolic(args) -> None:
    print("== Symbolic: series and exact inversion (symbolic alpha, f) ==")
    start = time.perf_counter()
    rod = RodImpact()
    for name in ("Y", "N"):
        rod.time_terms(name, 40)
    total = time.perf_counter() - start
    print(f"solve eq. (1), build and invert 40 terms of Y and N: {total:.2f} s (target < 2 s)")

    print("\nfirst 12 terms of eq. (2) (Y), one by one:")
    terms = RodImpact().series("Y", 12)
    ours_time, ours_ops, lcapy_rows, sympy_rows = [], [], [], []
    s, t = rod.s, rod.t
    for delay, F in terms:
        start = time.perf_counter()
        ((_, g),) = invert_delay_series([(delay, F)], s, t)
        ours_time.append(time.perf_counter() - start)
        ours_ops.append(sp.count_ops(g))
        lcapy_rows.append(lcapy_inverse(F * sp.exp(-delay * s)))
    budget, timed_out = args.sympy_budget, False
    for delay, F in terms:
        if timed_out or budget <= 0:
            sympy_rows.append(None)
            continue
        start = time.perf_counter()
        row = sympy_generic(F * sp.exp(-delay * s), min(args.sympy_timeout, budget))
        budget -= time.perf_counter() - start
        timed_out = row is None
        sympy_rows.append(row)
    print(f"{'n':>3} {'ours s':>9} {'ops':>5} {'Lcapy s':>9} {'ops':>5} {'SymPy s':>9} {'ops':>5}")
    for n in range(12):
        lc, sy = lcapy_rows[n], sympy_rows[n]
        print(
            f"{n + 1:>3} {ours_time[n]:>9.4f} {ours_ops[n]:>5}"
            + (f" {lc[0]:>9.4f} {lc[1]:>5}" if lc else f" {'-':>9} {'-':>5}")
            + (f" {sy[0]:>9.3f} {sy[1]:>5}" if sy else f" {'timeout':>9} {'-':>5}")
        )
    ours_total = sum(ours_time)
    print(f"ours, 12 terms: {ours_total:.3f} s, {sum(ours_ops)} operations")
    if all(lcapy_rows):
        lc_total = sum(r[0] for r in lcapy_rows)
        lc_ops = sum(r[1] for r in lcapy_rows)
        print(
            f"Lcapy, 12 terms: {lc_total:.3f} s, {lc_ops} operations: ours is "
            f"{lc_total / ours_total:.0f}x faster (target >= 10x); "
            f"ours/Lcapy operations {sum(ours_ops) / lc_ops:.2f} (target <= 1), "
            f"no term larger: {all(o <= r[1] for o, r in zip(ours_ops, lcapy_rows, strict=True))}"
        )
    else:
        print("Lcapy is not installed: comparison skipped (pip install lcapy)")
    done = [n for n, r in enumerate(sympy_rows) if r]
    if done:
        sy_total = sum(sympy_rows[n][0] for n in done)
        ours_done = sum(ours_time[n] for n in done)
        print(
            f"SymPy generic, terms 1..{done[-1] + 1} (timeout {args.sympy_timeout:g} s per term): "
            f"{sy_total:.1f} s, ours {ours_done:.3f} s: {sy_total / ours_done:.0f}x faster "
            f"(target >= 1000x on 12 terms)"
        )


def reference(terms, T: float, a: float, force: float) -> float:
    with mp.workdps(60):  # the expanded terms cancel ~20 digits for small alpha
        x, a, force = mp.mpf(T), mp.mpf(a), mp.mpf(force)
        return float(mp.fsum(g(x - d, a, force) for d, g in terms if d <= x))


def numeric(args) -> None:
    print("\n== Numeric: y(t), N(t) at 10**6 points on [0, 100] (rigid contact) ==")
    t = np.linspace(0.0, 100.0, 10**6)
    for a, force in PAIRS:
        times = {}
        for name, fn in (("y", displacement), ("N", contact_force)):
            runs = []
            for _ in range(3):  # best of three: the first run also pays for page faults
                start = time.perf_counter()
                fn(t, a, force)
                runs.append(time.perf_counter() - start)
            times[name] = min(runs)
        both = times["y"] + times["N"]
        print(
            f"alpha = {a:5g}, f = {force:g}: y {times['y']:.3f} s, N {times['N']:.3f} s, "
            f"both {both:.3f} s (target < 1 s)"
        )
    per_point = both / (2 * t.size)

    a, force = 1.0, 0.5

    def N_closed(x):
        return (a * x + force) * mp.cosh(x) / (x * (mp.cosh(x) + a * x * mp.sinh(x)))

    samples = (0.7, 1.9, 3.3, 4.6)
    start = time.perf_counter()
    with mp.workdps(30):
        for T in samples:
            mp.invertlaplace(N_closed, T, method="dehoog", degree=100)
    dehoog = (time.perf_counter() - start) / len(samples)
    print(
        f"mpmath.invertlaplace (de Hoog, 100 terms, 30 digits): {dehoog * 1e3:.0f} ms per point; "
        f"ours {per_point * 1e9:.0f} ns per point: {dehoog / per_point:.1e}x faster"
    )

    print("\nmaximum error against the exact terms (60 working digits), t in [0, 100]:")
    rod = RodImpact()
    s_t, s_a, s_f = rod.t, rod.alpha, rod.f
    exact = {
        name: [
            (int(d), sp.lambdify((s_t, s_a, s_f), g, "mpmath")) for d, g in rod.time_terms(name, 51)
        ]
        for name in ("Y", "N")
    }
    rng = np.random.default_rng(2024)
    worst = 0.0
    for a, force in PAIRS:
        T = np.sort(rng.uniform(0.0, 100.0, args.reference_points))
        errors = []
        for name, fn in (("Y", displacement), ("N", contact_force)):
            ref = np.array([reference(exact[name], x, a, force) for x in T])
            errors.append(np.max(np.abs(fn(T, a, force) - ref)))
        worst = max(worst, *errors)
        print(f"alpha = {a:5g}, f = {force:g}: y {errors[0]:.1e}, N {errors[1]:.1e}")
    print(f"maximum error {worst:.1e} (target <= 1e-10)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sympy-timeout", type=float, default=60.0)
    parser.add_argument("--sympy-budget", type=float, default=240.0)
    parser.add_argument("--reference-points", type=int, default=60)
    args = parser.parse_args()
    symbolic(args)
    numeric(args)


if __name__ == "__main__":
    main()
