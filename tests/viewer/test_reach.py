"""Reaching in, in real windows under Xvfb (reach_driver.py): throw, shoot, tilt, lift, Home, Ctrl+S.
Physics outcomes are checked against closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit.viewer.interaction import LIFT_SPEED, SPRING_HERTZ, THROW_WINDOW, TILT_RATE

from .conftest import run_driver, subprocess_env
from .test_save import assert_same_or_round_off

DRIVER = Path(__file__).with_name("reach_driver.py")
needs_xdotool = pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")


# the scenarios of reach_driver.py this module checks: the first test to ask runs them all in one window
# process (record_close_button is test_record.py's, run in a process of its own)
BATCH = (
    "drag_throw",
    "drag_throw_paused",
    "spring_into_plane",
    "shoot",
    "plane_tilt",
    "plane_lift",
    "home",
    "save",
)


def run_scenario(display: str, name: str, workdir: Path) -> dict:
    return run_driver(DRIVER, display, name, workdir, timeout=180, batch=BATCH)


def drag_velocity(r: dict) -> np.ndarray:
    """The pointer's steady motion carried onto the plane facing the camera through the ball."""
    metres_per_pixel = 2 * r["depth"] * math.tan(math.radians(r["fov"]) / 2) / r["height"]
    step_x, step_y = r["pixel_step"]
    return (step_x * np.array(r["right"]) + step_y * np.array(r["up"])) * metres_per_pixel / r["frame"]


def test_a_paused_dragged_ball_follows_the_pointer_and_leaves_with_the_drag_velocity(xvfb, tmp_path):
    """Paused, nothing steps: the held ball is placed along the drag (its path is clear), and letting go
    gives it the drag's velocity."""
    r = run_scenario(xvfb, "drag_throw_paused", tmp_path)
    assert r["grabbed"] == 0
    assert np.allclose(r["after_grab"], r["start"], atol=1e-9)  # picking it up does not move it
    v = drag_velocity(r)
    held = np.array([s["position"] for s in r["held"]])
    steps = np.diff(held, axis=0)  # one frame of pointer motion each
    assert np.allclose(steps, v * r["frame"], rtol=0, atol=1e-9)  # it follows, and does not fall
    assert r["held_times"][0] == r["held_times"][-1]  # no time passed while held
    assert "overlay lines" in r["draws_while_held"] and "overlay lines" not in r["draws_after_release"]
    assert "holding     ball 0, throw" in r["hud_while_held"]
    released = np.array(r["released"]["velocity"])
    assert np.allclose(released, v, rtol=1e-9, atol=1e-9)  # the drag's velocity over the last 0.1 s
    assert np.linalg.norm(v) > 3.0 and THROW_WINDOW == pytest.approx(0.1)
    assert r["held_after_release"] is None
    assert r["paused_still"] == r["released"]  # paused: nothing moves until Space
    assert_free_flight(r, released)


def assert_free_flight(r: dict, released: np.ndarray) -> None:
    """After letting go: v = v0 + g t, x = x0 + v0 t + g t²/2 (RK4 is exact for constant g)."""
    t, g = r["flight_time"], np.array(r["g"])
    assert t == pytest.approx(0.2, abs=0.005)
    assert np.allclose(r["flight"]["velocity"], released + g * t, atol=1e-9)
    x0 = np.array(r["released"]["position"])
    assert np.allclose(r["flight"]["position"], x0 + released * t + 0.5 * g * t * t, atol=1e-9)


def test_a_dragged_ball_is_pulled_by_a_damped_spring_comes_to_rest_on_the_pointer_and_is_thrown(
    xvfb, tmp_path
):
    """Running, the mouse joint pulls the ball: it lags the moving pointer, then settles on the still
    pointer within the sag a 5 Hz spring allows under gravity (g/ω², 1 cm), at rest; a quick drag and
    letting go throws it with the velocity it had, then it flies freely."""
    r = run_scenario(xvfb, "drag_throw", tmp_path)
    assert r["grabbed"] == 0
    assert np.allclose(r["after_grab"], r["start"], atol=1e-9)
    v = drag_velocity(r)
    held = np.array([s["position"] for s in r["held"]])
    target_path = np.array(r["start"]) + v * r["frame"] * np.arange(1, 21)[:, None]
    assert np.linalg.norm(held[-1] - np.array(r["start"])) > 0.3  # it was carried along
    assert np.linalg.norm(held[-1] - target_path[-1]) > 0.01  # but by a spring: it lags the pointer
    last = r["still"][-1]
    sag = np.linalg.norm(r["g"]) / (2 * np.pi * SPRING_HERTZ) ** 2
    offset = np.array(last["position"]) - np.array(last["target"])
    assert np.linalg.norm(offset) < 1.5 * sag + 1e-3
    assert offset[1] < 0  # it hangs below the pointer, as a weight on a spring does
    # at rest: the speed read between steps is only the g·dt each step adds and the spring takes back
    assert np.linalg.norm(last["velocity"]) <= np.linalg.norm(r["g"]) * r["dt"]
    assert "holding     ball 0, throw" in r["hud_while_held"]
    released = np.array(r["released"]["velocity"])
    assert np.allclose(released, r["before_release"]["velocity"], atol=1e-12)  # let go, not set
    assert np.linalg.norm(released) > 1.0
    assert released @ v / (np.linalg.norm(released) * np.linalg.norm(v)) > 0.8  # along the drag
    assert r["held_after_release"] is None
    assert_free_flight(r, released)


def test_a_ball_pulled_into_a_square_by_the_spring_never_passes_through_it(xvfb, tmp_path):
    r = run_scenario(xvfb, "spring_into_plane", tmp_path)
    targets = np.array(r["targets"])
    assert targets[:, 1].min() < r["square"] - 1.0  # the pointer asked for a point far below the square
    heights, gaps = np.array(r["heights"]), np.array(r["gaps"])
    assert len(heights) >= 360  # every step of the 1.5 s held
    # pressed onto the square by about 40 g, slid along it, and never into it, let alone through it
    assert heights.min() > r["square"]
    assert gaps.min() > r["radius"] - 2e-3
    assert np.ptp(np.array(r["targets"])[30:, 0]) > 1.0  # it was dragged along the square too
    assert r["final"]["position"][1] > r["square"]


def test_b_shoots_a_ball_along_the_view_at_the_speed_the_hud_shows(xvfb, tmp_path):
    r = run_scenario(xvfb, "shoot", tmp_path)
    forward, eye = np.array(r["forward"]), np.array(r["eye"])
    assert (r["count_before"], r["count_after"]) == (1, 2)
    shot = r["shot"]
    assert np.allclose(shot["velocity"], 10.0 * forward, atol=1e-12)
    assert np.allclose(shot["position"], eye + forward * (2 * shot["radius"] + r["near"]), atol=1e-12)
    assert shot["radius"] == 0.3  # as big as the scene's balls
    assert "fly speed        4.00 m/s  shot 10 m/s" in r["hud"]
    assert r["speed_after_shift_b"] == 20.0 and r["count_after_shift_b"] == 2  # Shift+B does not shoot
    assert "shot 20 m/s" in r["hud_after_shift_b"]
    assert np.allclose(r["second"]["velocity"], 20.0 * forward, atol=1e-12)
    t = r["second_flight_time"]
    assert t == pytest.approx(0.1, abs=0.005)
    expected = 20.0 * forward + np.array([0, -9.81, 0]) * t
    assert np.allclose(r["second_later"]["velocity"], expected, atol=1e-9)
    assert r["colors"] == 3 and r["draw_instances"] == [3]  # one instanced draw for all balls


@needs_xdotool
def test_a_clicked_square_is_outlined_and_the_arrows_tilt_it_so_the_ball_rolls_off_not_through(
    xvfb, tmp_path
):
    r = run_scenario(xvfb, "plane_tilt", tmp_path)
    assert r["selected"] == 1
    assert r["amber_before"] == 0 and r["amber_pixels"] > 1000  # the highlighted rim, in real pixels
    forward = np.array(r["forward"])
    horizontal = np.array([forward[0], 0.0, forward[2]]) / np.hypot(forward[0], forward[2])
    assert np.allclose(r["spin_while_held"], TILT_RATE * horizontal, atol=1e-12)
    assert r["spin_after"] == [0.0, 0.0, 0.0]
    assert r["held_seconds"] == pytest.approx(1.0, abs=1e-6)
    tilt = math.acos(np.clip(r["normal"][1], -1, 1))
    assert tilt == pytest.approx(TILT_RATE * r["held_seconds"], abs=1e-9)  # a steady angular velocity
    # the right edge went down: the normal leans to the camera's right
    assert np.dot(r["normal"], np.cross(forward, [0, 1, 0])) > 0
    # the ball never sank into the square while over it ...
    _, signed, distance = np.array(r["track"]).T
    over = np.abs(distance - np.abs(signed)) < 1e-9  # the centre is over the square's face
    assert over[:60].all() and not over[-1]  # on it while it tilted, off it at the end
    assert (signed[over] > 0).all()  # never behind the square
    touching = over & (signed < r["radius"] + 0.05)
    assert touching.sum() > 60 and (signed[touching] > r["radius"] - 1e-3).all()  # never sinks
    # ... and on the still slope it rolls at (5/7) g sin θ
    rolling = np.array(r["rolling"])
    speed = np.linalg.norm(rolling[:, 1:], axis=1)
    a = (speed[-1] - speed[2]) / (rolling[-1, 0] - rolling[2, 0])
    assert a == pytest.approx(5 / 7 * 9.81 * math.sin(tilt), rel=0.02)
    assert r["end"]["position"][1] == pytest.approx(r["radius"], abs=1e-3)  # rolled off onto the floor
    assert r["phase_after_right"] == "RUNNING"
    assert r["after_escape"] == {"selected": None, "closed": False, "message": "plane deselected"}
    assert r["spin_after_escape"] == [0.0, 0.0, 0.0]
    assert r["reselected"] == 1 and r["after_sky_click"] is None


def test_pgup_and_pgdn_raise_and_lower_the_selected_square_with_the_ball_riding_it(xvfb, tmp_path):
    r = run_scenario(xvfb, "plane_lift", tmp_path)
    assert r["selected"] == 1
    assert r["velocity_while_held"] == [0.0, LIFT_SPEED, 0.0] and r["velocity_after"] == [0.0, 0.0, 0.0]
    assert r["up_seconds"] == pytest.approx(0.5, abs=1e-6)
    assert r["heights"][0][1] == pytest.approx(1.0 + LIFT_SPEED * r["up_seconds"], abs=1e-9)
    assert r["heights"][1][1] == pytest.approx(1.0, abs=1e-6)
    assert np.allclose(r["ball_velocity_while_held"], [0, LIFT_SPEED, 0], atol=1e-6)  # an elevator
    gaps = np.array(r["gaps"])
    assert gaps.min() > r["radius"] - 1e-4  # never sinks into it
    assert gaps.max() < r["radius"] + 0.01  # the sudden start at 1 m/s is an impact: a small hop
    assert np.allclose(gaps[10:], r["radius"], atol=1e-4)  # then it rides without jitter
    assert r["end_gap"] == pytest.approx(r["radius"], abs=1e-4)


def test_home_puts_the_camera_back_to_the_scenes_view(xvfb, tmp_path):
    r = run_scenario(xvfb, "home", tmp_path)
    assert r["moved"]["position"] != r["start"]["position"] and r["moved"]["yaw"] != r["start"]["yaw"]
    assert np.allclose(r["back"]["position"], r["start"]["position"], atol=1e-12)
    assert r["back"]["yaw"] == pytest.approx(r["start"]["yaw"]) and r["back"]["pitch"] == pytest.approx(
        r["start"]["pitch"]
    )


def test_ctrl_s_saves_the_scene_as_it_stands_to_a_new_file_that_loads_back_the_same(xvfb, tmp_path):
    r = run_scenario(xvfb, "save", tmp_path)
    first, second = Path(r["first"]), Path(r["second"])
    assert first == tmp_path / "live-saved-1.toml" and second == tmp_path / "live-saved-2.toml"
    assert r["message"] == "scene saved to live-saved-1.toml"  # the HUD says where
    assert not r["camera_moved_by_ctrl_s"]
    text = first.read_text()
    assert "# a ball resting on a square above the floor" in text and "# the square we tilt" in text
    check = subprocess.run(
        [sys.executable, "-m", "ballpit", "check", str(first)], env=subprocess_env(None),
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert check.returncode == 0 and "ok: 2 balls, 2 planes" in check.stdout, check.stderr
    loaded = ballpit.load_scene(first)
    w = r["world"]
    for key in ("positions", "velocities", "angular_velocities", "radii"):  # round-off is saved as 0
        assert_same_or_round_off(np.array(getattr(loaded.spheres, key)), np.array(w[key]), key)
    assert np.allclose(loaded.spheres.orientations, w["orientations"], rtol=0, atol=1e-15)
    assert np.allclose(loaded.planes.centers, w["plane_centers"], rtol=0, atol=1e-12)
    q, q_live = np.array(loaded.planes.orientations), np.array(w["plane_orientations"])
    assert np.allclose(np.abs(np.einsum("ij,ij->i", q, q_live)), 1.0, atol=1e-12)  # the same rotation
    assert np.array_equal(loaded.planes.velocities, np.zeros((2, 3)))  # held keys are not saved
