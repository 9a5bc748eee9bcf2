"""Benchmark of the rod contact times (issue 11): certified search against the old sampling.

Run ``python benchmarks/bench_rod_contact_times.py [--n 100]``. In one run, on the
``n x n`` grid ``alpha`` geometric in [0.05, 10], ``f`` in [0, 2] (rigid contact,
``t_max = 100``), for both conditions it prints

* the time of :func:`impactsym.rod.contact_time` (certified isolation);
* the time of the sampled search it replaces (copied below: a grid uniform in
  ``sqrt(tau)`` per reflection interval, first sample ``<= 0`` bracketed and polished),
  running on the same kernel, and how many pairs it gets wrong;
* a dense-sampling brute force (20,000 samples per reflection interval) on a subset,
  its time per pair and its disagreements;
* with ``--atlas N``: the certified search alone on an ``N x N`` grid (the issue's
  target: 500 x 500 per condition under 10 s, i.e. 40 us per pair);
* the certified search on as many scattered pairs (every ``alpha`` distinct: nothing
  for the per-``alpha`` screening of a grid to share);
* finite ``kappa``: the symbolic series (once per process), then per point of an
  ``f`` sweep (200 points, the table built in the timed call) and of ``alpha``-``f``
  maps at fixed ``kappa`` (one table per ``alpha``): the Taylor tables of the delay
  equations (:mod:`impactsym.rod.elastic.taylor`, the default) against the mpmath cell
  tables (:mod:`impactsym.rod.elastic.cells`) and the pointwise search on the pole sums
  alone (:func:`pointwise_pole_contact_times`, copied below: no table;
  ``--kappa-only`` runs this part alone);
* stiff springs: ``alpha``-``f`` maps at ``kappa = 1e2, 1e3, 1e4`` in ms per point, the
  slow-manifold table (:mod:`impactsym.rod.elastic.manifold`) where it applies
  (``--stiff-only [--repeat k]`` runs this part alone), and the search alone on the
  tables left by the call.

Stiff maps (issue 22, target < 1 ms per point), ``--stiff-only --repeat 3``, CPU ms per
point for ``N`` / ``y`` at ``kappa = 1e2, 1e3, 1e4``. Before the round-3 work (load 6-9)
2.40/1.98, 1.89/1.65, 1.94/1.78; after its first part 2.14/2.02, 1.70/1.53, 1.72/1.68.
Then (h33stiff), main and this branch run in turns, two runs each, on the 2-core machine
at load 3.5: main 2.12-2.16/1.94-1.95, 1.66-1.91/1.45-1.81, 1.73-1.89/1.54-1.87; now
1.09-1.10/0.83-0.91, 1.05-1.07/0.88-0.89, 0.98-1.06/0.92-0.94 (the search alone 0.31-0.36
for ``N``, 0.19-0.21 for ``y``; at load 5 the same): ``y`` under the target, ``N`` 5-10 %
above it. What changed: all
cells of a reflection interval are computed at once (float starts from the cells' affine
maps by a doubling scan, the Taylor recurrences, solves and Gauss-Seidel sweeps as NumPy
operations over the cells, the few ulps each start misses of the exact end before kept
as low parts of every coefficient, which the bound measures); the tables of all
``alpha`` of a call are built together, one pass per interval over the cells of all of
them, and searched together; ``(0.1, 1e2)``, whose poles are too near for slow cells,
gets Taylor cells graded as the layer's (88 per interval, not 256); the bound's sums
along the coefficients by pairwise two-sums. Where the time goes now (a profile of the
six maps): building the cells 29 %, their bound 30 % (``cell_bounds``: proportional to
the cells, the exact residuals and jumps), the search 34 %, setting up the tables 6 %.
Then (h33stiff2), main and this branch in turns: at load 2, two runs each, main
1.00-1.01/0.79-0.82, 0.95-0.98/0.79-0.81, 0.93-0.94/0.82-0.83; now 0.86-0.87/0.81-0.82,
0.83-0.86/0.81-0.83, 0.84-0.86/0.84-0.86 (the search alone for ``N`` 0.29-0.33 ->
0.26-0.29); at load 4-4.6, four runs each, ``N`` 0.98-1.09 -> 0.85-0.97. ``N`` under
the target, ``y`` as before (0-3 % slower: its bound in a second call). What changed: a
search for ``N`` bounds only ``N`` (the bound of ``y``, a quarter of the bound, is
computed when ``y`` is asked for, the same bits); the first cells of each reflection
interval whose polynomial their Bernstein coefficients prove positive (the true ``N``
above ``-1e-12``, the search's depth) are not searched (``N``
nearly touches zero at some reflection times while ``N'' ~ kappa^2``: the halving
took a dozen rounds there).

Times are CPU seconds of this process (``time.process_time``), robust against a
loaded machine; ``--repeat k`` quotes the best of ``k`` runs of the certified search.
The package imported is this checkout's (not an installed copy).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's package

from impactsym.numeric.roots import bracketed_newton
from impactsym.rod import contact_time
from impactsym.rod.kernel import rigid_local, rigid_tables


def sampled_contact_time(alpha, f, which, t_max=100.0):
    """The former library search (issue 11 baseline), rigid contact only."""
    a, ff = np.ravel(alpha).astype(float), np.ravel(f).astype(float)
    ua, a_idx = np.unique(a, return_inverse=True)
    n_intervals = int(np.ceil(t_max / 2.0))
    tables = rigid_tables(ua, n_intervals + 1)

    def fn(tau, m, p, derivative=False):
        p = p.astype(np.int64)
        return rigid_local(
            which, m.astype(np.int64), tau, a_idx[p], a[p], ff[p], tables, derivative
        )

    root_step = np.sqrt(a / 2.0) * np.pi / 16.0
    result = np.full(a.size, np.inf)
    active = np.arange(a.size)
    for m in range(n_intervals):
        if active.size == 0:
            break
        length = np.minimum(2.0, t_max - 2.0 * m) * np.ones(active.size)
        du = root_step[active] / np.sqrt(m + 1.0)
        n_steps = np.clip(np.ceil(np.sqrt(length) / du), 16, 8192).astype(np.int64)
        counts = n_steps + 1
        p = np.repeat(active, counts)
        first = np.cumsum(counts) - counts
        k_idx = np.arange(p.size) - np.repeat(first, counts)
        tau = np.repeat(length, counts) * (k_idx / np.repeat(n_steps, counts)) ** 2
        values = fn(tau, np.full(p.size, m), p)
        hit = (values <= 0) & (k_idx >= (1 if m == 0 else 0))
        position = np.where(hit, np.arange(p.size), p.size)
        first_hit = np.minimum.reduceat(position, first)
        found = first_hit < p.size
        if not found.any():
            continue
        idx, pairs = first_hit[found], active[found]
        lo, hi = tau[idx - 1], tau[idx]
        root = bracketed_newton(
            lambda x, mm, pp: fn(x, mm, pp),
            lambda x, mm, pp: fn(x, mm, pp, True),
            lo,
            hi,
            [np.full(pairs.size, float(m)), pairs.astype(np.float64)],
        )
        result[pairs] = 2.0 * m + root
        active = active[~found]
    return result.reshape(np.shape(alpha))


def brute_force(alpha, f, which, t_max=100.0, per_interval=20000):
    """First sample <= 0 on a uniform grid of ``per_interval`` points per interval."""
    out = np.full(alpha.size, np.inf)
    for i, (a, force) in enumerate(zip(alpha.ravel(), f.ravel(), strict=True)):
        for m in range(1, int(t_max // 2)):
            tau = np.linspace(0.0, 2.0, per_interval, endpoint=False)
            ua = np.array([a])
            tables = rigid_tables(ua, m + 1)
            g = rigid_local(
                which, np.full(tau.size, m), tau, np.zeros(tau.size, int), a, force, tables
            )
            below = np.flatnonzero(g <= 0)
            if below.size:
                out[i] = 2.0 * m + tau[below[0]]
                break
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100)
    parser.add_argument("--brute", type=int, default=60, help="pairs for the brute force")
    parser.add_argument(
        "--atlas", type=int, default=0, help="also time the certified search alone on this grid"
    )
    parser.add_argument("--repeat", type=int, default=1, help="best of this many runs")
    args = parser.parse_args()
    if args.atlas:
        atlas(args.atlas, args.repeat)
    A, F = np.meshgrid(np.geomspace(0.05, 10, args.n), np.linspace(0, 2, args.n))
    rng = np.random.default_rng(1)
    pick = rng.choice(A.size, size=min(args.brute, A.size), replace=False)
    for condition, which in (("force", "N"), ("position", "y")):
        t_new, new = best_of(args.repeat, contact_time, A, F, condition=condition)
        start = time.process_time()
        try:
            old = sampled_contact_time(A, F, which)
            note = ""
        except ValueError:  # issue 11: the whole grid can fail, its halves do not
            half = A.shape[0] // 2
            old = np.concatenate(
                [
                    sampled_contact_time(A[:half], F[:half], which),
                    sampled_contact_time(A[half:], F[half:], which),
                ]
            )
            note = " (raised ValueError on the whole grid; timed on its two halves)"
        t_old = time.process_time() - start
        differ = ~np.isclose(new, old, rtol=0, atol=1e-8) & ~(np.isinf(new) & np.isinf(old))
        start = time.process_time()
        brute = brute_force(A.ravel()[pick], F.ravel()[pick], which)
        t_brute = (time.process_time() - start) / pick.size
        late = np.sum(new.ravel()[pick] > brute + 2.0 / 20000)
        print(
            f"{condition:8s} {A.size} pairs: certified {t_new:.2f} s "
            f"({1e6 * t_new / A.size:.0f} us/pair), sampled {t_old:.2f} s "
            f"({1e6 * t_old / A.size:.0f} us/pair), speed-up {t_old / t_new:.2f}x; "
            f"sampled differs at {int(differ.sum())} pairs; brute force "
            f"{1e3 * t_brute:.0f} ms/pair, certified later than brute force at {int(late)} "
            f"of {pick.size}{note}"
        )
        # scattered pairs: every alpha distinct, so nothing is shared
        alpha = np.exp(rng.uniform(np.log(0.05), np.log(10.0), A.size))
        force = rng.uniform(0.0, 2.0, A.size)
        t_scattered, _ = best_of(args.repeat, contact_time, alpha, force, condition=condition)
        print(
            f"{condition:8s} {A.size} scattered pairs (distinct alpha): certified "
            f"{t_scattered:.2f} s ({1e6 * t_scattered / A.size:.0f} us/pair)"
        )


def best_of(repeat, fn, *args, **kwargs):
    """Least CPU time of ``repeat`` calls and the last result."""
    best = np.inf
    for _ in range(max(repeat, 1)):
        start = time.process_time()
        out = fn(*args, **kwargs)
        best = min(best, time.process_time() - start)
    return best, out


def atlas(n: int, repeat: int = 1) -> None:
    """CPU time of the certified search alone on an ``n x n`` atlas, per condition."""
    A, F = np.meshgrid(np.geomspace(0.05, 10, n), np.linspace(0, 2, n))
    for condition in ("force", "position"):
        spent, _ = best_of(repeat, contact_time, A, F, condition=condition)
        print(
            f"{condition:8s} {n} x {n} atlas: {spent:.2f} s CPU ({1e6 * spent / A.size:.1f} "
            f"us/pair; issue 11 target: 500 x 500 under 10 s, 40 us/pair)"
        )


def pointwise_pole_contact_times(which, alpha, f, kappa, t_max):
    """The first finite-kappa search: every pair on its own on the pole sums alone (no
    table), from a uniform grid of initial nodes; flat arrays ``alpha, f, kappa``."""
    from impactsym.numeric.isolation import first_sign_change
    from impactsym.rod.elastic.search import check_stiffness, pole_search
    from impactsym.rod.elastic.taylor import fastest_rate

    result = np.full(alpha.size, np.inf)
    n_terms = int(t_max // 2) + 1
    keys = np.stack([alpha, kappa], axis=1)
    groups, inverse = np.unique(keys, axis=0, return_inverse=True)
    for g_index, (ag, kg) in enumerate(groups):
        members = np.flatnonzero(inverse.ravel() == g_index)
        ag, kg = float(ag), float(kg)
        check_stiffness(ag, kappa=kg)
        evaluate, bound = pole_search(which, ag, f[members], kappa=kg, n_terms=n_terms)
        step = min(0.1, 0.25 * ag, 0.5 / np.sqrt(fastest_rate(ag, kappa=kg)))
        base = np.union1d(
            np.linspace(0.0, t_max, int(np.ceil(t_max / step)) + 1),
            np.arange(2.0, t_max, 2.0),
        )
        owner = np.repeat(np.arange(members.size), base.size)
        nodes = np.tile(base, members.size)
        roots = first_sign_change(evaluate, bound, nodes, owner, members.size, max_cells=2**22)
        hit = np.isfinite(roots)
        result[members[hit]] = roots[hit]
    return result


def finite_stiffness() -> None:
    """Finite ``kappa`` (issue 11, item 3): the Taylor tables of the delay equations
    (``method="taylor"``, the default) against the mpmath cell tables of the pole data
    (``"cells"``, the method before) and the pointwise search on the pole sums
    (``"poles"``, the first method), on ``f`` sweeps at fixed ``(alpha, kappa)`` and on
    ``alpha``-``f`` maps at fixed ``kappa`` (every table build counted)."""
    from impactsym.rod.elastic import poles as pole_sums
    from impactsym.rod.elastic.cells import cell_table
    from impactsym.rod.elastic.search import elastic_contact_times
    from impactsym.rod.elastic.taylor import taylor_table

    def cold(which, alpha, f, kappa, method):
        """CPU seconds of one call with every table and pole model built anew."""
        for cache in (cell_table, taylor_table):
            cache.cache_clear()
        pole_sums.clear_cache()
        start = time.process_time()
        if method == "poles":
            out = pointwise_pole_contact_times(which, alpha, f, kappa, 20.0)
        else:
            out = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0, method=method)
        return out, time.process_time() - start

    start = time.process_time()
    pole_sums.series_coefficients("N", 11), pole_sums.series_coefficients("y", 11)
    print(f"finite kappa: symbolic series (once per process) {time.process_time() - start:.2f} s")
    print("  ms per point, tables built in the call; max |difference| to 'poles'")
    f = np.linspace(0.0, 2.0, 200)
    sub = slice(None, None, 10)  # the pointwise search costs the same per point at any count
    for a, k in ((1.3, 20.0), (0.7, 30.0), (0.05, 10.0), (1.0, 4.0), (50.0, 2.0)):
        alpha, kappa = np.full(f.size, a), np.full(f.size, k)
        for which in ("N", "y"):
            taylor, t_taylor = cold(which, alpha, f, kappa, "taylor")
            cells, t_cells = cold(which, alpha, f, kappa, "cells")
            poles, t_poles = cold(which, alpha[sub], f[sub], kappa[sub], "poles")
            diffs = []
            for new in (taylor[sub], cells[sub]):
                both = np.isfinite(new) & np.isfinite(poles)
                same = np.array_equal(np.isinf(new), np.isinf(poles))
                diff = np.max(np.abs(new[both] - poles[both]), initial=0.0)
                diffs.append(diff if same else np.inf)
            print(
                f"  f sweep (200) alpha={a}, kappa={k}, {which}: taylor "
                f"{1e3 * t_taylor / f.size:.2f}, cells {1e3 * t_cells / f.size:.2f}, poles "
                f"{1e3 * t_poles / poles.size:.1f} ms/point; |taylor - poles| {diffs[0]:.1e}, "
                f"|cells - poles| {diffs[1]:.1e}"
            )
    # dense-sampling brute force on the pole sums (the public y(t), N(t), not the tables)
    from impactsym.rod import contact_force, displacement

    t = np.linspace(0.0, 20.0, 40001)[1:]
    for a, k in ((1.3, 20.0), (0.05, 10.0), (5.0, 3.0)):
        f = np.linspace(0.0, 2.0, 11)  # seconds per point: the pole sums at 40000 samples
        for which, fn in (("N", contact_force), ("y", displacement)):
            certified, _ = cold(which, np.full(f.size, a), f, np.full(f.size, k), "taylor")
            start = time.process_time()
            brute = []
            for x in f:
                below = np.flatnonzero(fn(t, a, x, kappa=k) <= 0.0)
                brute.append(t[below[0]] if below.size else np.inf)
            t_brute = (time.process_time() - start) / f.size
            brute = np.array(brute)
            step = t[1] - t[0]
            later = np.sum(brute < certified - 1e-12)  # a root the certified search missed
            both = np.isfinite(brute) & np.isfinite(certified)
            apart = np.sum(~np.equal(np.isinf(brute), np.isinf(certified))) + np.sum(
                brute[both] - certified[both] > step
            )
            print(
                f"  brute force (40000 samples) alpha={a}, kappa={k}, {which}: "
                f"{1e3 * t_brute:.1f} ms/point; certified later than a sampled sign change: "
                f"{later}, apart by more than a sample: {apart} of {f.size}"
            )
    for n_alpha, n_f, k in ((10, 50, 20.0), (40, 50, 20.0), (20, 100, 4.0)):
        A, F = np.meshgrid(np.geomspace(0.1, 10.0, n_alpha), np.linspace(0.0, 2.0, n_f))
        alpha, kappa = A.ravel(), np.full(A.size, k)
        for which in ("N", "y"):
            taylor, t_taylor = cold(which, alpha, F.ravel(), kappa, "taylor")
            line = (
                f"  alpha-f map {n_alpha} x {n_f} at kappa={k}, {which}: taylor "
                f"{1e3 * t_taylor / A.size:.2f} ms/point"
            )
            if n_alpha == 10:  # the mpmath cell tables take minutes on the larger maps
                cells, t_cells = cold(which, alpha, F.ravel(), kappa, "cells")
                both = np.isfinite(taylor) & np.isfinite(cells)
                diff = np.max(np.abs(taylor[both] - cells[both]), initial=0.0)
                same = np.array_equal(np.isinf(taylor), np.isinf(cells))
                line += (
                    f", cells {1e3 * t_cells / A.size:.2f} ms/point ({t_cells / t_taylor:.0f}x); "
                    f"|taylor - cells| {diff:.1e}, inf agree {same}"
                )
            print(line + f" ({n_alpha} table builds included)")


def stiff_maps(repeat: int = 1) -> None:
    """Stiff springs (issue 22): ``alpha``-``f`` maps (5 x 20, one table per ``alpha``,
    built in the timed call as far as its contacts need) at ``kappa = 1e2 .. 1e4`` with the
    default method; the target is under 1 ms per point up to ``kappa = 1e4``. Per map: the
    CPU time of the call (best of ``repeat``, every cache cleared before each), and of the
    same call once more on the tables it left (the search alone: what the table build
    costs is the difference)."""
    from impactsym.rod.elastic import poles as pole_sums
    from impactsym.rod.elastic.cells import cell_table
    from impactsym.rod.elastic.manifold import manifold_table
    from impactsym.rod.elastic.search import elastic_contact_times
    from impactsym.rod.elastic.taylor import taylor_table

    pole_sums.series_coefficients("N", 11), pole_sums.series_coefficients("y", 11)  # once
    A, F = np.meshgrid(np.geomspace(0.1, 10.0, 5), np.linspace(0.0, 2.0, 20))
    alpha, f = A.ravel(), F.ravel()
    for k in (1e2, 1e3, 1e4):
        kappa = np.full(A.size, k)
        for which in ("N", "y"):
            cold = warm = np.inf
            for _ in range(max(repeat, 1)):
                for cache in (cell_table, taylor_table, manifold_table):
                    cache.cache_clear()
                pole_sums.clear_cache()
                start = time.process_time()
                out = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0)
                cold = min(cold, time.process_time() - start)
                pole_sums.clear_cache()
                start = time.process_time()
                elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0)
                warm = min(warm, time.process_time() - start)
            print(
                f"  stiff alpha-f map 5 x 20 at kappa={k:g}, {which}: "
                f"{1e3 * cold / A.size:.2f} ms/point (target < 1; search alone "
                f"{1e3 * warm / A.size:.2f}), {np.isfinite(out).sum()} finite"
            )


if __name__ == "__main__":
    if "--stiff-only" in sys.argv:
        at = sys.argv.index("--repeat") + 1 if "--repeat" in sys.argv else 0
        stiff_maps(int(sys.argv[at]) if at else 1)
        sys.exit()
    if "--kappa-only" not in sys.argv:
        main()
    finite_stiffness()
    stiff_maps()
