"""Rough edges of the first trial, in real windows under Xvfb with real key and pointer events."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .conftest import run_driver
from .rough_edges_driver import SCENARIOS

DRIVER = Path(__file__).with_name("rough_edges_driver.py")
BATCH = tuple(SCENARIOS)  # every scenario runs in one window process, on one worker


def run_scenario(display: str, name: str, workdir: Path) -> dict:
    return run_driver(DRIVER, display, name, workdir, timeout=120, batch=BATCH)


def test_a_slope_tilted_over_by_the_arrow_keys_shows_its_colour_on_its_back(xvfb, tmp_path):
    r = run_scenario(xvfb, "tilt_slope_over", tmp_path)
    assert r["selected"] == 1
    assert r["facing_camera"] < 0 and r["tilt_degrees"] > 30  # ↑ tipped it until its back faces us
    before, color = np.array(r["before"]), np.array(r["color"])
    assert before[0] > before[2] + 60 and color[0] > color[2] + 0.5  # an orange slope
    for pixel in np.array(r["after"]):  # its back: still orange (in the shade), not a grey see-through
        assert pixel[0] > pixel[2] + 30 and pixel[0] > pixel[1] + 10, pixel


def test_a_click_just_above_the_visible_horizon_selects_nothing(xvfb, tmp_path):
    r = run_scenario(xvfb, "click_above_horizon", tmp_path)
    assert r["ground_distance"] > 76  # that ray meets the ground only where the fog has hidden it
    assert r["selected"] is None
    assert r["selected_near"] == 0  # the ground near by is picked as before


def test_the_hud_keeps_its_share_of_a_small_window(xvfb, tmp_path):
    r = run_scenario(xvfb, "hud_sizes", tmp_path)
    big, small = r["1280x720"], r["800x450"]
    assert small["window"] == [800, 450] and small["font"] < big["font"]
    share_big, share_small = big["height"] / 720, small["height"] / 450
    assert share_small <= 1.15 * share_big  # it was 1.6 times the share: 11 points in a smaller window
    assert small["width"] / 800 <= 1.15 * big["width"] / 1280
