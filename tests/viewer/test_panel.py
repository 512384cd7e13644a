"""The panel in real windows under Xvfb (panel_driver.py): real clicks at the widgets' places, real
typing, a file dropped on the window; pictures read back where a picture is what is checked."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from .conftest import run_driver

DRIVER = Path(__file__).with_name("panel_driver.py")
BATCH = (
    "busy_panel",
    "scene_list",
    "drop_buttons",
    "restitution_edit",
    "file_drop",
    "add_ball",
    "orbit",
    "energy_legend",
    "record_button",
)
pytestmark = pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")


def run_scenario(display: str, name: str, workdir: Path) -> dict:
    return run_driver(DRIVER, display, name, workdir, timeout=240, batch=BATCH if name in BATCH else ())


def test_while_the_physics_is_busy_frames_redraw_the_panels_last_build_from_its_buffers(xvfb, tmp_path):
    r = run_scenario(xvfb, "busy_panel", tmp_path)
    builds, redraws = r["quick"]  # of the next four frames: with no input, no build
    assert builds + redraws == 4 and redraws >= 2
    assert r["same_pixels"] and r["panel_pixels"] > 10_000  # and drawn it is, pixel for pixel
    assert r["uploads"] == builds  # from the buffers that hold it: a redraw uploads nothing again
    assert r["after_pointer"] >= 1  # input: built again
    assert r["at_ease"] == 3


def test_clicking_a_scene_in_the_list_loads_it_and_f4_hides_the_panel(xvfb, tmp_path):
    r = run_scenario(xvfb, "scene_list", tmp_path)
    assert r["before"] == "slopes.toml" and r["after"] == "cradle.toml"
    assert r["balls"] == 6 and r["phase"] == "WAITING"
    # the camera went to the new scene's view: on the file's line of sight to its look-at point (with no
    # ground, the cradle is framed to fill the view: only the distance along that line changes)
    target, eye, filed = (np.array(r[k]) for k in ("look_at", "camera", "scene_camera"))
    along = (filed - target) / np.linalg.norm(filed - target)
    assert np.allclose((eye - target) / np.linalg.norm(eye - target), along, atol=1e-9)
    assert np.allclose(r["forward"], -along, atol=1e-9)
    assert "cradle.toml" in r["title"] and r["recent"] == ["cradle.toml"]
    assert r["hud_x_shown"] >= r["panel_width"]  # the HUD sits right of the panel
    assert r["panel_after_f4"] is False and r["hud_x_hidden"] < 20 and r["inset_hidden"] == 0.0
    # the panel is opaque: most of its strip is its background colour (the rest its widgets and text), not
    # the scene's (the view is not drawn under it); hidden, the view fills the strip
    assert max(r["background"]) > 0
    assert r["panel_background_share"] > 0.5 and r["strip_background_share_hidden"] < 0.05


def test_the_drop_pause_step_and_reset_buttons_do_what_their_keys_do_and_the_prompt_goes(xvfb, tmp_path):
    r = run_scenario(xvfb, "drop_buttons", tmp_path)
    assert r["prompt"] and r["prompt_white"] > 300  # "press X or click Drop", large, white
    assert r["after_drop"] == "RUNNING" and r["fell"] > 0.05
    assert r["prompt_after"] is False
    assert r["after_pause"] == "PAUSED"
    assert r["stepped"] == pytest.approx(1 / 240, abs=1e-9)
    assert r["after_reset"] == ["WAITING", 0.0, 2.25]


def test_a_restitution_typed_into_the_inspector_sets_the_next_bounce_to_e_squared_h(xvfb, tmp_path):
    r = run_scenario(xvfb, "restitution_edit", tmp_path)
    assert r["selected"] == 0
    assert r["restitution"] == 0.6 and r["errors"] == {}
    heights = np.array(r["heights"])
    after = heights[heights[:, 0] > r["edited_at"]]
    bounce = int(np.argmax(np.diff(after[:, 1]) > 0))  # the first step on which it rose again
    assert after[bounce, 1] == pytest.approx(0.25, abs=0.02)  # it reached the floor (within one step)
    apex = after[bounce : bounce + 150, 1].max()  # its next flight lasts 2·e·√(2h/g) ≈ 0.77 s, 184 steps
    drop = 2.25 - 0.25  # the ball's bottom fell from 2 m
    # e = e_ball × e_floor = 0.6 × 1.0; the apex of the next flight is e²·h above the floor
    assert apex - 0.25 == pytest.approx(0.6**2 * drop, abs=1e-4)


def test_a_nan_typed_into_a_field_is_refused_beside_it_the_value_stays_and_the_run_goes_on(xvfb, tmp_path):
    r = run_scenario(xvfb, "restitution_edit", tmp_path)
    assert r["radius_error"] == "radius must be finite, got nan"
    assert r["radius"] == 0.25
    assert r["phase"] == "RUNNING" and r["ran_on"] > 0.1
    assert r["error_red"] > 50  # drawn in red under the field
    # keys typed into a field are the field's: "1" (Euler's key) typed into the mass is only a digit
    assert r["integrator_after_typing"] == "rk4" and r["mass"] == 1.5
    # P opens the plots; the selected ball's height shows its apexes marked
    assert r["plots"] == ["plot area energy", "plot area ball"]
    assert r["apex_marker"] > 10


def test_a_scene_dropped_on_the_window_opens_and_a_broken_one_keeps_the_current_scene(xvfb, tmp_path):
    r = run_scenario(xvfb, "file_drop", tmp_path)
    assert r["after_good"] == "bounce.toml" and r["balls"] == 1
    assert r["after_bad"] == "bounce.toml"
    assert "broken.toml:3" in r["error"] and "radius" in r["error"]
    assert r["error_red"] > 100
    assert r["still_runs"] > 0.3


def test_a_ball_is_added_where_the_pointer_clicks_and_one_inside_it_is_refused(xvfb, tmp_path):
    r = run_scenario(xvfb, "add_ball", tmp_path)
    assert r["adding"] is True
    assert r["count"] == 2 and r["radius"] == 0.25
    x, y, z = r["new"]
    assert y == pytest.approx(0.25 + 1e-3, abs=1e-9)  # resting on the floor, just clear of it
    assert np.hypot(x - 1.5, z - 0.5) < 0.05  # where the pointer was
    assert r["count_again"] == 2
    assert "would overlap ball 1" in r["error"]


def test_a_double_clicked_ball_is_orbited_the_wheel_zooms_a_drag_turns_and_home_flies_again(xvfb, tmp_path):
    r = run_scenario(xvfb, "orbit", tmp_path)
    assert r["active"] and r["position"] == r["centre"]  # a double-click does not move the ball
    assert np.allclose(r["target"], r["centre"])
    assert r["zoomed"] == pytest.approx(r["distance"] * 0.85, rel=1e-9)
    assert abs(r["turned"]) > 0.1  # turned about the ball...
    assert r["looks_at_target"] < 1e-9  # ...still looking at it
    active, eye, filed = r["after_home"]
    assert not active and np.allclose(eye, filed)  # the scene's view (it has a ground), flying free


def test_the_energy_plots_legend_with_ghosts_stays_inside_the_plot_and_shows_every_curves_colour(
    xvfb, tmp_path
):
    r = run_scenario(xvfb, "energy_legend", tmp_path)
    assert r["ghosts"] == 3  # K, U and four totals: the widest the legend gets
    fx, fy, fw, fh = r["frame"]
    lx, ly, lw, lh = r["legend"]
    assert fx <= lx and lx + lw <= fx + fw and fy <= ly and ly + lh <= fy + fh  # not clipped
    for name, pixels in r["swatches"].items():  # each curve's swatch drawn in the legend, in its colour
        assert pixels >= 50, (name, r["swatches"])


def test_the_record_button_records_the_3d_view_at_simulated_time_and_a_second_click_writes_the_mp4(
    xvfb, tmp_path
):
    from PIL import Image

    from .test_mp4 import decode

    r = run_scenario(xvfb, "record_button", tmp_path)
    assert r["recording"] and not r["after_second_click"] and r["still_runs"] == "RUNNING"
    assert r["rec_red"] > 30 and r["saved_line"]  # "REC 1.1 s" in red while it recorded; then the file
    video = r["video"]
    # one frame per 1/30 s of the simulated time covered (its first and last state included): about
    # 1.1 s of 1/60 s frames between the clicks
    assert 1.0 <= r["covered"] <= 1.5
    assert video["frames"] == math.floor(r["covered"] * r["fps"] + 1e-6) + 1
    frames, facts = decode(video["path"])
    assert facts["frames"] == len(frames) == video["frames"]
    assert facts["seconds"] == pytest.approx(video["frames"] / 30, abs=1e-3) and facts["rate"] == 30
    # the 3-D view right of the panel (with the HUD and the bar), not the panel
    w = r["panel_width"]
    assert facts["size"] == (1280 - w, 720)
    window = np.asarray(Image.open(r["window"]), dtype=int)
    frame = frames[r["grabbed_frame"]].astype(int)
    below_mark = slice(40, None)  # the window's red "REC" mark, top right, is not in the video
    assert np.abs(frame - window[:, w:])[below_mark].mean() < 5
    assert np.abs(frame - window[:, : 1280 - w])[below_mark].mean() > 15


def test_without_pyav_the_record_button_says_why_in_the_panel_and_the_run_goes_on(xvfb, tmp_path):
    r = run_scenario(xvfb, "record_without_pyav", tmp_path)
    assert not r["recording"] and not r["videos"]
    assert r["error"] == "recording video needs PyAV, which is not installed: pip install 'ballpit[video]'"
    assert r["error_red"] > 50  # in the panel, in red
    assert r["ran_on"] == pytest.approx(30 / 60, abs=1e-6)  # 30 frames of 1/60 s after the click
