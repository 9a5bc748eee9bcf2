"""Keeping freed memory for reuse: array passes without fresh pages.

NumPy takes an array's memory from ``malloc`` and gives it back with ``free``. Under
glibc (``mallopt(3)``, its dynamic mmap threshold) a block above the mmap threshold (128
kB at the start) is mapped fresh and its pages faulted in at first touch, and freed heap
memory beyond twice the threshold goes back to the system; freeing a mapped block of up
to 32 MiB raises both to its size. Code that works in passes of arrays of a few hundred
kB (tens of MB in all, freed at the end of each pass) otherwise runs through fresh pages
pass after pass: each page faulted in and zeroed again, often as long as the arithmetic
itself. :func:`keep_freed_pages` raises the thresholds once, by freeing an untouched
block: the numbers computed are the same either way.
"""

from __future__ import annotations

import numpy as np

__all__ = ["KEEP_BYTES", "keep_freed_pages"]

#: the block :func:`keep_freed_pages` frees: glibc raises its mmap threshold to the size
#: of a freed mapped block of at most 32 MiB (and its trim threshold to twice that)
KEEP_BYTES = 30 * 2**20


def keep_freed_pages() -> None:
    """Let the process reuse the memory its arrays free instead of returning it (under
    glibc; elsewhere a plain allocation, freed again).

    Allocates and frees an untouched block of :data:`KEEP_BYTES` (none of its pages is
    touched: no cost), which raises glibc's mmap threshold to that size and its trim
    threshold to twice it for the rest of the process: arrays up to 30 MiB then come
    from the heap, and up to 60 MiB of freed memory is kept for reuse. Called by array
    code that runs many passes (the PyBullet phase means and design tables).

    >>> keep_freed_pages()
    """
    np.empty(KEEP_BYTES // 8)
