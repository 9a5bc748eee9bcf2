"""Many restitution designs of one contact (table_design): the tabulated, inverted phase
mean gives the designs the target-by-target search gives, and they hit their targets in
the general phase summary (an algorithm that shares nothing with the table)."""

import os

import numpy as np
import pytest

from impactsym.engines import mujoco
from impactsym.engines.mujoco import discrete, table_design
from impactsym.engines.mujoco.euler import euler_contact
from impactsym.engines.mujoco.model import coefficients

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


@pytest.mark.parametrize(("gravity", "speed"), [(9.81, 1.0), (0.0, 0.5)])
def test_table_designs_equal_the_target_by_target_ones(gravity, speed):
    targets = np.linspace(0.3, 0.85, 200)  # >= 128 targets of one contact: the table
    many = mujoco.solref_for(
        restitution=targets, speed=speed, gravity=gravity, timestep=0.002, solimp=FLAT
    )
    few = np.concatenate(
        [
            mujoco.solref_for(
                restitution=part, speed=speed, gravity=gravity, timestep=0.002, solimp=FLAT
            ).solref[1]
            for part in np.array_split(targets, 4)  # 50 each: the search per target
        ]
    )
    # both hit the phase mean to 1e-9 or better: the dampratios agree to a few 1e-9
    np.testing.assert_allclose(many.solref[1], few, rtol=1e-7)
    pick = np.arange(0, 200, 23)
    c = coefficients((many.solref[0][pick], many.solref[1][pick]), FLAT, 0.002)
    n = pick.size
    ref = discrete._split_and_integrate(
        euler_contact, "euler", FLAT, c.damping, c.stiffness, np.ones(n),
        np.full(n, gravity), np.full(n, speed), np.full(n, 0.002),
    )  # fmt: skip
    np.testing.assert_allclose(ref[0], targets[pick], rtol=0, atol=2e-9)


def test_targets_of_several_contacts_share_no_table():
    """Two speeds, 150 targets each: one table per contact, each design its own."""
    targets = np.tile(np.linspace(0.35, 0.8, 150), 2)
    speeds = np.repeat([0.7, 1.4], 150)
    d = mujoco.solref_for(
        restitution=targets, speed=speeds, gravity=9.81, timestep=0.002, solimp=FLAT
    )
    np.testing.assert_allclose(d.prediction.restitution, targets, rtol=0, atol=2e-9)
    assert not np.allclose(d.solref[1][:150], d.solref[1][150:])


def _synthetic(kink: float = 0.0):
    """A falling phase mean ``E(dr) = 1 / (1 + dr^2)`` (plus ``kink * (1 - dr)`` below
    ``dr = 1``: a kink of the slope there) with a summary of made-up smooth fields."""

    def mean(dr):
        return 1.0 / (1.0 + dr * dr) + kink * np.maximum(1.0 - dr, 0.0)

    def summary(dr, i):
        E, t = mean(dr), 1.0 + dr
        return np.stack([E, t, E - 0.1, E + 0.1, t - 0.01, t + 0.01, np.zeros(dr.size)])

    return mean, summary


@pytest.mark.parametrize("kink", [0.0, 0.05])
def test_designs_read_off_the_table_hit_the_true_mean(kink):
    """Smooth: every target is read off, at the exact inverse; a kink of the slope inside
    the table: its stencils are refused and every design still hits the true mean."""
    mean, summary = _synthetic(kink)
    targets = np.linspace(0.3, 0.9, 5000)

    def gap(dr, i, final=False):
        return targets[i] - mean(dr)

    dr, left, checked, known = table_design.table_crossings(
        gap, np.zeros(targets.size, int), targets, np.full(targets.size, 0.05), 100.0, summary
    )
    assert left.size == 0
    assert checked[np.isfinite(known[0])].all()
    np.testing.assert_allclose(mean(dr), targets, rtol=0, atol=1e-9)
    read = np.isfinite(known[0])
    np.testing.assert_allclose(known[:, read], summary(dr[read], None), rtol=0, atol=1e-9)
    if kink == 0.0:
        assert read.all()
        np.testing.assert_allclose(dr, np.sqrt(1.0 / targets - 1.0), rtol=1e-11)
    else:  # the targets whose design lies next to the kink were evaluated
        near = np.abs(np.log(dr)) < 1e-4  # within a spacing of the split table
        assert near.any()
        assert not read[near].any()
        assert read.mean() > 0.9


def test_default_solimp_designs_read_off_the_table_match_predict(monkeypatch):
    """Many targets of one contact with the default solimp: most designs and their
    summaries are read off the table (counted), and predict at their solref (the
    general phase summary, evaluated) agrees to the design tolerance of the table."""
    read = []
    original = table_design._interpolated

    def spy(*args):
        out = original(*args)
        read.append(int(out[0].sum()))
        return out

    monkeypatch.setattr(table_design, "_interpolated", spy)
    targets = np.linspace(0.3, 0.9, 3000)
    d = mujoco.solref_for(restitution=targets, speed=1.0, gravity=9.81, timestep=0.002)
    assert sum(read) > 1500
    pick = np.arange(0, 3000, 29)
    p = mujoco.predict(
        solref=(d.solref[0][pick], d.solref[1][pick]), speed=1.0, gravity=9.81, timestep=0.002
    )
    np.testing.assert_allclose(p.restitution, targets[pick], rtol=0, atol=2e-9)
    np.testing.assert_allclose(d.prediction.restitution[pick], p.restitution, rtol=0, atol=2e-9)
    np.testing.assert_allclose(d.prediction.contact_time[pick], p.contact_time, rtol=1e-9)
    for got, ref in zip(d.prediction.restitution_range, p.restitution_range, strict=True):
        np.testing.assert_allclose(got[pick], ref, rtol=0, atol=2e-9)


def test_designs_read_off_the_table_hold_in_mujoco():
    """MuJoCo itself at its default dt = 0.002 on designs read off the table: per touch
    phase it matches predict to 1e-12 (relative), its mean over 32 phases hits the target
    to the sampling of the phase (1e-3), and its phases lie in the design's range."""
    if os.environ.get("CI") != "true":  # CI installs MuJoCo: there it must run
        pytest.importorskip("mujoco")
    from impactsym.engines.drivers import mujoco_phases

    targets = np.linspace(0.3, 0.9, 3000)
    d = mujoco.solref_for(restitution=targets, speed=1.0, gravity=9.81, timestep=0.002)
    phases = (np.arange(32) + 0.5) / 32
    lo, hi = d.prediction.restitution_range
    for i in (100, 2900):
        solref = (float(d.solref[0][i]), float(d.solref[1][i]))
        mj = mujoco_phases(
            solref=solref, solimp=mujoco.DEFAULT_SOLIMP, speed=1.0, gravity=9.81,
            timestep=0.002, phases=phases,
        )  # fmt: skip
        per = mujoco.predict(solref=solref, speed=1.0, gravity=9.81, timestep=0.002, phase=phases)
        np.testing.assert_allclose(mj["restitution"], per.restitution, rtol=1e-12)
        assert mj["restitution"].mean() == pytest.approx(targets[i], abs=1e-3)
        assert lo[i] <= mj["restitution"].min() <= mj["restitution"].max() <= hi[i]
