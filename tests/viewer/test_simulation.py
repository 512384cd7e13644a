"""The viewer's simulation driver: fixed-step accumulator, interpolation, run phases, reset, reload."""

from __future__ import annotations

import copy
import itertools
import math
import os

import numpy as np
import pytest

import ballpit
from ballpit.scene import read_scene
from ballpit.viewer.simulation import MAX_FRAME_SECONDS, Phase, Simulation

from .conftest import line_of_balls

GOOD_SCENE = """
[world]
timestep = 0.005
integrator = "rk2"

[camera]
position = [1, 3, 9]
look_at = [0, 1, 0]

[[plane]]
position = [0, 0, 0]

[[sphere]]
position = [0, 3, 0]
radius = 0.3
color = "#ff0000"
"""


def drifting_world() -> ballpit.World:
    """No gravity, one ball moving at 1 m/s along x and spinning: motion is exactly linear in time."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_sphere(position=(0, 1, 0), velocity=(1, 0, 0), angular_velocity=(0, 2, 0), radius=0.5)
    return world


def test_nothing_moves_while_waiting_for_x():
    sim = Simulation(line_of_balls())
    before = np.array(sim.world.spheres.positions)
    assert sim.phase is Phase.WAITING
    assert sim.advance(1.0) == 0
    assert np.array_equal(sim.world.spheres.positions, before)
    assert sim.world.time == 0.0


def test_steps_are_fixed_and_the_accumulator_keeps_the_remainder():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    dt = sim.timestep
    fed = 0.0
    for frame in (0.016, 0.021, 0.0005, 0.033, 0.017):
        sim.advance(frame)
        fed += frame
        assert 0.0 <= sim.accumulator < dt
        assert sim.steps_total * dt + sim.accumulator == pytest.approx(fed, abs=1e-12)
    assert sim.world.time == pytest.approx(sim.steps_total * dt)


def test_a_long_frame_catches_up_at_most_the_frame_cap():
    sim = Simulation(drifting_world(), step_budget=math.inf)  # no wall-time limit: only the cap
    sim.start()
    steps = sim.advance(10.0)
    assert steps == pytest.approx(MAX_FRAME_SECONDS / sim.timestep, abs=1)


def test_slow_physics_drops_the_backlog_instead_of_spiralling():
    ticks = itertools.count(0.0, 0.03)  # every step appears to take 30 ms of wall time
    sim = Simulation(drifting_world(), step_budget=0.05, clock=lambda: next(ticks))
    sim.start()
    for _ in range(50):
        steps = sim.advance(0.1)  # each frame asks for 24 steps
        assert steps <= 3
        assert sim.accumulator < sim.timestep  # the debt never grows
    assert sim.dropped_seconds > 4.0


def test_rendering_interpolates_between_the_last_two_steps():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    dt = sim.timestep
    sim.advance(10.5 * dt)
    assert sim.alpha == pytest.approx(0.5, abs=1e-9)
    positions, orientations = sim.render_state()
    current = sim.world.spheres.positions
    assert positions[0, 0] == pytest.approx(current[0, 0] - 0.5 * dt)  # half a step behind, at 1 m/s
    assert np.allclose(np.linalg.norm(orientations, axis=1), 1.0)
    q_prev, q_now = sim.prev_orientations[0], sim.world.spheres.orientations[0]
    assert min(np.linalg.norm(orientations[0] - q_prev), np.linalg.norm(orientations[0] - q_now)) > 0


def test_pause_freezes_and_single_steps_advance_exactly_one_timestep():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    sim.advance(0.05)
    sim.toggle_pause()
    assert sim.phase is Phase.PAUSED
    t = sim.world.time
    assert sim.advance(0.5) == 0
    assert sim.world.time == t
    sim.step_once()
    sim.step_once()
    assert sim.world.time == pytest.approx(t + 2 * sim.timestep)
    assert sim.render_state()[0][0, 0] == sim.world.spheres.positions[0, 0]  # paused: no interpolation
    sim.toggle_pause()
    assert sim.phase is Phase.RUNNING
    assert sim.advance(0.05) > 0


def test_single_step_is_ignored_unless_paused():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.step_once()
    assert sim.world.time == 0.0
    assert "paused" in sim.message


def test_reset_restores_the_initial_state_and_waits_for_x_again():
    world = line_of_balls()
    initial = np.array(world.spheres.positions)
    sim = Simulation(world)
    sim.start()
    sim.set_integrator("euler")
    for _ in range(20):
        sim.advance(1 / 60)
    assert not np.allclose(sim.world.spheres.positions, initial)
    sim.reset()
    assert np.array_equal(sim.world.spheres.positions, initial)
    assert sim.world.time == 0.0
    assert sim.phase is Phase.WAITING
    assert sim.world.integrator == "euler"  # the live choice survives a reset


def test_the_real_time_factor_counts_no_time_spent_waiting_for_x_or_paused():
    """A run fed real time steps at real time: its first reading after X, and after a pause, is 1, not
    the share of a measuring window that also held the wait (0.4 s waited, then 0.1 s run: 0.2)."""
    sim = Simulation(drifting_world(), step_budget=math.inf)
    for _ in range(24):  # 0.4 s waiting for X
        sim.advance(1 / 60)
    sim.start()
    for _ in range(32):  # 0.53 s: one measuring window (0.5 s) and a little
        sim.advance(1 / 60)
    assert sim.real_time_factor == pytest.approx(1.0, abs=0.02)
    sim.toggle_pause()
    for _ in range(24):  # 0.4 s paused
        sim.advance(1 / 60)
    sim.toggle_pause()
    sim.real_time_factor = 0.0  # forget the reading before the pause: the next one is read anew
    for _ in range(32):
        sim.advance(1 / 60)
    assert sim.real_time_factor == pytest.approx(1.0, abs=0.02)


def test_time_scale_speeds_up_simulated_time():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    sim.faster()
    sim.advance(0.1)
    assert sim.world.time == pytest.approx(0.2, abs=sim.timestep)


def test_kinetic_energy_counts_translation_and_spin():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_sphere(velocity=(3, 0, 0), angular_velocity=(0, 0, 2), mass=2.0, radius=0.5)
    sim = Simulation(world)
    inertia = 0.4 * 2.0 * 0.5**2
    assert sim.kinetic_energy() == pytest.approx(0.5 * 2.0 * 9 + 0.5 * inertia * 4)


def test_trails_keep_recent_positions_oldest_first_within_a_budget():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    for _ in range(30):
        sim.advance(1 / 30)
    samples = sim.trails.ordered()
    assert samples.shape[1:] == (1, 3)
    assert np.all(np.diff(samples[:, 0, 0]) > 0)  # moving +x, oldest first
    big = Simulation(line_of_balls(10_000))
    assert big.trails.length * 10_000 <= 200_000


def test_scene_settings_come_from_the_scene_file(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD_SCENE)
    sim = Simulation(read_scene(path))
    assert sim.timestep == 0.005
    assert sim.appearance.name == "good.toml"
    assert np.allclose(sim.appearance.camera_position, [1, 3, 9])
    assert np.allclose(sim.appearance.sphere_colors, [[1, 0, 0]])


def test_a_broken_reload_keeps_the_last_good_world_and_reports_the_error(tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_text(GOOD_SCENE)
    sim = Simulation(read_scene(path))
    sim.start()
    sim.advance(0.1)
    world = sim.world
    path.write_text(GOOD_SCENE.replace("radius = 0.3", "radius = -1"))
    assert sim.reload() is False
    assert sim.world is world and sim.phase is Phase.RUNNING
    assert "radius" in sim.error and "scene.toml" in sim.error
    assert "keeping the last good scene" in capsys.readouterr().err
    assert sim.advance(0.1) > 0  # still running


def test_saving_the_file_is_noticed_and_a_good_reload_replaces_the_world(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(GOOD_SCENE)
    sim = Simulation(read_scene(path))
    generation = sim.generation
    assert not sim.file_changed()
    path.write_text(GOOD_SCENE + "\n[[sphere]]\nposition = [1, 3, 0]\n")
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))
    assert sim.file_changed()
    assert not sim.file_changed()  # once per change
    assert sim.reload() is True
    assert sim.ball_count == 2 and sim.error is None
    assert sim.generation > generation
    assert sim.phase is Phase.WAITING


def test_a_world_built_in_code_cannot_be_reloaded_but_keeps_running():
    sim = Simulation(drifting_world(), step_budget=math.inf)
    sim.start()
    assert sim.reload() is False
    assert "no scene file" in sim.error
    assert sim.phase is Phase.RUNNING


def test_the_initial_snapshot_is_independent_of_the_running_world():
    world = drifting_world()
    sim = Simulation(world)
    snapshot = copy.deepcopy(sim.initial.spheres.positions)
    sim.start()
    sim.advance(0.2)
    assert np.array_equal(sim.initial.spheres.positions, snapshot)
