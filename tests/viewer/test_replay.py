"""Reading trajectories for ``view --replay``: what simulate writes reads back exactly; what does not fit
the scene is a one-line error naming the file, exit status 2, before any window opens."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit.scene import read_scene
from ballpit.viewer.replay import Replay, TrajectoryError, read_trajectory

from ..cli.test_commands import assert_user_error
from ..cli.test_commands import ballpit as run_ballpit

SCENES = Path(__file__).resolve().parents[2] / "scenes"


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Path]:
    """slopes.toml for 0.5 s written by simulate as .npz and as .csv (every 5th step)."""
    folder = tmp_path_factory.mktemp("runs")
    out = {}
    for suffix in ("npz", "csv"):
        path = folder / f"run.{suffix}"
        r = run_ballpit(
            "simulate", SCENES / "slopes.toml", "--duration", "0.5", "--every", "5", "--out", path, "-q"
        )
        assert r.returncode == 0, r.stderr
        out[suffix] = path
    return out


def test_simulate_output_reads_back_as_the_run_it_recorded(runs):
    world = ballpit.load_scene(SCENES / "slopes.toml")
    npz = read_trajectory(runs["npz"], n_balls=len(world.spheres))
    csv = read_trajectory(runs["csv"], n_balls=len(world.spheres))
    assert npz.frames == csv.frames == 25  # the initial state and every 5th of 120 steps
    assert np.allclose(npz.times, csv.times, rtol=1e-8, atol=0)  # CSV keeps 9 digits
    assert np.allclose(npz.position, csv.position, rtol=1e-8, atol=1e-12)
    dt = read_scene(SCENES / "slopes.toml").timestep
    for _ in range(5 * 7):
        world.step(dt)
    assert np.array_equal(npz.position[7], world.spheres.positions)  # .npz is bit for bit
    assert np.array_equal(npz.orientation[7], world.spheres.orientations)


def test_a_replay_writes_its_frames_into_the_scene_world(runs):
    world = ballpit.load_scene(SCENES / "slopes.toml")
    trajectory = read_trajectory(runs["npz"])
    replay = Replay(world, trajectory)
    assert replay.latest == 24 and replay.timestep == pytest.approx(
        5 * read_scene(SCENES / "slopes.toml").timestep
    )
    replay.seek(10)
    assert np.array_equal(world.spheres.velocities, trajectory.velocity[10])
    assert world.time == trajectory.times[10]
    assert replay.advance(replay.timestep * 2.5) and replay.current == 12
    replay.seek(24)
    assert not replay.advance(1.0)


def test_stacked_npz_arrays_read_too(tmp_path, runs):
    t = read_trajectory(runs["npz"])
    stacked = tmp_path / "stacked.npz"
    n = t.frames * t.balls
    np.savez(stacked, time=np.repeat(t.times, t.balls), id=np.tile(np.arange(t.balls), t.frames),
             position=t.position.reshape(n, 3), velocity=t.velocity.reshape(n, 3),
             angular_velocity=t.angular_velocity.reshape(n, 3),
             orientation=t.orientation.reshape(n, 4))  # fmt: skip
    again = read_trajectory(stacked)
    assert np.array_equal(again.position, t.position) and np.array_equal(again.orientation, t.orientation)


def test_trajectories_that_do_not_fit_are_one_line_errors_with_status_2(tmp_path, runs):
    slopes, cradle = SCENES / "slopes.toml", SCENES / "cradle.toml"
    assert_user_error(run_ballpit("view", cradle, "--replay", runs["npz"]), "run.npz", "5 balls", "6")
    assert_user_error(run_ballpit("view", cradle, "--replay", runs["csv"]), "run.csv", "5 balls")
    missing = tmp_path / "missing.csv"
    missing.write_text("time,id,x,y,z\n0,0,1,2,3\n")
    assert_user_error(run_ballpit("view", slopes, "--replay", missing), "missing.csv", "missing", "vx", "qw")
    junk = tmp_path / "junk.npz"
    junk.write_text("not a zip")
    assert_user_error(run_ballpit("view", slopes, "--replay", junk), "junk.npz", "not an .npz")
    bad = tmp_path / "bad.csv"
    bad.write_text(runs["csv"].read_text().splitlines()[0] + "\n0,0,1,2,x\n")
    assert_user_error(run_ballpit("view", slopes, "--replay", bad), "bad.csv", "cannot read")
    assert_user_error(
        run_ballpit("view", slopes, "--replay", tmp_path / "nope.npz"), "nope.npz", "no such file"
    )
    assert_user_error(
        run_ballpit("view", slopes, "--replay", tmp_path / "run.txt"), "run.txt", ".csv or .npz"
    )
    with pytest.raises(TrajectoryError, match=r"ids 0\.\.N-1"):
        shuffled = tmp_path / "shuffled.csv"
        lines = runs["csv"].read_text().splitlines()
        shuffled.write_text("\n".join([lines[0], lines[2], lines[1], *lines[3:]]) + "\n")
        read_trajectory(shuffled)


def test_replay_is_in_the_view_help():
    r = subprocess.run([sys.executable, "-m", "ballpit", "view", "--help"], capture_output=True, text=True)
    assert "--replay" in r.stdout
