"""Benchmark of the exported NumPy module (``impactsym export python FILE``).

Prints, measured in one run:
  * the time to generate the module (cold: SymPy derives the forms; warm: again);
  * contact_time, restitution on a 300 x 300 (D, f) grid per condition, stick_boundary
    at 1000 values of f, rod_contact_time for 40 pairs: exported module and package,
    their time ratio (target about 1: the same code) and whether they agree bit for bit.

Run: python benchmarks/bench_export.py
"""

from __future__ import annotations

import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from timing import best_of


def main() -> None:
    start = time.perf_counter()
    from impactsym.export import python_module, write_python_module

    write_python_module(Path(tempfile.mkdtemp()) / "impactsym_numpy.py")
    cold = time.perf_counter() - start
    warm, source = best_of(1, python_module)
    print(f"generate: cold {cold:.1f} s, warm {warm:.1f} s, {len(source.splitlines())} lines")
    path = Path(tempfile.mkdtemp()) / "impactsym_numpy.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("impactsym_numpy", path)
    exported = importlib.util.module_from_spec(spec)
    sys.modules["impactsym_numpy"] = exported
    spec.loader.exec_module(exported)

    from impactsym import contact, rod

    D, f = np.meshgrid(np.linspace(0.0, 3.0, 300), np.linspace(0.0, 3.0, 300))
    forces = np.logspace(-8, 8, 1000)
    rng = np.random.default_rng(0)
    alpha, pressing = 10 ** rng.uniform(-1.5, 1.5, 40), rng.uniform(0.0, 2.5, 40)
    cases = [
        ("contact_time", contact.contact_time, exported.contact_time, (D, f)),
        ("restitution", contact.restitution, exported.restitution, (D, f)),
        ("stick_boundary", contact.stick_boundary, exported.stick_boundary, (forces,)),
        ("rod_contact_time", rod.contact_time, exported.rod_contact_time, (alpha, pressing)),
    ]
    for name, package, copy, args in cases:
        for condition in ("position", "force"):
            t_package, expected = best_of(3, package, *args, condition=condition)
            t_copy, got = best_of(3, copy, *args, condition=condition)
            same = np.array_equal(got, expected, equal_nan=True)
            print(
                f"{name:16s} {condition:8s} package {t_package:7.3f} s  exported "
                f"{t_copy:7.3f} s  ratio {t_copy / t_package:5.2f}  bit-identical {same}"
            )


if __name__ == "__main__":
    main()
