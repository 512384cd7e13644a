"""Frame pacing (pacing.py): the window draws at 60 FPS while the physics has time to spare and at 33
while it is busy nearly all the time, with a gap between the two thresholds so the rate holds. The
real window's loop following it is in test_physics_beside.py."""

from __future__ import annotations

import pytest

from ballpit.viewer.pacing import (
    BUSY_FAST,
    BUSY_SLOW,
    FAST_FPS,
    PACE_FAST,
    PACE_SLOW,
    SLOW_FPS,
    FramePacer,
)


def test_a_busy_physics_slows_the_drawing_and_slack_brings_the_full_rate_back():
    pacer = FramePacer()
    assert pacer.interval(0.0) == pytest.approx(1 / FAST_FPS)
    assert pacer.interval(0.85) == pytest.approx(1 / FAST_FPS)  # between the thresholds: as it was
    assert pacer.interval(BUSY_SLOW) == pytest.approx(1 / SLOW_FPS)
    assert "physics needs the CPU" in pacer.describe()
    assert pacer.interval(0.8) == pytest.approx(1 / SLOW_FPS)  # still as it was
    assert pacer.interval(BUSY_FAST) == pytest.approx(1 / FAST_FPS)
    assert pacer.describe() == f"{FAST_FPS:g} FPS at most"


def test_a_physics_far_behind_real_time_keeps_the_full_rate_since_slower_drawing_would_not_bring_it_near():
    pacer = FramePacer()
    assert pacer.interval(1.0, pace=0.1) == pytest.approx(1 / FAST_FPS)  # pile10k landing: 0.05-0.1
    assert pacer.interval(1.0, pace=PACE_SLOW) == pytest.approx(1 / SLOW_FPS)
    assert pacer.interval(1.0, pace=0.22) == pytest.approx(1 / SLOW_FPS)  # between: as it was
    assert pacer.interval(1.0, pace=PACE_FAST - 0.01) == pytest.approx(1 / FAST_FPS)


def test_the_slow_rate_keeps_the_30_fps_the_viewer_promises():
    assert 30.0 < SLOW_FPS < FAST_FPS and BUSY_FAST < BUSY_SLOW < 1.0 and PACE_FAST < PACE_SLOW
