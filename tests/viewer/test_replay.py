"""Reading trajectories for ``view --replay``: what simulate writes reads back exactly; what does not fit
the scene is a one-line error naming the file, exit status 2, before any window opens; a record made
after B added a ball replays, the added ball from the frame it appears in."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit.cli.trajectory import TrajectoryError, read_trajectory
from ballpit.scene import read_scene
from ballpit.viewer.recording import Recorder
from ballpit.viewer.replay import Replay
from ballpit.viewer.simulation import Simulation

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


SLOPES = SCENES / "slopes.toml"


def _record_with_a_shot(path: Path) -> tuple[Simulation, int]:
    """slopes.toml recorded in the viewer's way: 20 steps, a ball shot in (what B does), 20 more."""
    sim = Simulation(read_scene(SLOPES), SLOPES, step_budget=math.inf)
    recorder = Recorder(path, sim)
    sim.start()
    dt = sim.timestep
    sim.advance(20 * dt + 1e-9)
    shot = sim.add_ball((1.0, 0.0, 0.0), position=(0.0, 6.0, 2.0), radius=0.2, velocity=(0.0, 0.0, -3.0))
    sim.advance(20 * dt + 1e-9)
    recorder.finish()
    return sim, shot


@pytest.mark.parametrize("suffix", [".npz", ".csv"])
def test_a_record_made_after_a_ball_was_shot_in_replays(tmp_path, suffix):
    path = tmp_path / f"run{suffix}"
    live, shot = _record_with_a_shot(path)
    t = read_trajectory(path, n_balls=5)
    assert t.frames == 41 and t.balls == 6
    assert t.balls_at(0) == 5 and t.balls_at(20) == 5 and t.balls_at(21) == 6 and t.balls_at(40) == 6
    assert np.isnan(t.position[20, 5]).all()  # not there yet
    rtol = 0 if suffix == ".npz" else 1e-8
    np.testing.assert_allclose(t.position[40], live.world.spheres.positions, rtol=rtol, atol=1e-12)

    sim = Simulation(read_scene(SLOPES), SLOPES, trajectory=t)
    assert sim.error is None and sim.ball_count == 5
    assert len(sim.appearance.sphere_colors) == 6  # a colour for the added ball, as B gives it
    sim.start()
    sim.advance(30 * sim.timestep)  # plays on past the frame the ball appears in
    assert sim.ball_count == 6 and len(sim.prev_positions) == 6
    current = sim.timeline.replay.current
    np.testing.assert_allclose(sim.world.spheres.positions, t.position[current], rtol=rtol, atol=1e-12)
    assert sim.world.spheres[shot].radius == pytest.approx(np.median(read_scene(SLOPES).world.spheres.radii))
    sim.toggle_pause()
    sim.scrub(0.0)  # back before the shot: the scene's five balls again
    assert sim.ball_count == 5 and len(sim.trails.ordered()[0]) == 5
    np.testing.assert_array_equal(sim.world.spheres.positions, t.position[0, :5])


def test_replay_seek_outside_the_added_balls_keeps_the_scene_balls(tmp_path):
    path = tmp_path / "run.csv"
    _record_with_a_shot(path)
    world = read_scene(SLOPES).world
    t = read_trajectory(path)
    r = Replay(world, t)
    for frame in (40, 3, 25, 0):
        r.seek(frame)
        assert len(world.spheres) == t.balls_at(frame)
        np.testing.assert_array_equal(world.spheres.positions, t.position[frame, : t.balls_at(frame)])
