"""Drake and PyBullet designs: 10^5 targets each, against the 2 s target.

Prints, after one warm-up call per case, the seconds of ``pybullet.contact_for`` (default
``timestep = 1/240``; gravity 0 and 9.81 m/s^2; ``contact_time`` given or left at its
default of 10 steps) and ``drake.point_contact_for`` (continuous ``time_step = 0`` and the
default ``time_step = 1e-3`` with ``"lagged"``; ``contact_time`` or ``max_penetration``;
gravity 0 and 9.81 m/s^2) on ``N`` random targets (array ``restitution`` and
``contact_time``/``max_penetration``; one speed 1 m/s and mass 0.1 kg), and the time
scaled to 10^5 designs over the 2 s target, with the largest relative miss of the
designs' restitution. ``--quick``: ``N = 10^3`` (the 10^5 column
then extrapolates linearly); ``--count N`` sets it.

Run: ``PYTHONPATH=. python benchmarks/bench_drake_pybullet.py [--quick]`` (from the
repository root).

Measured with ``--quick`` (10^3 designs, 2 cores shared with other jobs, low load),
seconds per 10^3 designs, before -> after the speed-ups (PyBullet: break points in
closed form, ``phase_means``; Drake: only unconverged designs iterated, the size from the
damping root's own evaluations, narrow warm brackets, fewer phases per search call for
many brackets), the factor over the 2 s target after:

* PyBullet, g = 0: contact_time array 15.3 -> 2.7 (137 x); default contact_time -> 1.1
  (56 x).
* PyBullet under gravity: these 10^3-target arrays were refused (Newton from the
  textbook start missed designs that exist, e.g. e = 0.4431 at 10 steps).
* PyBullet from a table (from ``TABLE_GROUP`` = 256 targets of one contact; a table
  costs a fixed ~2000 evaluations, so time ``--count 100000``, not ``--quick``), with the
  phase means in passes of 8192 designs (10^5 at once ran out of the cache) and their
  roots ahead found without stacking (1.9 x): ``--count 10000`` at load ~5, seconds
  per 10^4 and exact evaluations per design, before -> after: contact_time array
  10.9 -> 2.5 (14.4 -> 3.65), default 5.9 -> 0.90 (16.2 -> 2.19); under gravity refused
  after 6.2 and 6.3 s -> designed in 1.08 and 1.12 (2.24; every target).
  ``--count 100000`` (load 4.5-5.5): 28.1, 8.7, 10.5, 12.8 s, i.e. 14, 4.3, 5.2 and 6.4 x
  the target.
* PyBullet, each exact phase mean cheaper and none repeated: every piece's restitution
  integrated in closed form from the quadratic its tracked run carries (no runs at Gauss
  nodes), the prediction with its ranges taken from the evaluation that accepted each
  design (no second evaluation), the roots ahead solved only at the sub-steps next to a
  change of branch, tracked runs that end at a separating end without gravity, passes of
  contacts of like length, the table's inverse without three-operand einsums. CPU
  seconds (``time.process_time``) per 10^5, ``--count 100000``, load ~5, main and this
  measured back to back, before -> after: contact_time array 19.8 -> 4.2, default
  7.6 -> 1.6; under gravity 6.8 -> 2.1 and 7.5 -> 2.2 (2.1, 0.8, 1.04 and 1.1 x the
  target); designs and predictions as before to 1e-14 (ranges 2e-13).
* PyBullet without gravity, each exact phase mean searched from one phase interval
  where every phase provably ends final (the branch quantities are linear in the phase,
  so their roots see every change up to the end state, and a contact that ends
  separating within its step budget changes nothing after it; the others on the grid
  of 8): 6 runs of the map per design and evaluation instead of 13, passes of 4 x 8192
  designs, pattern-only check runs. CPU seconds per 10^5 (``time.process_time``, one
  warm-up call of 10 targets, then the call; ``_cases(100000)``), main and this back to
  back, load 2-2.5, before -> after: contact_time array 3.9 -> 1.7-1.8 (still 3.05
  exact evaluations per design), default 1.5 -> 0.75; under gravity 1.7 and 1.8-1.9 as
  before (the same path and numbers). Designs from the table (this path) and
  predictions as before to 1e-14 (ranges 1e-13); small calls, whose designs Newton
  iterates from the textbook start on the exact means, land up to a few 1e-12
  (relative) away (10 calls, e 0.2-0.6, 6-15 steps: damping 3.4e-12, stiffness 2e-13,
  the designs' predicted restitution 1e-12, contact time 3e-14; the means' rounding
  carried through the iteration, well within the 1e-9 acceptance). Contacts
  that stick at some phases leave the one-interval search at their first failing end
  (before, up to 12 rounds each to their step budget, then the grid): 2000 random
  contacts without gravity, a third of them sticking at some phases, ``predict`` with
  one and two sub-steps, main vs this (best of 2, load 1-1.8): 3.3 vs 3.3 s and 5.1 vs
  5.2 s (2-3 x main before); the map's loop iterations 102456 vs 106512 and 104034 vs
  109711, its element-steps 8-9% fewer.
* PyBullet, the same numbers for less (designs and predictions bit-identical on these
  four cases and 406 random calls): the table's interpolant and inverse in passes of
  8192 columns (a coarse box that grows inverted only at its edge targets), glibc's
  malloc thresholds raised once (``numeric.memory``; the interpolation's 25 MB
  temporaries had raised them by accident, without which the passes fault in fresh
  pages, 1.5-3.4e5 faults a call), the roots ahead sought only within the piece
  search's interval, the pieces merged by an integer sort. CPU seconds per 10^5 (the
  ``_cases(100000)`` timing below, main and this back to back, 2 x 3 runs each, load
  4-6), before -> after: g = 0 array 1.80-1.97 -> 1.62-1.82, default 0.74-0.77 ->
  0.67-0.75; under gravity 1.60-1.74 -> 1.26-1.42 (array) and 1.75-1.94 -> 1.41-1.58
  (default).
* Drake continuous, g = 0: 0.015 (0.76 x: under the target).
* Drake continuous, g = 9.81: 11.0 -> 5.1 (contact_time, 254 x), 5.7 (max_penetration);
  from 128 targets per call the designs are read off one Chebyshev table in (s, b)
  (``drake.pressed_table``). CPU seconds (one BLAS thread, load 4-8), ``--count 100000``:
  about 160 -> 0.77 (contact_time) and 0.42 (max_penetration): 0.4 and 0.2 x the target
  (at 10^3 the table's fixed cost, ~0.05 s, makes the scaled column 2.5 x).
* Drake lagged 1e-3: 284 -> 18.9 (contact_time, 943 x), 23.6 (max_penetration), g = 0;
  20.3 and 27.6, g = 9.81 (1000-1400 x). From 256 targets sharing g/v per call the
  designs start from a table of the phase means in (s, w = h sqrt(k/m)) and finish by
  Broyden steps on the exact phase means, the few next to a plateau's edge by a walk
  along the restitution's contour (``drake.step_table``, ~5.5 phase means per design
  instead of ~20). CPU seconds per 10^3 (one thread, load 4-8), before -> after:
  8.1 -> 1.9 and 10.2 -> 2.1 (g = 0), 11.2 -> 1.7 and 12.6 -> 2.2 (g = 9.81), still
  85-105 x the target. At 10^4 targets 12.0, 14.4 (g = 0) and 13.5, 14.2 (g = 9.81):
  120-145 s per 10^5, 60-72 x; there the iteration alone refused the array (g = 0,
  contact_time: a target 7e-5 steps from a plateau's edge).
* Drake lagged 1e-3, each change of the end step located by a root of the end margin
  (``drake.phases``: ~20 margins per change instead of 63 contacts) instead of
  multisection: CPU seconds per 10^5 from 10^4 targets (these cases, the call timed by
  ``time.process_time``, load 1.6), before -> after: 115.3 -> 87.0 and 130.8 -> 99.6
  (g = 0), 124.9 -> 95.7 and 129.5 -> 97.1 (g = 9.81): still 44-50 x. Gauss nodes stay
  at 5 (4 move the mean by 5e-13).
* Drake lagged 1e-3, the phase means' contacts run by a lean loop (``drake.stepping``
  ``contact_ends``: the update's constants once per contact, finished contacts gathered
  out instead of masked field by field, blocks of 16384 that stay in the cache; the end
  margins stepped the same way), and the pieces' ends taken from the grid and the jump
  searches instead of run again: the same designs, predictions and phase means bit for
  bit. CPU seconds per 10^5 from 10^4 targets (the call timed by ``time.process_time``,
  main and this back to back, load 0.9-1.2), before -> after: 87.3 -> 28.7 and
  96.5 -> 28.4 (g = 0), 95.7 -> 34.7 and 94.9 -> 29.0 (g = 9.81): 14-17 x the target.
  One phase mean of 10^4 designs takes 0.30-0.34 s (1.03-1.12 s before); at 10^4 about
  1 s of each call is the tail, ~100-200 phase means of a few designs each (the
  Broyden stragglers, the plateau-edge walks, the targets left to the iteration) at
  ~7-14 ms apiece, mostly NumPy's per-call overhead in the root search's margins.
* A refusal from a big call under gravity (256 lagged targets over 8-100 steps, one with
  e = 0.999): 136 s CPU -> 2.3 s (the table's box reached settled corners stepped to
  2e6 updates; they are now decided by their energy).
* Drake lagged 1e-3, the phase means' root search one margin per bracket and call
  (``drake.phases._roots``: a quadratic-corrected falsi stepped just past its estimate;
  fans of phases for the last few brackets): ~10 margins per change instead of ~21, half
  the calls for small batches. CPU seconds per 10^4 targets (``time.process_time``,
  main and this back to back 3 times, load 3-3.5), before -> after: 2.83-3.11 ->
  2.34-2.56 and 2.85-2.97 -> 2.44-2.69 (g = 0), 3.39-3.48 -> 2.81-3.28 and
  2.87-2.94 -> 2.49-2.88 (g = 9.81); designs as before to 1.2e-13 for 99% (2000 per
  case; a few in 10^3 move within the iteration's 1e-10).
* Drake lagged 1e-3, the phase summary's pieces the quarters of the phase cut at the
  changes, 7 Gauss nodes each (35 runs per design instead of 45; the mean 0.8-1.4e-14
  from 16 nodes at the 99th percentile, the former 5 per eighth 3-5e-14): ``predict``
  of 10^5 designs of 20-40 steps (CPU seconds, one run each, load ~3-4), main -> the
  root search -> the quarters: 4.65 -> 3.49 -> 2.62 (g = 0), 5.43 -> 4.29 -> 3.59
  (g = 9.81).
* Drake lagged 1e-3, the change's equations (``drake.jump_means``): the end state
  changes once over the phase, so by contact time the target fixes where, and by largest
  overlap the design carries its estimate; the restitution's pieces and the end margin
  there are smooth in the parameters (no plateau, no search), 27 state runs per
  evaluation instead of ~65 contact runs and ~19 margins, from a Jacobian of differences
  of the panels' midpoint rule (~4.3 evaluations per design instead of ~6), the overlap
  read at the last grid phase (one run). CPU seconds per 10^5, ``_cases(100000)``, main
  and this back to back (load 1.5-3), before -> after: 28.9 -> 10.8 and 28.5 -> 13.8 (g
  = 0, contact_time and max_penetration), 26.0 -> 13.3 and 27.9 -> 14.9 (g = 9.81).
  About 4 s of each is the prediction the designs return (one phase summary with
  ranges).

What stays over the target is the exact phase mean itself: one evaluation for 10^5 designs
takes ~0.6-1.5 s (PyBullet, ``root_summary``, in passes of 8192; ~4 s, and ~25 s, before:
tracked runs of the map from 8 grid phases and each root, ~10 per design) and 16-20 s CPU
(Drake lagged, without the range search, designs of 20-40 steps, g = 0 and 9.81; 22-26 s
with the multisection; ~3 s since the lean loop; ~2 s since the one-margin root search
and the quarter pieces, most of it the Gauss nodes and the grid), and
a design takes 10-50 of them (Drake lagged from a table: ~5.5, since the change's
equations ~4.3 of a quarter the cost; PyBullet from a table: 2,
or ~3 for the contact_time array, whose table cells mostly hold a kink; its prediction
comes free). A table per step ratio (the targets share speed and mass), inverted, cuts
the evaluations to one or two per design; below 2 s needs more: designs read from a
table whose error is bounded without a per-design evaluation, or a compiled step loop.

* Drake lagged 1e-3, designs read off tables of exact designs, one per end state (and
  per plateau between two), each confirmed by one exact evaluation that is also its
  prediction (``drake.change_table``, ``jump_means.jump_summary``), on step loops about
  20 % cheaper per update (bit-identical). CPU seconds per 10^5 (``_cases(100000)``,
  load ~2), before -> after: 10.0 -> 2.06 and 12.8 -> 3.64 (g = 0, contact_time and
  max_penetration), 10.9 -> 2.26 and 13.2 -> 3.92 (g = 9.81). Read off the tables:
  99.3 % and 96 % of the contact-time targets, 97.5 % and 96 % of the overlap ones
  (their contacts last 36-60 steps, the others 20-40).

* Drake lagged 1e-3, the one evaluation cheaper (``jump_summary``: the restitution's
  range by six parabolic steps from its own samples, 0.14 of a phase apart at most,
  instead of two zoom rounds first, ~20 runs per extreme; its bookkeeping in blocks;
  state B + 1 one update after B instead of a run from touch), targets beyond a table's
  narrower window of phases read off it extrapolated where the evaluation holds (61 % of
  the 3994 phase-end targets under gravity, which all took the slow path), boxes of 256
  targets from 1024 in a call, the tables' leftovers to the table of means whatever
  their count, Newton for the overlap's phase from the secant root. CPU seconds per 10^5
  (``_cases(100000)``, load 1.4-1.9, two runs each, after the reviews' mends), before ->
  after: 2.06 -> 1.51-1.55 and 3.46 -> 3.01-3.17 (g = 0, contact_time and
  max_penetration), 2.22 -> 1.70-1.75 and 3.38 -> 3.10-3.19 (g = 9.81). The one
  evaluation: 1.4-1.75 s -> 0.9-1.2 s.

* Drake lagged 1e-3 (stop 39): the step loops in preallocated buffers, the end test
  against the impulse floor per block, no turning test without gravity (bit-identical;
  ``drake.stepping``); one Gauss panel per piece in the change's equations, 12 node runs
  per evaluation instead of 15 (``drake.jump_means``); the one evaluation in parts of
  32768 designs (its arrays below the 4 MiB from which NumPy asks for huge pages, whose
  faults stalled on compaction: 1.4 s -> 1.1 s in a call); by overlap 8 phase nodes per
  table, the likely end state's table first, plateau tables from 32 targets with 6 nodes
  solved together, the tables' overlaps from one run; the evaluation's refusals under
  gravity (a second change next to the phase's ends) by Broyden's steps from the table's
  own design (0.86 -> 0.44 s); the tables' nodes on a 16 x 24 table of means with the
  evaluation's rule. CPU seconds per 10^5 (``_cases(100000)``, one case per process,
  quiet machine), main -> this: 1.57 -> 1.00, 2.97 -> 1.85 (g = 0, contact_time and
  max_penetration), 1.74 -> 1.46, 3.05-3.3 -> 2.13 (g = 9.81).
* Drake lagged 1e-3 (stop 40): the targets whose end state changes twice (a change
  next to each end of the phase interval; about 2 % under gravity, by overlap and by
  contact time) designed on the equations of two changes (``drake.two_changes``:
  three Gauss pieces at Newton estimates of the changes) instead of six exact phase
  means each by overlap (0.40 -> 0.12 s) or the per-call table of means by contact time
  (0.46 -> 0.05 s); the table's starts in one walk over its columns (0.08 -> 0.04 s);
  the tables read in turns with one Newton for many tables (0.23 -> 0.17 s); the
  summary's grid run to its known end states (``stepping.ended_at``, bit for bit:
  0.31 -> 0.27 s). CPU seconds per 10^5 (``_cases(100000)``, one case per process,
  quiet machine), main -> this: 1.01-1.02 -> 0.87-0.95, 1.83 -> 1.68-1.69 (g = 0,
  contact_time and max_penetration), 1.42-1.45 -> 0.91-0.92, 2.08-2.11 -> 1.53-1.55
  (g = 9.81).

Where it stands (seconds per 10^5, this script, quiet machine): PyBullet 1.60 (g = 0,
contact_time array), 0.67 (g = 0, default), 1.26 and 1.38 (under gravity); Drake
continuous 0.09-0.37; Drake lagged 1e-3 0.82, 1.60 (g = 0, contact_time and
max_penetration), 0.90, 1.55 (g = 9.81): every case under the target, the slowest at
0.80 of it. Of Drake's by largest overlap without gravity (1.6-1.7 s) the one
evaluation per design takes 0.8 s (about 24 runs of the contact: the update is at
NumPy's limit, 5-6 ns per contact and update), the tables' nodes 0.27 s, the phases
read off the tables 0.18 s, the plateaus 0.14 s, the targets no table serves 0.13 s
(mostly the per-call tables of means).
"""

from __future__ import annotations

import argparse
import contextlib

import numpy as np
from timing import best_of

from impactsym.engines import drake, pybullet

TARGET = 2.0  # seconds for 10^5 designs
FULL = 100_000
SPEED, MASS = 1.0, 0.1


def _cases(n: int):
    """(label, function, options) per case. The targets lie where the designs exist
    (PyBullet under gravity included: Newton from the textbook start misses some, e.g.
    e = 0.4431 at 10 steps, which the table's starts reach; a target refused is reported
    as such)."""
    rng = np.random.default_rng(20)
    h_pb = 1 / 240
    e_pb = rng.uniform(0.2, 0.5, n)
    t_pb = rng.uniform(10.0, 40.0, n) * h_pb  # 10 to 40 PyBullet steps
    e_pg = rng.uniform(0.4, 0.45, n)  # under gravity: a band where every phase leaves
    t_pg = rng.uniform(9.8, 10.2, n) * h_pb
    for g, e, t in ((0.0, e_pb, t_pb), (9.81, e_pg, t_pg)):
        for given in (t, None):
            what = "array" if given is not None else "default"
            yield (f"pybullet.contact_for, g={g}, contact_time={what}", pybullet.contact_for,
                   {"restitution": e, "contact_time": given, "gravity": g})  # fmt: skip
    e_dc = rng.uniform(0.35, 0.9, n)
    t_dc = rng.uniform(1e-3, 2e-2, n)  # continuous: 1 to 20 ms
    x_dc = rng.uniform(1e-4, 1e-3, n)
    e_dl = rng.uniform(0.3, 0.6, n)
    t_dl = rng.uniform(2e-2, 4e-2, n)  # at 1e-3 s: 20 to 40 steps
    x_dl = rng.uniform(6e-3, 1.2e-2, n)
    for g in (0.0, 9.81):
        for step, e, t, x in ((0.0, e_dc, t_dc, x_dc), (1e-3, e_dl, t_dl, x_dl)):
            mode = "continuous" if step == 0 else "lagged 1e-3"
            base = {"restitution": e, "gravity": g, "time_step": step}
            yield (f"drake.point_contact_for, {mode}, g={g}, contact_time", drake.point_contact_for,
                   {**base, "contact_time": t})  # fmt: skip
            yield (f"drake.point_contact_for, {mode}, g={g}, max_penetration",
                   drake.point_contact_for, {**base, "max_penetration": x})  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^3 designs per case")
    parser.add_argument("--count", type=int, default=None, help="designs per case")
    parser.add_argument("--only", default="", help="run the cases whose label holds this")
    args = parser.parse_args()
    n = args.count or (1_000 if args.quick else FULL)
    print(f"{n} designs per case (speed {SPEED} m/s, mass {MASS} kg); 10^5 column scaled")
    for label, fn, options in _cases(n):
        if args.only not in label:
            continue
        first = {key: (val[:10] if isinstance(val, np.ndarray) else val)
                 for key, val in options.items()}  # fmt: skip
        with contextlib.suppress(ValueError):  # warm-up: caches, imports
            fn(speed=SPEED, mass=MASS, **first)
        try:
            seconds, out = best_of(1, fn, speed=SPEED, mass=MASS, **options)
        except ValueError as refused:  # a target out of reach: say so, time the others
            print(f"  {label:<66s} refused: {str(refused)[:160]}")
            continue
        full = seconds * FULL / n
        miss = np.max(np.abs(out.restitution / options["restitution"] - 1.0))
        print(f"  {label:<66s} {seconds:8.3f} s   10^5: {full:9.2f} s = {full / TARGET:8.2f} x 2 s"
              f"   e miss {miss:.1e}")  # fmt: skip


if __name__ == "__main__":
    main()
