"""mpmath's working precision, one thread at a time: :func:`workdps`.

mpmath keeps its precision in one context shared by the whole process (``mpmath.mp``),
not per thread: two threads inside ``mpmath.workdps`` with different digits change each
other's precision mid-computation (a 60-digit stage then runs at 40 digits) and leave the
process at the wrong one. The package's own high-precision stages (the rod's mpmath cell
tables and pole sums, the viscoelastic series) enter their precision through
:func:`workdps`, which holds one process-wide re-entrant lock meanwhile: they run one at
a time, whatever thread calls them (they hold the GIL for their whole length anyway).
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import mpmath

from impactsym.validation import check_count

__all__ = ["workdps"]

_LOCK = threading.RLock()


@contextmanager
def workdps(dps: int) -> Iterator[None]:
    """``mpmath.workdps(dps)`` under the process-wide lock (module docstring); nested
    calls in one thread are fine (re-entrant). ``dps``: a whole number of digits in
    ``[1, 100000]`` (else ``TypeError``/``ValueError`` naming it).

    >>> with workdps(30):
    ...     print(mpmath.mp.dps)
    30
    """
    dps = check_count("dps", dps, upper=100_000)  # (a bad one is named before the lock)
    with _LOCK, mpmath.workdps(dps):
        yield
