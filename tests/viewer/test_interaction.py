"""Reaching in without a window: balls added live, reset, the shot speeds, plane motion given back."""

from __future__ import annotations

import numpy as np

from ballpit.viewer.camera import Camera
from ballpit.viewer.interaction import SHOT_SPEEDS, TILT_RATE, Interaction
from ballpit.viewer.simulation import Phase, Simulation

from .conftest import line_of_balls


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
