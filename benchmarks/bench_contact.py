"""Benchmark of the spring-damper contact (paper section 2, impactsym.contact.api).

Prints, measured in one run:
  * contact_time on a 1000 x 1000 (D, f) grid, per condition (target < 2 s);
  * contact_time and restitution of 10^5 unpressed contacts (f = 0): the closed forms
    (impactsym.contact.unpressed) against the kernel's bracketed root they replace;
  * speed-up per point over scipy.integrate.solve_ivp with events (target >= 10,000);
  * max relative error against a 30-digit mpmath reference (target <= 1e-12);
  * stick_boundary at 1000 values of f: time (target < 0.1 s) and error (<= 1e-12).

Run: python benchmarks/bench_contact.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import mpmath as mp
import numpy as np
from scipy.integrate import solve_ivp
from timing import best_of

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from references.oscillator import contact_function, refine_root

from impactsym import contact_time, restitution, stick_boundary
from impactsym.contact.kernel import first_release

CONDITIONS = ("position", "force")


def solve_ivp_contact(d, f, condition):
    def event(_t, y):
        return y[0] if condition == "position" else 2 * d * y[1] + y[0]

    event.terminal, event.direction = True, -1
    sol = solve_ivp(
        lambda _t, y: [y[1], 2 * d * f - 2 * d * y[1] - y[0]],
        (0, 100),
        [0.0, 1.0],
        events=event,
        rtol=1e-10,
        atol=1e-12,
    )
    return sol.t_events[0][0] if sol.t_events[0].size else np.inf


def boundary_reference(f, condition, guess):
    """30-digit D* from the first minimum of g (g' = 0 polished near the float ridge)."""
    from impactsym.contact.kernel import kernels

    def minimum(d):
        ridge = float(kernels(condition=condition).ridge(np.array([float(d)]), np.array([f]))[0])

        def slope(t):
            h = mp.mpf("1e-12")
            return (
                contact_function(t + h, d, f, condition, 45)
                - contact_function(t - h, d, f, condition, 45)
            ) / (2 * h)

        t_min = mp.findroot(slope, (ridge * (1 - 1e-6), ridge * (1 + 1e-6)), solver="secant")
        return contact_function(t_min, d, f, condition, 45)

    with mp.workdps(30):
        return mp.findroot(minimum, (guess * (1 - 1e-7), guess * (1 + 1e-7)), solver="secant")


def main() -> None:
    print("impactsym benchmark: spring-damper contact (section 2)")
    D, f = np.meshgrid(np.linspace(0, 1.5, 1000), np.linspace(0, 1, 1000))
    contact_time(0.3, 0.3, condition="position")  # build the lambdified kernels once
    contact_time(0.3, 0.3, condition="force")
    per_point = {}
    for condition in CONDITIONS:
        seconds, grid = best_of(3, contact_time, D, f, condition=condition)
        per_point[condition] = seconds / D.size
        print(
            f"  contact_time, 10^6-point grid, {condition:8s}: {seconds:.3f} s "
            f"(target < 2 s; {np.isfinite(grid).mean():.0%} release)"
        )

    D0 = np.linspace(0.0, 1.5, 10**5)
    zero = np.zeros_like(D0)
    for condition in CONDITIONS:
        closed, _ = best_of(
            3,
            lambda c=condition: (
                contact_time(D0, 0.0, condition=c),
                restitution(D0, 0.0, condition=c),
            ),
        )
        root, _ = best_of(1, first_release, D0, zero, condition=condition)
        print(
            f"  unpressed contact_time + restitution, 10^5, {condition:8s}: {closed * 1e3:.1f} ms "
            f"(closed forms); the kernel's root alone {root * 1e3:.0f} ms"
        )

    rng = np.random.default_rng(0)
    sample = list(zip(rng.uniform(0, 1.2, 40), rng.uniform(0, 1, 40), strict=True))
    for condition in CONDITIONS:
        start = time.perf_counter()
        for d, fr in sample:
            solve_ivp_contact(d, fr, condition)
        ivp = (time.perf_counter() - start) / len(sample)
        print(
            f"  solve_ivp with events, {condition:8s}: {ivp * 1e3:.2f} ms/point; speed-up of "
            f"contact_time {ivp / per_point[condition]:,.0f}x (target >= 10,000x)"
        )

    for condition in CONDITIONS:
        d = rng.uniform(0, 3, 400)
        fr = rng.uniform(0, 2, 400)
        d_star = stick_boundary(fr, condition=condition)
        away = np.abs(d - d_star) > 0.02 * np.minimum(d_star, 1)
        tau = contact_time(d[away], fr[away], condition=condition)
        release = np.isfinite(tau)
        errors = [
            abs(t - float(refine_root(t, di, fi, condition, dps=30))) / t
            for t, di, fi in zip(tau[release], d[away][release], fr[away][release], strict=True)
        ]
        print(
            f"  max rel. error vs 30-digit mpmath, {condition:8s}: {max(errors):.2e} "
            f"over {len(errors)} released points (target <= 1e-12)"
        )

    f_values = np.geomspace(1e-3, 20, 1000)
    for condition in CONDITIONS:
        stick_boundary(f_values[:2], condition=condition)
        seconds, d_star = best_of(5, stick_boundary, f_values, condition=condition)
        check = f_values[::100]
        errors = [
            abs(float(ds) - float(boundary_reference(fv, condition, float(ds)))) / ds
            for fv, ds in zip(check, d_star[::100], strict=True)
        ]
        print(
            f"  stick_boundary, 1000 f values, {condition:8s}: {seconds * 1e3:.1f} ms "
            f"(target < 100 ms); max rel. error {max(errors):.2e} at {len(check)} points "
            f"(target <= 1e-12)"
        )


if __name__ == "__main__":
    main()
