"""Frame pacing (pacing.py): the window draws at 60 FPS while the physics has time to spare and at 33
while it is busy nearly all the time, with a gap between the two thresholds so the rate holds. The
real window's loop following it is in test_physics_beside.py."""

from __future__ import annotations

import pytest

from ballpit.viewer.pacing import (
    BUSY_FAST,
    BUSY_SLOW,
    FAST_FPS,
    HUD_BUSY_INTERVAL,
    HUD_INTERVAL,
    PACE_FAST,
    PACE_SLOW,
    PANEL_BUSY_HZ,
    PANEL_HZ,
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


def test_the_panel_is_built_twenty_times_a_second_at_ease_and_ten_while_the_physics_is_busy():
    pacer = FramePacer()
    at_ease = [t for t in (i / 60 for i in range(60)) if pacer.build_panel(t)]
    assert len(at_ease) == PANEL_HZ == 20  # a second of 60 frames
    assert pacer.build_panel(5.0) and pacer.build_panel(5.001, free=False)  # stepped by hand: every frame
    assert pacer.hud_interval() == HUD_INTERVAL
    pacer.interval(1.0)  # busy
    assert pacer.hud_interval() == HUD_BUSY_INTERVAL == 0.25
    built = [t for t in (i / 33 for i in range(33)) if pacer.build_panel(10.0 + t)]
    assert len(built) == PANEL_BUSY_HZ == 10  # a second of 33 frames
    assert not pacer.build_panel(10.999, free=False)  # busy: by hand too
    plain = FramePacer(thrifty=False)
    assert plain.build_panel(0.0) and plain.build_panel(0.001)
    plain.interval(1.0)
    assert plain.build_panel(0.0) and plain.build_panel(0.001) and plain.hud_interval() == HUD_INTERVAL
