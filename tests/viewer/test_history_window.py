"""History keys and scrubbing, replay, integrator ghosts and the energy plot in real windows under Xvfb
(history_driver.py runs each scenario in its own process)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ballpit.physics import INTEGRATOR_NAMES

from .conftest import REPO, run_driver, subprocess_env

DRIVER = Path(__file__).with_name("history_driver.py")


# the scenarios of history_driver.py that take no extra arguments, run in one window process
BATCH = ("history_keys", "ghosts_and_plot", "ghosts_in_real_time")


def run_scenario(display: str, name: str, workdir: Path, *extra: str) -> dict:
    return run_driver(DRIVER, display, name, workdir, *extra, timeout=300, batch=() if extra else BATCH)


def test_arrow_keys_and_a_dragged_timeline_move_through_the_history_exactly(xvfb, tmp_path):
    r = run_scenario(xvfb, "history_keys", tmp_path)
    assert r["bar_before_drop"] == 0  # no timeline before the drop
    assert r["paused_at"] == 360 and r["paused_matches"]
    # every stop is the state a plain headless run had at that step, bit for bit
    assert r["checks"] == [["left", 359, True], ["left", 358, True], ["left", 357, True],
                           ["shift+left", 117, True], ["right", 118, True], ["n", 119, True],
                           ["shift+right", 359, True]]  # fmt: skip
    assert r["latest"] == 360  # going back and forth through the history keeps it
    assert r["bar_pixels"] > 300  # the bar is drawn along the bottom
    assert "screen panels" in r["labels"]
    # a real pointer drag on the bar scrubs (and pauses)
    assert r["scrubbed_to"] == r["scrub_expected"] and r["scrub_matches"]
    assert r["scrub_phase"] == "PAUSED"
    assert "in the past" in r["hud"]
    # resuming from the past drops the future; the re-run still equals the plain run
    assert r["resumed_from"] <= r["after_resume_latest"] < r["resumed_from"] + 10
    assert r["rerun_at"] > r["resumed_from"] and r["rerun_matches"]


def test_ghosts_show_each_integrators_drift_and_the_plot_draws_it(xvfb, tmp_path):
    r = run_scenario(xvfb, "ghosts_and_plot", tmp_path)
    assert r["steps"] == 720
    drifts = {name: (drift, main) for name, drift, main in r["drifts"]}
    assert drifts["rk4"][1] and not drifts["euler"][1] and not drifts["rk2"][1]
    # identical to the same runs done headless
    for name, expected in r["expected"].items():
        assert drifts[name][0] == pytest.approx(expected, rel=1e-12, abs=1e-12)
    # a frictionless elastic bounce: RK4 (and midpoint RK2: exact for constant gravity) hold the energy;
    # explicit Euler gains about g·dt of speed per flight, a few % over two bounces from 2 m
    assert abs(drifts["rk4"][0]) < 1e-6 and abs(drifts["rk2"][0]) < 1e-6
    assert 1.0 < drifts["euler"][0] < 6.0
    assert "E drift ghost Euler" in r["hud"] and "+3.06" in r["hud"]
    calls = dict((label, n) for label, n in r["calls"])
    assert calls["balls"] == 1 and calls["ghosts"] == 3  # one instanced call for the three ghost sets
    assert [label for label, _ in r["calls"]].count("balls") == 1
    # the panel's energy plot (P): one total line per integrator, in its ghost's colour
    assert r["plot_pixels"]["euler"] > 20 and r["plot_pixels"]["rk4"] > 20
    assert r["kinetic_pixels"] > 50
    assert r["series"] == ["kinetic", "potential", "time", *(f"total {n}" for n in sorted(INTEGRATOR_NAMES))]
    assert r["span"] == pytest.approx(3.0, abs=0.05)
    assert r["ghosts_in_a_process"]  # the viewer steps them in a process of their own
    assert r["ghost_step_after_left"] == 719  # the ghosts step back with the run
    assert r["ghosts_after_left_match"] == {name: True for name in INTEGRATOR_NAMES if name != "rk4"}
    assert "ghosts" not in r["calls_off"]


def test_in_real_time_the_ghosts_are_drawn_at_the_step_shown_and_esc_esc_ends_their_process(xvfb, tmp_path):
    r = run_scenario(xvfb, "ghosts_in_real_time", tmp_path)
    running = [f for f in r["frames"] if f[0] is not None and f[0] > 0]
    assert len(running) > 30
    # two balls, three ghosts each, in every frame; the child steps ahead of the run, so the frame of
    # the step shown is there when it is drawn (on a quiet machine every frame; on a loaded one the
    # child, niced, may fall behind and the latest step it reached is drawn), never a later one
    assert all(f[2] == 3 for f in running)
    assert any(f[1] == f[0] for f in running)
    assert all(f[1] <= f[0] for f in running)
    assert running[-1][1] > running[0][1]  # they move on
    step, ghost_step, current = r["paused"]
    assert step == ghost_step == current  # paused, they are drawn at the step shown
    calls = dict((label, n) for label, n in r["calls"])
    assert calls["ghosts"] == 6
    assert r["pid_alive"] and r["closed"] and r["quit_seconds"] < 2.0
    assert r["pid_gone"]


@pytest.fixture(scope="module")
def slopes_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A ``ballpit simulate`` trajectory of the slopes demo (2 s), made once for the replay tests (they
    only read it; BATCH keeps this module's tests on one worker)."""
    out = tmp_path_factory.mktemp("slopes_run") / "run.npz"
    proc = subprocess.run(
        [sys.executable, "-m", "ballpit", "simulate", str(REPO / "scenes" / "slopes.toml"), "--duration", "2",
         "--out", str(out), "-q"],
        env=subprocess_env(None), capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return out


def test_a_simulate_trajectory_replays_with_pause_step_scrub_and_time_scale(xvfb, tmp_path, slopes_run):
    r = run_scenario(xvfb, "replay", tmp_path, str(REPO / "scenes" / "slopes.toml"), str(slopes_run))
    assert r["phase"] == "RUNNING" and r["first"] == [0, True]
    frame, time, matches = r["after_half_second"]
    assert 118 <= frame <= 120 and matches and time == pytest.approx(frame / 240, abs=1e-6)
    assert r["paused_still"]
    assert r["left"][1] == r["left"][0] - 1 and r["left"][2]
    assert r["right_twice"] == [r["left"][1] + 2, True]
    current, latest, matches = r["scrub"]
    assert latest == 480 and current == round(0.1 * latest) and matches
    elapsed, scale, matches = r["fast"]
    assert scale == 2.0 and elapsed == pytest.approx(1.0, abs=0.02) and matches  # 0.5 s of frames at ×2
    assert r["end"] == [480, 480, "PAUSED"]
    assert "replay      run.npz" in r["hud"]


def test_b_and_dragging_a_ball_in_a_replay_are_refused_with_a_message_and_the_replay_plays_on(
    xvfb, tmp_path, slopes_run
):
    r = run_scenario(
        xvfb, "replay_refuses_reaching_in", tmp_path, str(REPO / "scenes" / "slopes.toml"), str(slopes_run)
    )
    assert r["before"]["phase"] == "RUNNING" and r["before"]["balls"] == 5
    assert "not available in a replay" in r["b_message"]
    after = r["after_b"]
    assert after["balls"] == 5 and after["error"] is None and after["phase"] == "RUNNING"
    assert after["frame"] >= r["before"]["frame"] + 100 and after["matches"]  # 0.5 s more, as recorded
    assert "not available in a replay" in r["drag_message"] and r["held"] is None
    assert r["after_drag"] == r["paused_at"] and r["after_drag"]["matches"]  # nothing moved
    resumed = r["resumed"]
    assert resumed["frame"] >= r["paused_at"]["frame"] + 100 and resumed["matches"]
    assert resumed["error"] is None and resumed["balls"] == 5


def test_the_integrators_scene_shows_the_ghosts_apart_from_their_balls(xvfb, tmp_path):
    r = run_scenario(xvfb, "integrator_ghosts_part_ways", tmp_path, str(REPO / "scenes" / "integrators.toml"))
    assert r["help_shown"] and "ballpit view integrators" in r["help"]
    named = next(line for line in r["help"].splitlines() if "integrators" in line)  # beside G
    assert named.startswith("G ") and "ghosts" in named
    radius = r["radius"]
    early, late = r["t1"], r["t5"]
    for name in ("euler", "rk2"):  # the scene runs RK4; G shows the other two
        # 1 s in, each ghost still covers its ball (under 5 cm apart)...
        assert early[name]["time"] == early["time"] and max(early[name]["metres"]) < 0.05
        # ...and by 5 s most have left it: more than a ball's width away, in the world and on screen
        metres, pixels = np.array(late[name]["metres"]), np.array(late[name]["pixels"])
        assert late[name]["time"] == late["time"] == pytest.approx(5.0, abs=0.05)
        assert np.median(metres) > 2 * radius, metres
        assert np.median(pixels) > 2 * late["drawn_radius"], pixels
    calls = dict((label, n) for label, n in late["calls"])
    ghost_sets = len(INTEGRATOR_NAMES) - 1  # every other registered integrator
    assert calls["balls"] == 8 and calls["ghosts"] == 8 * ghost_sets  # every ghost set is drawn
