"""keep_freed_pages: array passes reuse the memory they free (glibc's thresholds)."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

_CHURN = """
import resource, sys
import numpy as np
from impactsym.numeric.memory import keep_freed_pages
if sys.argv[1] == "keep":
    keep_freed_pages()
np.ones(1)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):  # a pass's temporaries, freed together: 8 x 1 MiB, written
    block = [np.ones(2**17) for _ in range(8)]
    del block
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(
    platform.libc_ver()[0] != "glibc" or any(name.startswith("MALLOC_") for name in os.environ),
    reason="glibc's dynamic malloc thresholds (a MALLOC_*_ setting fixes them)",
)
def test_passes_reuse_the_pages_their_temporaries_freed():
    # after keep_freed_pages glibc keeps the memory a pass frees for the next pass
    # instead of mapping and faulting in fresh pages each time (a fresh interpreter
    # each: the thresholds are per process)
    faults = {}
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[1])}
    for mode in ("keep", "plain"):
        run = subprocess.run([sys.executable, "-c", _CHURN, mode], capture_output=True,
                             text=True, check=True, env=env)  # fmt: skip
        faults[mode] = int(run.stdout)
    one_pass = 8 * 2**20 // 4096
    assert faults["keep"] < 2 * one_pass  # the first pass's pages, then reused
    assert faults["plain"] > 5 * one_pass  # (glibc's default: fresh pages again)
