"""Benchmark of the paper's questions for the nonlinear laws (impactsym.contact.lawstick,
lawgrid, lawbounce).

Prints, measured in one run (the first call of each law also lambdifies its forms):
  * law_stick_boundary on 20 damping numbers in [0.1, 3], per law and condition
    (default rtol 1e-10), and the number of passes that takes;
  * law_contact_map on a 40 x 40 grid (1600 impacts), per law, position condition;
  * bounce_sequence(..., law=) for (0.3, 0.2), per nonlinear law: time and contacts.

Run: PYTHONPATH=. python benchmarks/bench_lawstick.py (from the repository root)
"""

from __future__ import annotations

import numpy as np
from timing import best_of

from impactsym.contact import LAWS, bounce_sequence, law_contact_map, law_stick_boundary


def main() -> None:
    delta = np.geomspace(0.1, 3.0, 20)
    print("law_stick_boundary, 20 damping numbers:")
    for law in LAWS:
        for condition in ("position", "force"):
            law_stick_boundary(law, delta[:1], condition=condition)  # compile
            seconds, f_star = best_of(1, law_stick_boundary, law, delta, condition=condition)
            print(f"  {law:14s} {condition:8s} {seconds:7.2f} s   f*(0.1) = {f_star[0]:.6g}")
    d, f = np.meshgrid(np.linspace(0.05, 2.0, 40), np.geomspace(1e-2, 10.0, 40))
    print("law_contact_map, 40 x 40 grid, position condition:")
    for law in LAWS:
        seconds, m = best_of(1, law_contact_map, law, d, f, condition="position")
        print(f"  {law:14s} {seconds:7.2f} s   sticking cells {int(m.sticks.sum())}")
    print("bounce_sequence(0.3, 0.2, law=...), position condition:")
    for law in LAWS:
        seconds, seq = best_of(1, bounce_sequence, 0.3, 0.2, condition="position", law=law)
        print(f"  {law:14s} {seconds:7.2f} s   {seq.n_contacts} contacts, rest at "
              f"{seq.time_to_rest:.6g}")  # fmt: skip


if __name__ == "__main__":
    main()
