"""Real windows under Xvfb: each scenario runs window_driver.py in its own process (a process is
either a window process or a headless one, and this pytest process renders headless)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from .conftest import REPO, ended, run_driver, started, subprocess_env, xdotool
from .window_driver import GOOD_SCENE

DRIVER = Path(__file__).with_name("window_driver.py")
# the scenarios this module checks run in one window process, on one worker (the driver's others, the
# physics beside the drawing, are test_physics_beside.py's, which runs each in a process of its own)
BATCH = (
    "title",
    "drop",
    "fly",
    "pause_step_reset",
    "broken_reload",
    "keys",
    "plus_minus_x_keys",
    "slopes_framing",
    "help_beside_hud",
    "double_escape",
    "profile_page",
)


def run_scenario(display: str, name: str, workdir: Path) -> dict:
    return run_driver(DRIVER, display, name, workdir, timeout=120, batch=BATCH)


def pixels(png: str) -> np.ndarray:
    """A screenshot the window wrote (F12), as an (H, W, 3) int array."""
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGB")).astype(int)


def test_the_title_shows_the_frame_rate(xvfb, tmp_path):
    result = run_scenario(xvfb, "title", tmp_path)
    assert result["first"] == "ballpit — untitled — 0.0 FPS"
    match = re.fullmatch(r"ballpit — untitled — (\d+\.\d) FPS", result["caption"])
    assert match and float(match.group(1)) > 1.0
    assert result["frames"] > 5


def test_nothing_moves_before_x_and_the_balls_fall_after_it(xvfb, tmp_path):
    result = run_scenario(xvfb, "drop", tmp_path)
    assert result["waited"] == result["start"] and result["time_waited"] == 0.0
    assert result["phase"] == "RUNNING"
    assert result["time_after"] == pytest.approx(0.5, abs=0.01)
    fall = np.array(result["start"])[:, 1] - np.array(result["after"])[:, 1]
    assert np.all(fall > 0.5)  # ½·g·t² ≈ 1.2 m in 0.5 s


def test_wasd_qe_fly_the_camera_and_the_mouse_looks_and_scroll_sets_speed(xvfb, tmp_path):
    result = run_scenario(xvfb, "fly", tmp_path)
    distance = result["speed"] * 0.5  # 30 frames of 1/60 s
    forward, right = np.array(result["forward"]), np.array(result["right"])
    moves = {k: np.array(v) for k, v in result["moves"].items()}
    assert np.allclose(moves["W"], forward * distance, atol=1e-6)
    assert np.allclose(moves["S"], -forward * distance, atol=1e-6)
    assert np.allclose(moves["A"], -right * distance, atol=1e-6)
    assert np.allclose(moves["D"], right * distance, atol=1e-6)
    assert np.allclose(moves["Q"], [0, -distance, 0], atol=1e-6)
    assert np.allclose(moves["E"], [0, distance, 0], atol=1e-6)
    assert np.linalg.norm(moves["LSHIFT+W"]) == pytest.approx(4 * distance)
    assert result["yaw_change_right_drag"] > 0
    assert result["scroll_speed_ratio"] == pytest.approx(1.25**2)


def test_pause_single_step_and_reset_do_what_they_say(xvfb, tmp_path):
    r = run_scenario(xvfb, "pause_step_reset", tmp_path)
    assert r["paused_time"] > 0
    assert r["still_time"] == r["paused_time"] and r["still_positions"] == r["paused_positions"]
    assert r["after_n"] == pytest.approx(r["paused_time"] + r["dt"])
    assert r["after_right"] == pytest.approx(r["paused_time"] + 2 * r["dt"])
    assert r["resumed_time"] > r["after_right"] + 5 * r["dt"]
    assert r["reset_positions"] == r["initial"] and r["reset_time"] == 0.0
    assert r["reset_phase"] == "WAITING" and "press X" in r["hud"]


def test_a_broken_scene_reload_keeps_the_app_running_and_shows_the_error(xvfb, tmp_path):
    r = run_scenario(xvfb, "broken_reload", tmp_path)
    assert r["title"].startswith("ballpit — live.toml — ")
    assert "live.toml" in r["f5_error"] and "radius" in r["f5_error"]
    assert r["f5_same_world"] and r["still_running"]
    assert r["error_pixels"] > 30  # the error is drawn in the window
    assert "syntax" in r["auto_error"].lower()  # noticed on save, without a key press
    assert r["auto_same_world"] and r["auto_seconds"] < 5
    assert r["ctrl_r_error"] == r["auto_error"]
    assert r["fixed_error"] == "" and r["fixed_balls"] == 2 and r["fixed_phase"] == "WAITING"
    assert r["alive"]


def test_integrator_time_scale_overlay_hud_help_screenshot_and_escape_keys(xvfb, tmp_path):
    r = run_scenario(xvfb, "keys", tmp_path)
    assert [r["integrator_1"], r["integrator_2"], r["integrator_3"]] == ["euler", "rk2", "rk4"]
    assert r["faster"] == 2.0 and r["slower"] == 0.5
    assert r["overlays"] == [True, True, True]
    # after the drop the timeline bar is drawn last, in the screen-space pass
    assert r["draw_labels"] == ["planes", "balls", "trails", "overlay lines", "screen panels"]
    assert r["hud_hidden"] and r["help_shown"]
    shot = Path(r["screenshot"])
    assert shot.parent == tmp_path / "screenshots" and shot.suffix == ".png" and shot.stat().st_size > 1000
    assert r["screenshot_message"] == f"screenshot saved to screenshots/{shot.name}"  # the HUD says where
    assert r["captured"]
    # Esc releases the captured mouse and does nothing else; quitting takes Esc, Esc after it
    assert r["after_first_escape"] == {"captured": False, "closed": False,
                                       "message": "mouse released (Tab captures it again)"}  # fmt: skip
    assert r["after_second_escape"] == {"closed": False, "message": "press Esc again to quit"}
    assert r["after_third_escape"] == {"closed": True}


def test_the_slopes_demo_frames_its_action_clear_of_the_hud(xvfb, tmp_path):
    r = run_scenario(xvfb, "slopes_framing", tmp_path)
    width, height = r["size"]
    assert r["scene"] == "slopes.toml" and (width, height) == (1280, 720)
    left, top, right, bottom = r["hud"]
    # the featured top ball (purple, #9b5de5) is on screen from the first frame, not behind the HUD
    first = pixels(r["first_frame"])
    purple = (first[..., 2] > first[..., 0] + 40) & (first[..., 0] > first[..., 1] + 30)
    rows, cols = np.nonzero(purple)
    outside = ~((cols >= left) & (cols < right) & (rows >= top) & (rows < bottom))
    assert outside.sum() > 20
    # over the whole run, no ball is drawn under the HUD panel or off screen
    track = np.array(r["track"])  # (steps, balls, (x, y, radius))
    assert len(track) >= 2300  # every step of the 10 s (240 a second)
    x, y, radius = track[..., 0], track[..., 1], track[..., 2]
    under_hud = (x + radius > left) & (x - radius < right) & (y + radius > top) & (y - radius < bottom)
    assert not under_hud.any()
    assert (x - radius >= 0).all() and (x + radius <= width).all()
    assert (y - radius >= 0).all() and (y + radius <= height).all()
    # nor under the timeline bar that appears with the drop along the bottom
    assert r["bar_top"] < 0.95 * height
    assert (y + radius <= r["bar_top"]).all()
    # and the action fills the window down to the bar: no empty band of floor
    assert (y + radius).max() > r["bar_top"] - 0.1 * height
    assert (y - radius).min() < 0.4 * height
    # with balls drawn big enough to see their spin (the scene is 19 m wide; 0.5 m balls)
    assert np.median(2 * radius) >= 24 and (2 * radius).min() >= 20


def overlap(a: list[float], b: list[float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_the_f1_help_never_covers_the_hud_panel(xvfb, tmp_path):
    from ballpit.viewer.hud import PANEL_COLOR

    r = run_scenario(xvfb, "help_beside_hud", tmp_path)
    for name, w in r.items():
        width, height = w["size"]
        assert w["help_shown"], name
        help_, text = w["help"], w["help_text"]
        assert 0 <= help_[0] and help_[2] <= width and 0 <= help_[1] and help_[3] <= height, name
        assert help_[0] <= text[0] and text[2] <= help_[2] and help_[1] <= text[1] and text[3] <= help_[3]
        if w["hud_drawn"]:
            assert not overlap(w["hud"], help_), name
        assert help_[0] >= w["left"] and w["hud"][0] >= w["left"], name  # both right of the ImGui panel
    # 1280x720 has room for both side by side, 900x700 one above the other; 700x420 too, as the text
    # scales with the window (hud.font_size); 600x300 only for the help
    beside, above = r["1280x720"], r["900x700"]
    assert beside["hud_drawn"] and beside["help"][0] >= beside["hud"][2]
    assert above["hud_drawn"] and above["help"][1] >= above["hud"][3]
    assert r["700x420"]["hud_drawn"]
    assert not r["600x300"]["hud_drawn"]
    # beside the ImGui panel the help's text shrinks to fit the 3-D view (950 px wide; 470 at 800x450)
    assert r["800x450 panel"]["left"] == 330 and r["800x450 panel"]["help"][2] <= 800
    # in the real pixels: the HUD's bright text shows in its panel, the gap between the panels is scene
    image = pixels(r["1280x720"]["pixels"])
    hud, help_ = (np.array(r["1280x720"][k], dtype=int) for k in ("hud", "help"))
    hud_pixels = image[hud[1] : hud[3], hud[0] : hud[2]]
    assert (hud_pixels.min(axis=-1) > 200).sum() > 200  # its text
    gap = image[help_[1] : help_[3], hud[2] + 2 : help_[0] - 2]
    panel = np.array(PANEL_COLOR[:3])
    assert gap.size and (np.abs(gap - panel).max(axis=-1) > 10).mean() > 0.5  # not a panel


def test_one_escape_asks_for_a_second_which_quits(xvfb, tmp_path):
    r = run_scenario(xvfb, "double_escape", tmp_path)
    hint = "press Esc again to quit"
    assert r["first"] == {"closed": False, "message": hint}
    assert r["later"] == {"closed": False, "message": ""}  # the hint goes after about 2 s
    assert r["again"] == {"closed": False, "message": hint}  # so one Esc asks again
    assert r["twice"] == {"closed": True}
    before, first, later = (np.array(r[k]) for k in ("strip_before", "strip_first", "strip_later"))
    assert (np.abs(first - before).max(axis=-1) > 60).sum() > 40  # the hint is drawn in the window
    assert (np.abs(later - before).max(axis=-1) > 60).sum() == 0  # and gone again


# ---------------------------------------------------------------------- the real event loop + X input
@pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")
def test_the_app_runs_its_event_loop_takes_real_x_key_presses_and_quits_on_a_second_escape(xvfb, tmp_path):
    scene = tmp_path / "demo.toml"
    scene.write_text(GOOD_SCENE)
    code = "import sys, pathlib; from ballpit.viewer.app import run; sys.exit(run(pathlib.Path(sys.argv[1])))"
    with started([sys.executable, "-c", code, str(scene)], xvfb, tmp_path) as proc:
        window = ""
        deadline = time.monotonic() + 60
        while not window and time.monotonic() < deadline and proc.poll() is None:
            window = xdotool(xvfb, "search", "--name", "demo.toml").split("\n")[0]
            time.sleep(0.1)
        assert window, f"the viewer window never appeared: {ended(proc)}"
        name = ""
        deadline = time.monotonic() + 30
        while not re.search(r"[1-9]\d*\.\d FPS$", name) and time.monotonic() < deadline:
            time.sleep(0.2)  # the title's FPS updates twice a second once frames flow
            name = xdotool(xvfb, "getwindowname", window)
        assert re.fullmatch(r"ballpit — demo\.toml — \d+\.\d FPS", name), name
        xdotool(xvfb, "mousemove", "--window", window, "20", "20")  # pointer focus for XTEST input
        for keys in (["x"], ["F12"], ["Escape"]):
            xdotool(xvfb, "key", "--delay", "50", *keys)
            time.sleep(0.3)
        time.sleep(0.5)
        assert proc.poll() is None, "one Escape quit the viewer; it should ask for a second"
        xdotool(xvfb, "key", "Escape")
        try:
            out, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the viewer did not quit on Escape; title {name!r}; {ended(proc)}")
    assert proc.returncode == 0, err
    assert "Traceback" not in err, err
    shot = re.search(r"screenshot saved to (\S+\.png)", out)
    assert shot and Path(shot.group(1)).is_file(), out
    assert Path(shot.group(1)).parent == tmp_path / "screenshots"


@pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")
def test_plus_and_minus_typed_on_a_real_keyboard_change_the_time_scale_every_time(xvfb, tmp_path):
    # Shift is let go before "=": X reports the release as EQUAL while the press was PLUS
    r = run_scenario(xvfb, "plus_minus_x_keys", tmp_path)
    assert r["scales"] == [2.0, 4.0, 8.0, 4.0, 2.0, 4.0, 2.0, 1.0]


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_without_a_display_the_viewer_prints_one_line_and_exits_1(tmp_path):
    code = "import sys; from ballpit.viewer.app import run; sys.exit(run())"
    for display in (None, ":12345"):  # no DISPLAY at all; a DISPLAY with no server behind it
        proc = subprocess.run(
            [sys.executable, "-c", code], env=subprocess_env(display), cwd=REPO,
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert proc.returncode == 1, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1, proc.stderr
        assert "no display" in lines[0] and "ballpit render SCENE --out demo.gif" in lines[0]
        assert "xvfb-run ballpit" in lines[0]


def test_f2_shows_the_time_of_each_stage_of_the_step_and_f2_again_goes_back(xvfb, tmp_path):
    from ballpit.physics.core.profile import STAGES

    result = run_scenario(xvfb, "profile_page", tmp_path)
    text = result["profile"]
    ms = {}
    for line in text.splitlines():
        match = re.fullmatch(r"(.+?)\s+(\d+\.\d+) ms", line)
        if match:
            ms[match.group(1).strip()] = float(match.group(2))
    assert set(STAGES) <= set(ms), text
    assert ms["step"] > 0 and sum(ms[s] for s in STAGES) <= ms["step"] * 1.01 + 0.002, text
    steps = int(re.search(r"step profile, (\d+) steps", text).group(1))
    assert steps > 0 and re.search(r"intervals/step \d+\.\d+", text)
    assert result["page"] == "stats" and "sim time" in result["back"]


def test_f2_names_the_renderer_and_its_quality_and_f3_switches_the_quality_live(xvfb, tmp_path):
    result = run_scenario(xvfb, "profile_page", tmp_path)
    lines = result["profile"].splitlines()
    assert f"renderer    {result['renderer']}" in lines
    switched = result["switched"]
    assert any(line.startswith(f"quality     {switched['before']}: ") for line in lines), lines
    if "llvmpipe" in result["renderer"]:  # Xvfb: Mesa's CPU rasteriser, so it starts low
        assert switched["before"] == "low"
    assert switched["quality"] != switched["before"]
    assert switched["message"].startswith(f"quality {switched['quality']}: ")
    assert switched["scale"] == (1.0 if switched["quality"] == "high" else 0.5)
