"""The mpmath cell table shared between threads: a repair is one step with its check.

:meth:`CellTable.certified` repairs pending cells in mpmath where first needed, on a
table the cache shares between threads. A thread that comes to a cell another thread is
repairing must wait for the repair and see the repaired cell, as one thread alone does;
without the lock it found the cell neither pending nor repaired yet and answered "not
certified" (its search then ran on the pole sums: a different result).
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from impactsym.rod.elastic import cells
from impactsym.rod.elastic.cells import CellTable
from impactsym.rod.elastic.search import TABLE_TOLERANCE


def test_threads_checking_a_cell_under_repair_see_the_repaired_cell(monkeypatch):
    which, a, k = "y", 2.0, 1000.0  # a fast pole: cells repaired in mpmath
    alone = CellTable(which, a, k, 4)
    pending = np.array(sorted(alone._pending))
    f = np.full(pending.size, 2.0)
    before = alone.err_a[pending] + f * alone.err_b[pending] <= TABLE_TOLERANCE
    expected = alone.certified(pending, f, TABLE_TOLERANCE)
    assert not np.array_equal(before, expected)  # the repair changes the answer

    slow_cell = cells._mp_cell

    def slowed(*args, **kwargs):  # a long repair, so that the threads meet in it
        time.sleep(0.02)
        return slow_cell(*args, **kwargs)

    monkeypatch.setattr(cells, "_mp_cell", slowed)
    shared = CellTable(which, a, k, 4)
    start = threading.Barrier(6)

    def check(_):
        start.wait()
        return shared.certified(pending, f, TABLE_TOLERANCE)

    with ThreadPoolExecutor(6) as pool:
        found = list(pool.map(check, range(6)))
    for got in found:
        np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(shared.A[pending], alone.A[pending])
