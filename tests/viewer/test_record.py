"""``ballpit view SCENE --record FILE``: the timeline the viewer showed, written when the window closes
(Esc Esc, the close button, Ctrl+C). An untouched run's record equals ``ballpit simulate`` bit for bit."""

from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from ballpit import cli
from ballpit.cli.trajectory import TRAJECTORY_COLUMNS
from ballpit.scene import default_scene_path, read_scene

from .conftest import ended, run_driver, started, subprocess_env, xdotool
from .test_reach import DRIVER as REACH_DRIVER

# record_close_button runs on its own (REACH_DRIVER): asked through test_reach's batch, a worker without
# that batch ran all of reach_driver.py's scenarios again for it

needs_xdotool = pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")


@contextmanager
def viewer(display: str, workdir: Path, *args: str) -> Iterator[subprocess.Popen]:
    """``ballpit view ARGS`` in its own process, once frames flow in its window (the pointer on it)."""
    with started([sys.executable, "-m", "ballpit", "view", *args], display, workdir) as proc:
        window, name = "", ""
        deadline = time.monotonic() + 60
        while (
            not re.search(r"[1-9]\d*\.\d FPS$", name) and time.monotonic() < deadline and proc.poll() is None
        ):
            time.sleep(0.2)
            window = window or xdotool(display, "search", "--name", "slopes.toml").split("\n")[0]
            name = xdotool(display, "getwindowname", window) if window else ""
        assert window and proc.poll() is None, f"no viewer window: {ended(proc)}"
        xdotool(display, "mousemove", "--window", window, "20", "20")  # pointer focus for XTEST input
        yield proc


def finish(proc: subprocess.Popen) -> tuple[str, str]:
    try:
        return proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the viewer did not exit; {ended(proc)}")


def quit_viewer(display: str, proc: subprocess.Popen) -> tuple[str, str]:
    """Esc, Esc: the viewer quits (writing its record); what it printed."""
    xdotool(display, "key", "Escape")
    time.sleep(0.3)
    xdotool(display, "key", "Escape")
    return finish(proc)


def simulate(scene: Path, steps: int, out: Path) -> None:
    """``ballpit simulate`` for exactly ``steps`` steps of the scene's timestep (its command line run in
    this process: the viewer's record is what runs apart)."""
    dt = read_scene(scene).timestep
    assert cli.main(["simulate", str(scene), "--duration", repr(steps * dt), "--out", str(out), "-q"]) == 0


def assert_same_trajectory(record, expected) -> None:
    """Every trajectory column of ``record`` equals ``expected``'s, dtype and bits."""
    for column in TRAJECTORY_COLUMNS:
        assert record[column].dtype == expected[column].dtype, column
        assert np.array_equal(record[column], expected[column]), column  # bit for bit


@needs_xdotool
def test_a_record_closed_before_x_holds_only_the_start_though_the_drop_was_stepped_meanwhile(xvfb, tmp_path):
    # waiting for X, the physics thread steps the drop's first 1.5 s ahead (stepper.py, "Held before X");
    # none of it was shown, so none of it is recorded
    scene = tmp_path / "slopes.toml"
    shutil.copy(default_scene_path(), scene)
    with viewer(xvfb, tmp_path, str(scene), "--record", "run.npz") as proc:
        time.sleep(2.0)
        out, err = quit_viewer(xvfb, proc)
    assert proc.returncode == 0 and "Traceback" not in err, err
    assert "recorded 0 steps (5 balls) to run.npz" in out
    record = np.load(tmp_path / "run.npz")
    assert np.unique(record["time"]).tolist() == [0.0]
    simulate(scene, 1, tmp_path / "sim.npz")
    expected = np.load(tmp_path / "sim.npz")
    start = expected["time"] == 0.0
    assert_same_trajectory(record, {column: expected[column][start] for column in TRAJECTORY_COLUMNS})


@needs_xdotool
def test_a_recorded_untouched_run_equals_ballpit_simulate_bit_for_bit(xvfb, tmp_path):
    scene = tmp_path / "slopes.toml"
    shutil.copy(default_scene_path(), scene)
    with viewer(xvfb, tmp_path, str(scene), "--record", "run.npz") as proc:
        xdotool(xvfb, "key", "x")
        time.sleep(2.0)  # the drop, the first bounces and spins
        out, err = quit_viewer(xvfb, proc)
    assert proc.returncode == 0 and "Traceback" not in err, err
    record = np.load(tmp_path / "run.npz")
    assert set(record.files) == set(TRAJECTORY_COLUMNS)
    times = np.unique(record["time"])
    steps = len(times) - 1  # the starting state, then one record per step
    assert steps > 100, steps
    assert f"recorded {steps} steps (5 balls) to run.npz" in out
    simulate(scene, steps, tmp_path / "sim.npz")
    assert_same_trajectory(record, np.load(tmp_path / "sim.npz"))


@needs_xdotool
def test_a_record_rewound_and_resumed_holds_the_timeline_as_it_stands_and_equals_simulate(xvfb, tmp_path):
    # Run, pause, step back a second and a few steps through the history, resume, run on, quit: the
    # record drops the steps that were dropped, so no step appears twice and it still equals an
    # untouched ``ballpit simulate`` of as many steps, bit for bit.
    scene = tmp_path / "slopes.toml"
    shutil.copy(default_scene_path(), scene)
    with viewer(xvfb, tmp_path, str(scene), "--record", "run.npz") as proc:
        xdotool(xvfb, "key", "x")
        time.sleep(2.0)
        xdotool(xvfb, "key", "space")  # pause
        time.sleep(0.3)
        xdotool(xvfb, "key", "shift+Left")  # a second back
        for _ in range(3):
            xdotool(xvfb, "key", "Left")  # and three steps
        time.sleep(0.3)
        xdotool(xvfb, "key", "space")  # resume from the past: the later history is dropped
        time.sleep(1.0)
        _out, err = quit_viewer(xvfb, proc)
    assert proc.returncode == 0 and "Traceback" not in err, err
    record = np.load(tmp_path / "run.npz")
    times = record["time"].reshape(-1, 5)[:, 0]  # five balls a record
    assert np.all(np.diff(times) > 0)  # no step twice, no jump back in time
    steps = len(times) - 1
    assert steps > 100, steps
    simulate(scene, steps, tmp_path / "sim.npz")
    assert_same_trajectory(record, np.load(tmp_path / "sim.npz"))


@needs_xdotool
def test_ctrl_c_writes_the_record_and_a_shot_ball_gets_the_next_id(xvfb, tmp_path):
    scene = tmp_path / "slopes.toml"
    shutil.copy(default_scene_path(), scene)
    with viewer(xvfb, tmp_path, str(scene), "--record", "run.csv") as proc:
        xdotool(xvfb, "key", "x")
        time.sleep(0.8)
        xdotool(xvfb, "key", "b")
        time.sleep(0.8)
        proc.send_signal(signal.SIGINT)  # Ctrl+C in the terminal
        out, err = finish(proc)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err, err
    lines = (tmp_path / "run.csv").read_text().splitlines()
    assert lines[0] == ",".join(TRAJECTORY_COLUMNS)
    rows = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    times, ids = rows[:, 0], rows[:, 1].astype(int)
    counts = np.array([np.sum(times == t) for t in np.unique(times)])
    assert set(counts) == {5, 6}  # five balls, then six from the step after B
    first_six = int(np.argmax(counts == 6))
    assert (counts[:first_six] == 5).all() and (counts[first_six:] == 6).all()
    assert set(ids[times == times[-1]]) == {0, 1, 2, 3, 4, 5}
    steps = len(counts) - 1
    assert f"recorded {steps} steps (6 balls) to run.csv" in out
    # up to the shot, the same rows, to the character, as simulate writes
    simulate(scene, first_six - 1, tmp_path / "sim.csv")
    expected = (tmp_path / "sim.csv").read_text().splitlines()
    assert lines[: len(expected)] == expected and len(expected) == 1 + 5 * first_six


def test_the_close_button_writes_the_record_and_a_reset_starts_the_timeline_again(xvfb, tmp_path):
    r = run_driver(REACH_DRIVER, xvfb, "record_close_button", tmp_path, timeout=180)
    assert r["written_before_close"] is False and r["closed"]
    record = np.load(tmp_path / "run.npz")
    times = np.unique(record["time"])
    assert times[0] == 0.0 and np.all(np.diff(times) > 0)  # from the reset on: no jump back in time
    assert len(times) - 1 == r["steps_since_reset"]
    live = read_scene(tmp_path / "live.toml")
    world = live.world
    from ballpit.cli.simulate import run
    from ballpit.cli.trajectory import TrajectoryWriter

    writer = TrajectoryWriter(tmp_path / "sim.npz", len(world.spheres))
    run(world, r["steps_since_reset"] * live.timestep, dt=live.timestep, trajectory=writer)
    writer.commit()
    assert_same_trajectory(record, np.load(tmp_path / "sim.npz"))


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_a_bad_record_path_is_a_one_line_error_before_any_window(tmp_path):
    for bad, says in (("run.txt", "must end in .csv or .npz"), ("nowhere/run.npz", "does not exist")):
        proc = subprocess.run(
            [sys.executable, "-m", "ballpit", "view", "slopes", "--record", bad], env=subprocess_env(None),
            cwd=tmp_path, capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "--record" in lines[0] and says in lines[0], proc.stderr
