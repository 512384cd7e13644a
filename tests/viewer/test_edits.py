"""What the panel's widgets command, without a window: each edit runs on the physics side through
``Simulation.edit`` (here a real Simulation, the command run at once as the physics thread would run it
between steps); refused edits leave their one-line error under the widget's key and change nothing."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.viewer import actions, controls
from ballpit.viewer.camera import Camera
from ballpit.viewer.edits import Edits, add_ball_at
from ballpit.viewer.interaction import SPRING_DAMPING, SPRING_HERTZ, spring_velocity
from ballpit.viewer.orbit import Orbit
from ballpit.viewer.picking import Ray
from ballpit.viewer.simulation import Phase, Simulation

from .conftest import line_of_balls


def run_now(sim: Simulation):
    """``PhysicsThread.submit`` as the physics thread runs it: the command, then its answer."""

    def submit(command, then=None):
        result = command(sim)
        if then is not None:
            then(result)

    return submit


def bounce_sim() -> Simulation:
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), restitution=1.0, friction=0.0)
    world.add_sphere(position=(0, 2.25, 0), radius=0.25, restitution=1.0, friction=0.0)
    return Simulation(world)


def test_every_action_has_one_handler_and_every_key_and_button_label_comes_from_the_same_binding():
    every = list(controls.Action) + list(controls.INTEGRATOR_ACTIONS)
    assert set(actions.HANDLERS) == set(every)
    assert actions.label(controls.Action.START, "Drop") == "Drop (X)"
    assert actions.label(controls.Action.RELOAD, "Reload") == "Reload (Ctrl+R / F5)"
    assert actions.label(controls.Action.STEP, "Step") == "Step (N / Right)"
    assert controls.action_for_key("F4") is controls.Action.PANEL


def test_a_ball_edit_mid_run_changes_the_next_bounce_to_e_squared_h_and_the_history_keeps_it():
    sim = bounce_sim()
    edits = Edits(run_now(sim))
    sim.start()
    sim.advance(0.2)
    edits.ball(0, "restitution", 0.5)
    assert edits.errors == {}
    step_edited = sim.timeline.history.current
    heights = []
    for _ in range(240):
        sim.advance(1 / 240)
        heights.append(sim.world.spheres[0].position[1])
    heights = np.array(heights)
    bounce = int(np.argmax(np.diff(heights) > 0))
    assert heights[bounce:].max() - 0.25 == pytest.approx(0.25 * 2.0, abs=1e-4)
    # stepping back past the edit and forward again repeats the edited run, bit for bit
    end = sim.world.spheres[0].position.copy()
    sim.toggle_pause()
    sim.timeline.seek(step_edited - 5)
    assert sim.world.spheres[0].restitution == 1.0
    sim.timeline.seek(sim.timeline.history.latest)
    assert np.array_equal(sim.world.spheres[0].position, end)


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("radius", -0.1, "radius must be positive, got -0.1"),
        ("radius", math.nan, "radius must be finite, got nan"),
        ("mass", 0.0, "mass must be positive, got 0.0"),
        ("restitution", -1.0, "restitution must be from 0 to 1, got -1.0"),
        ("restitution", 2.0, "restitution must be from 0 to 1, got 2.0"),
        ("velocity", (0.0, math.nan, 0.0), "velocity must be finite"),
    ],
)
def test_a_refused_ball_edit_leaves_its_error_under_its_widget_and_changes_nothing(name, value, message):
    sim = bounce_sim()
    edits = Edits(run_now(sim))
    before = sim.world.snapshot()
    edits.ball(0, name, value)
    assert edits.error(f"ball.{name}").startswith(message)
    after = sim.world.snapshot()
    assert np.array_equal(after.state.body, before.state.body)
    assert np.array_equal(after.model.spheres.radius, before.model.spheres.radius)
    edits.ball(0, name, 0.3 if name != "velocity" else (0, 1, 0))  # a good edit clears the error
    assert edits.error(f"ball.{name}") is None


def test_world_settings_apply_at_once_and_stay_through_a_reset_the_timestep_resets_the_run():
    sim = bounce_sim()
    edits = Edits(run_now(sim))
    sim.start()
    sim.advance(0.1)
    edits.world("gravity", (0.0, -1.62, 0.0))
    edits.world("substeps", 4)
    edits.world("sleep", True)
    edits.world("restitution_threshold", 0.2)
    assert sim.phase is Phase.RUNNING and sim.world.time > 0  # at once, the run goes on
    assert sim.world.gravity[1] == -1.62 and sim.world.substeps == 4 and sim.world.sleep
    sim.reset()
    assert (
        sim.world.gravity[1] == -1.62 and sim.world.substeps == 4 and sim.world.restitution_threshold == 0.2
    )
    edits.world("restitution_threshold", None)
    assert sim.world.restitution_threshold is None
    sim.start()
    sim.advance(0.1)
    edits.world("timestep", 1 / 120)
    assert sim.timestep == 1 / 120 and sim.phase is Phase.WAITING and sim.world.time == 0.0
    edits.world("substeps", 0)
    assert edits.error("world.substeps") == "substeps must be a whole number from 1 to 1,000, got 0"
    edits.world("gravity", (0, "a", 0))
    assert "gravity" in edits.error("world.gravity")
    assert sim.world.substeps == 4 and sim.world.gravity[1] == -1.62


def test_a_plane_turned_and_moved_from_the_inspector_and_a_bad_angle_refused():
    sim = Simulation(line_of_balls(2))
    edits = Edits(run_now(sim))
    edits.plane(1, "rotation", (0.0, 0.0, 30.0))
    edits.plane(1, "position", (1.0, 2.5, 0.0))
    plane = sim.world.planes[1]
    assert np.allclose(plane.normal, (-0.5, math.sqrt(3) / 2, 0.0))
    assert np.allclose(plane.position, (1.0, 2.5, 0.0))
    edits.plane(1, "rotation", (0.0, math.inf, 0.0))
    assert edits.error("plane.rotation") == "rotation must be finite, got (0.0, inf, 0.0)"
    assert np.allclose(plane.normal, (-0.5, math.sqrt(3) / 2, 0.0))


def test_the_panels_integrator_leaves_the_ghosts_the_other_integrators():
    sim = Simulation(line_of_balls(3))
    sim.toggle_ghosts()
    sim.start()
    sim.advance(0.1)
    Edits(run_now(sim)).world("integrator", "rk2")
    assert sim.world.integrator == "rk2"
    ghosts = sim.timeline.ghosts
    assert ghosts.integrators == ("euler", "rk4", "symplectic")
    assert {name: world.integrator for name, world in ghosts.worlds.items()} == {
        "euler": "euler",
        "rk4": "rk4",
        "symplectic": "symplectic",
    }


def test_deleting_a_ball_shrinks_what_is_kept_per_ball_and_the_ghosts_lose_it_too():
    sim = Simulation(line_of_balls(3))
    sim.toggle_ghosts()
    sim.start()
    sim.advance(0.1)
    edits = Edits(run_now(sim))
    edits.remove_ball(1)
    assert sim.ball_count == 2 and len(sim.appearance.sphere_colors) == 2
    assert all(len(g.spheres) == 2 for g in sim.timeline.ghosts.worlds.values())
    sim.advance(0.1)  # the run goes on
    assert len(sim.render_state()[0]) == 2


def test_a_ball_added_where_the_pointer_points_rests_on_that_plane_and_one_inside_it_is_refused():
    sim = Simulation(line_of_balls(1, y=6.0))
    down = Ray(np.array([2.0, 5.0, 0.0]), np.array([0.0, -1.0, 0.0]))
    index = add_ball_at(sim, down)
    ball = sim.world.spheres[index]
    assert np.allclose(ball.position, (2.0, 0.3 + 1e-3, 0.0))  # on the ground, the scene's radius
    with pytest.raises(ValueError, match="would overlap ball 1"):
        add_ball_at(sim, down)
    with pytest.raises(ValueError, match="point at a plane"):
        add_ball_at(sim, Ray(np.array([0.0, 5.0, 0.0]), np.array([0.0, 1.0, 0.0])))


def test_opening_a_broken_file_keeps_the_scene_and_says_why_under_scene(tmp_path):
    sim = bounce_sim()
    edits = Edits(run_now(sim))
    bad = tmp_path / "bad.toml"
    bad.write_text("[[sphere]]\nposition = [0, 1, 0]\nradius = -1\n")
    generation = sim.generation
    edits.open_scene(bad)
    assert sim.generation == generation and sim.error is None
    assert edits.error("scene").startswith("cannot open bad.toml:") and "radius" in edits.error("scene")


def test_the_mouse_joint_is_a_critically_soft_spring_whose_pull_does_not_depend_on_the_mass():
    # Held still at 2 cm from the target, with no gravity, the ball closes the gap like a damped
    # oscillator of f = 5 Hz and ζ = 0.7: after one period it has closed nearly all of it, without
    # overshooting by more than e^(−πζ/√(1−ζ²)) ≈ 4.6 % of it.
    h = 1 / 240
    x, v = np.array([0.02, 0.0, 0.0]), np.zeros(3)
    path = []
    for _ in range(round(1 / SPRING_HERTZ / h)):
        v = spring_velocity(x, v, np.zeros(3), np.zeros(3), h)
        x = x + v * h
        path.append(x[0])
    overshoot = math.exp(-math.pi * SPRING_DAMPING / math.sqrt(1 - SPRING_DAMPING**2))
    assert abs(path[-1]) < 0.02 * 0.1
    assert min(path) > -0.02 * overshoot * 1.3
    # a big pull is capped: at most SPRING_MAX_ACCELERATION·h per step
    far = spring_velocity(np.array([100.0, 0, 0]), np.zeros(3), np.zeros(3), np.zeros(3), h)
    assert np.linalg.norm(far) == pytest.approx(400.0 * h)


def test_the_orbit_camera_turns_about_its_target_zooms_towards_it_and_pans_with_it():
    camera = Camera.looking_at((0.0, 2.0, 10.0), (0.0, 2.0, 0.0))
    orbit = Orbit()
    orbit.start(camera, (0.0, 2.0, 0.0))
    orbit.turn(camera, 200, 0)
    assert orbit.distance(camera) == pytest.approx(10.0)
    assert np.allclose(camera.position + camera.forward * 10.0, (0.0, 2.0, 0.0))  # still looking at it
    assert camera.position[0] != 0.0
    orbit.zoom(camera, 2)
    assert orbit.distance(camera) == pytest.approx(10.0 * 0.85**2)
    before = camera.position.copy()
    orbit.pan(camera, 50, 0, 720)
    assert np.allclose(camera.position - before, orbit.target - (0.0, 2.0, 0.0))
    orbit.follow_wanted = True
    orbit.start(camera, (1.0, 1.0, 1.0), ball=3)
    assert orbit.follow == 3
    orbit.carry(camera, (2.0, 1.0, 1.0))
    assert np.allclose(orbit.target, (2.0, 1.0, 1.0))


def test_a_replay_refuses_edits_and_plays_on(tmp_path):
    from ballpit.cli.trajectory import TrajectoryWriter, read_trajectory

    sim = bounce_sim()
    out = tmp_path / "run.npz"
    writer = TrajectoryWriter(out, 1)
    world = sim.world.copy()
    for _ in range(10):
        b = world.spheres
        writer.record(world.time, b.positions, b.velocities, b.angular_velocities, b.orientations)
        world.step(1 / 240)
    writer.commit()
    replay = Simulation(bounce_sim().world, trajectory=read_trajectory(out, n_balls=1))
    edits = Edits(run_now(replay))
    edits.ball(0, "restitution", 0.5)
    assert edits.error("ball.restitution") == "a replay plays a recorded run: it cannot be edited"
    assert replay.world.spheres[0].restitution == 1.0
