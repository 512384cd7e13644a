"""F9 records the real window (under Xvfb) to an MP4 of one frame per 1/30 s of simulated time."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from .conftest import run_driver
from .test_mp4 import decode

DRIVER = Path(__file__).with_name("video_driver.py")
BATCH = ("f9_lockstep", "f9_real_time")


def run_scenario(display: str, name: str, workdir: Path) -> dict:
    return run_driver(DRIVER, display, name, workdir, timeout=180, batch=BATCH if name in BATCH else ())


def test_f9_records_the_window_at_simulated_time_and_a_pause_adds_nothing(xvfb, tmp_path):
    r = run_scenario(xvfb, "f9_lockstep", tmp_path)
    assert r["recording"]
    # 90 frames of 1/60 s drawn while recording: 89/60 s after the first, one video frame per 1/30 s
    times = r["times"]
    assert times[-1] - times[0] == pytest.approx(89 / 60) and r["started_at"] == pytest.approx(times[0])
    first = r["first"]
    assert first["exists"] and first["frames"] == 45 and first["seconds"] == pytest.approx(1.5)
    frames, facts = decode(first["path"])
    assert facts["frames"] == 45 and len(frames) == 45 and facts["seconds"] == pytest.approx(1.5)
    assert facts["size"] == (320, 180) and facts["rate"] == pytest.approx(30)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 60  # the balls fell
    # 0.5 s running, 1 s paused, 0.5 s running: 1 s of video
    paused = r["paused"]
    assert paused["frames"] == 30 and paused["seconds"] == pytest.approx(1.0)
    assert decode(paused["path"])[1]["frames"] == 30
    assert len(r["names"]) == 2 and all(n.startswith("ballpit-") and n.endswith(".mp4") for n in r["names"])


def test_f9_in_real_time_plays_back_at_the_speed_it_ran(xvfb, tmp_path):
    r = run_scenario(xvfb, "f9_real_time", tmp_path)
    video = r["video"]
    covered = r["last"] - r["started_at"]  # simulated s from the first state recorded to the last
    assert covered >= 1.9  # about 2 s of the run
    assert video["frames"] == math.floor(covered * r["fps"] + 1e-6) + 1
    _, facts = decode(video["path"])
    assert facts["frames"] == video["frames"] and facts["size"] == (640, 360)
    assert facts["seconds"] == pytest.approx(video["frames"] / 30, abs=1e-3)


def test_f9_without_pyav_says_which_extra_to_install(xvfb, tmp_path):
    r = run_scenario(xvfb, "f9_without_pyav", tmp_path)
    assert not r["recording"] and not r["videos"]
    assert "needs PyAV" in r["message"] and "pip install 'ballpit[video]'" in r["message"]
