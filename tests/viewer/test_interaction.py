"""Reaching in without a window: balls added live, reset, the shot speeds, plane motion given back."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.core.contacts import KIND_NAMES
from ballpit.scene import read_scene
from ballpit.viewer.camera import Camera
from ballpit.viewer.interaction import SHOT_SPEEDS, TILT_RATE, Interaction, typical_material
from ballpit.viewer.picking import pointer_ray
from ballpit.viewer.simulation import Phase, Simulation

from .conftest import REPO, line_of_balls


def test_a_shot_ball_grows_everything_kept_per_ball_and_reset_drops_it_again():
    sim = Simulation(line_of_balls(3))
    hands = Interaction(sim)
    index = hands.shoot(Camera.looking_at((0, 3, 10), (0, 1, 0)))
    assert index == 3 and sim.ball_count == 4
    assert len(sim.world.spheres.masses) == len(sim.appearance.sphere_colors) == 4
    assert sim.prev_positions.shape == (4, 3) and sim.trails.ordered().shape[1] == 4
    sim.start()
    sim.advance(0.1)
    positions, _ = sim.render_state()
    assert positions.shape == (4, 3)
    sim.reset()
    assert (
        sim.ball_count == 3 and len(sim.appearance.sphere_colors) == 3 and len(sim.world.spheres.masses) == 3
    )


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_a_shot_ball_is_made_of_the_scenes_material_and_rolls_to_a_stop_at_five_sevenths_rho_g():
    sim = Simulation(read_scene(REPO / "scenes" / "slopes.toml"))  # every ball: e 1, mu 0.5, rho 0.3
    camera = Camera.looking_at((0.0, 0.25, 3.0), (0.0, 0.25, 10.0))  # eye at a ball's height, level
    ball = sim.world.spheres[Interaction(sim).shoot(camera)]  # starts on the ground, away from the slopes
    assert (ball.restitution, ball.friction, ball.rolling_friction) == (1.0, 0.5, 0.3)
    speeds = []
    for _ in range(4 * 240):  # 4 s
        sim.world.step(sim.timestep)
        speeds.append(float(np.linalg.norm(ball.velocity)))
    # rolling on the ground (rho 0.3 too): it slows at (5/7)·rho·g with rho = sqrt(0.3·0.3)
    assert speeds[round(1.5 * 240)] - speeds[round(2.5 * 240)] == pytest.approx(5 / 7 * 0.3 * 9.81, rel=1e-3)
    assert speeds[-1] < 1e-9 and ball.position[2] < 20.0  # at rest after about 14 m, not rolling for ever


def test_the_typical_material_is_the_most_common_one_and_the_first_on_a_tie():
    world = line_of_balls(1)
    for e, mu, rho in ((0.9, 0.4, 0.1), (0.5, 0.2, 0.0), (0.5, 0.2, 0.0), (0.9, 0.4, 0.1)):
        world.add_sphere(position=(0, 9, 0), radius=0.1, restitution=e, friction=mu, rolling_friction=rho)
    assert typical_material(world.spheres) == {"restitution": 0.9, "friction": 0.4, "rolling_friction": 0.1}
    world.add_sphere(position=(0, 9, 0), radius=0.1, restitution=0.5, friction=0.2)
    assert typical_material(world.spheres) == {"restitution": 0.5, "friction": 0.2, "rolling_friction": 0.0}
    assert typical_material(ballpit.World().spheres) == {}


def test_shift_b_steps_round_the_shot_speeds():
    hands = Interaction(Simulation(line_of_balls(1)))
    seen = [hands.next_shot_speed() for _ in range(len(SHOT_SPEEDS))]
    assert seen == [20.0, 40.0, 5.0, 10.0]


def test_a_selected_plane_turns_only_while_a_key_is_held_and_gets_its_own_motion_back():
    world = line_of_balls(1)
    world.planes[1].angular_velocity = (0.0, 0.1, 0.0)  # a plane that turns by itself
    sim = Simulation(world)
    hands = Interaction(sim)
    camera = Camera.looking_at((0, 3, 10), (0, 1, 0))  # looking along −z: right is +x
    hands.select(1)
    hands.update(camera, (320, 180), {"UP"}, 0.0)
    assert np.allclose(world.planes[1].angular_velocity, [-TILT_RATE, 0.1, 0.0])
    hands.update(camera, (320, 180), set(), 0.0)
    assert np.allclose(world.planes[1].angular_velocity, [0.0, 0.1, 0.0])
    hands.update(camera, (320, 180), {"PAGEDOWN", "RIGHT"}, 0.0)
    assert np.allclose(world.planes[1].velocity, [0.0, -1.0, 0.0])
    assert np.allclose(world.planes[1].angular_velocity, [0.0, 0.1, -TILT_RATE])
    assert hands.own_motion()[1][1].tolist() == [0.0, 0.1, 0.0]
    assert hands.takes_key("RIGHT") and not hands.takes_key("N")
    assert hands.deselect() and not hands.deselect()
    assert np.allclose(world.planes[1].velocity, 0.0)
    assert np.allclose(world.planes[1].angular_velocity, [0.0, 0.1, 0.0])
    assert not hands.takes_key("RIGHT")  # → steps again
    assert sim.phase is Phase.WAITING


def test_a_clicked_plane_is_named_by_the_index_the_events_give_it():
    """The HUD numbers planes as world.planes and the events' b (plane index) do: from 0."""
    world = line_of_balls(1, y=3.0)  # plane 0 the ground, plane 1 a slope under the ball
    sim = Simulation(world)
    contacts = []
    while not contacts:
        record = world.step(sim.timestep)
        contacts = [int(b) for k, b in zip(record.kind, record.b, strict=True) if k == 0]
    assert KIND_NAMES[0] == "sphere-plane" and contacts == [1]  # the ball landed on plane index 1
    hands = Interaction(sim)
    camera = Camera.looking_at((0, 3, 10), (0, 2, 0))
    (x, y), _ = camera.project(np.asarray(world.planes[1].position), 320, 180)  # rows from the top
    ray = pointer_ray(camera, x, 180 - y, 320, 180)  # pyglet's y runs up
    message = hands.press(ray, x, 180 - y, camera.forward)
    assert hands.selected_plane == 1
    assert message.startswith("plane 1 selected")
    assert hands.hud_lines() == ["selected    plane 1: arrows PgUp PgDn"]


def test_a_ball_pulled_by_the_mouse_joint_into_another_ball_pushes_it_and_never_passes_through_it():
    # Two balls side by side on the ground, no gravity to hold them: the left one is grabbed and its
    # target put 3 m beyond the right one. The spring drives it into its neighbour, which it must push
    # along (momentum) rather than pass through.
    world = ballpit.World(gravity=(0.0, 0.0, 0.0))
    world.add_spheres([[0.0, 1.0, 0.0], [0.7, 1.0, 0.0]], radius=0.3, friction=0.0)
    sim = Simulation(world)
    hands = Interaction(sim)
    camera = Camera.looking_at((0.0, 1.0, 6.0), (0.0, 1.0, 0.0))
    from ballpit.viewer.picking import Ray

    ray = Ray(np.array(camera.position), np.array([0.0, 0.0, -1.0]))
    hands.press(ray, 0.0, 0.0, camera.forward)
    assert hands.held_ball == 0
    sim.start()
    hands.target = np.array([3.7, 1.0, 0.0])
    gaps = []
    sim.after_step.append(
        lambda: gaps.append(float(np.linalg.norm(world.spheres[1].position - world.spheres[0].position)))
    )
    for _ in range(240):
        sim.advance(1 / 240)
    assert min(gaps) > 0.6 - 1e-3  # never into the other ball
    assert world.spheres[0].position[0] < world.spheres[1].position[0]  # still on its side
    assert world.spheres[1].position[0] > 1.5  # pushed along
