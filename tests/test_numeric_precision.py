"""mpmath's working precision under threads (impactsym.numeric.precision)."""

from __future__ import annotations

import threading
import time

import mpmath
import pytest

from impactsym.numeric.precision import workdps


def _precisions_seen(enter):
    """The precisions one thread sees inside its 60-digit stage while another enters
    40 digits again and again, and the process's precision afterwards."""
    seen = set()

    def long_stage():
        with enter(60):
            for _ in range(100):
                seen.add(mpmath.mp.dps)
                time.sleep(0.0005)

    def short_stages():
        for _ in range(100):
            with enter(40):
                time.sleep(0.0005)

    threads = [threading.Thread(target=long_stage), threading.Thread(target=short_stages)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return seen, mpmath.mp.dps


def test_a_stage_keeps_its_precision_while_another_thread_enters_its_own():
    before = mpmath.mp.dps
    seen, after = _precisions_seen(workdps)
    assert seen == {60}
    assert after == before


def test_plain_mpmath_workdps_is_shared_between_threads():
    # why the lock exists: without it the 60-digit stage runs at 40 digits at times
    # (a scheduling race: retried a few times before it is called absent)
    before = mpmath.mp.dps
    for _ in range(5):
        seen, _ = _precisions_seen(mpmath.workdps)
        if seen != {60}:
            break
    mpmath.mp.dps = before
    assert seen != {60}


@pytest.mark.parametrize(
    ("dps", "error"), [("30", TypeError), (2.5, TypeError), (True, TypeError), (0, ValueError)]
)
def test_a_bad_precision_is_refused_by_name(dps, error):
    with pytest.raises(error, match="dps"), workdps(dps):
        pass
