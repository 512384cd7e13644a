"""Edits between steps: a ball's size and mass, removing a ball, moving a plane, the overlap check a
ball added by hand passes. Each is validated (naming the argument) and the step goes on from it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit


def ground_and_ball(height: float = 2.0, radius: float = 0.5) -> tuple[ballpit.World, object]:
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), restitution=0.0)
    ball = world.add_sphere(position=(0, height, 0), radius=radius)
    return world, ball


def test_a_resized_ball_has_the_inertia_of_its_new_size_and_comes_to_rest_on_its_new_radius():
    world, ball = ground_and_ball()
    world.set_sphere_size(0, radius=0.2, mass=3.0)
    assert ball.radius == 0.2 and ball.mass == 3.0
    assert ball.inertia == pytest.approx(0.4 * 3.0 * 0.2**2, rel=1e-12)
    for _ in range(480):
        world.step(1 / 240)
    assert ball.position[1] == pytest.approx(0.2, abs=1e-6)
    assert abs(ball.velocity[1]) < 1e-6


def test_a_hollow_ball_keeps_two_thirds_m_r_squared_when_resized():
    world = ballpit.World()
    ball = world.add_sphere(position=(0, 0, 0), radius=0.5, mass=2.0, hollow=True)
    world.set_sphere_size(0, radius=1.0)
    assert ball.inertia == pytest.approx(2.0 / 3.0 * 2.0 * 1.0, rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "named"),
    [({"radius": -0.1}, "radius"), ({"radius": math.nan}, "radius"), ({"mass": 0.0}, "mass")],
)
def test_a_bad_size_is_refused_naming_it_and_changes_nothing(kwargs, named):
    world, ball = ground_and_ball()
    inertia = ball.inertia
    with pytest.raises(ValueError, match=named):
        world.set_sphere_size(0, **{"radius": 0.3, "mass": 2.0, **kwargs})
    assert (ball.radius, ball.mass, ball.inertia) == (0.5, 1.0, inertia)


@pytest.mark.parametrize("index", [1, -1])
def test_a_ball_index_out_of_range_is_refused_naming_index(index):
    world, _ = ground_and_ball()
    with pytest.raises(ValueError, match="index"):
        world.set_sphere_size(index, radius=0.3)
    with pytest.raises(ValueError, match="index"):
        world.remove_sphere(index)


def test_removing_a_ball_keeps_the_others_and_their_fall_is_still_free_fall():
    world = ballpit.World()
    world.add_spheres([[0, 10, 0], [2, 10, 0], [4, 10, 0]], radius=0.2, mass=[1.0, 2.0, 3.0])
    world.remove_sphere(1)
    assert len(world.spheres) == 2
    assert list(world.spheres.masses) == [1.0, 3.0]
    assert np.allclose(world.spheres.positions[:, 0], [0.0, 4.0])
    for _ in range(240):
        world.step(1 / 240)
    assert np.allclose(world.spheres.positions[:, 1], 10 - 0.5 * 9.81 * world.time**2, atol=1e-9)


def test_removing_a_ball_from_a_settled_sleeping_pile_wakes_it_and_the_ball_above_falls_into_the_gap():
    world = ballpit.World(sleep=True)
    world.add_plane(position=(0, 0, 0), restitution=0.0)
    world.add_spheres([[0, 0.5, 0], [0, 1.5, 0]], radius=0.5, restitution=0.0)
    for _ in range(480):
        world.step(1 / 240)
    assert world.asleep.all()
    world.remove_sphere(0)
    assert not world.asleep.any()
    for _ in range(480):
        world.step(1 / 240)
    assert world.spheres[0].position[1] == pytest.approx(0.5, abs=1e-6)


def test_a_moved_plane_catches_a_ball_at_its_new_height_and_tilted_it_rolls_it_at_five_sevenths_g_sin():
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), size=4.0, restitution=0.0)
    ball = world.add_sphere(position=(0, 3, 0), radius=0.5, restitution=0.0)
    world.move_plane(0, position=(0, 1, 0))
    assert np.allclose(world.planes[0].position, (0, 1, 0))
    for _ in range(480):
        world.step(1 / 240)
    assert ball.position[1] == pytest.approx(1.5, abs=1e-6)
    world.move_plane(0, rotation=(0, 0, 10))
    assert np.allclose(world.planes[0].normal, (-math.sin(math.radians(10)), math.cos(math.radians(10)), 0))
    ball.position = world.planes[0].position + 0.5 * world.planes[0].normal  # on the tilted face
    ball.velocity = (0, 0, 0)
    world.step(1 / 240)
    v0, t0 = ball.velocity.copy(), world.time
    for _ in range(60):
        world.step(1 / 240)
    a = np.linalg.norm(ball.velocity - v0) / (world.time - t0)
    assert a == pytest.approx(5 / 7 * 9.81 * math.sin(math.radians(10)), rel=1e-3)


@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"position": (0, math.nan, 0)}, "position"),
        ({"rotation": (0, 0)}, "rotation"),
        ({"index": 3}, "index"),
    ],
)
def test_a_bad_plane_move_is_refused_naming_it_and_changes_nothing(kwargs, named):
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), size=4.0)
    index = kwargs.pop("index", 0)
    with pytest.raises(ValueError, match=named):
        world.move_plane(index, **{"position": (0, 2, 0), **kwargs})
    assert np.allclose(world.planes[0].position, 0.0) and np.allclose(world.planes[0].normal, (0, 1, 0))


def test_first_overlap_names_the_ball_or_plane_a_new_ball_would_cut_and_none_when_clear():
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), size=2.0)
    world.add_sphere(position=(5, 1, 0), radius=0.5)
    assert world.first_overlap((5.0, 1.9, 0.0), 0.5) == "ball 0"
    assert world.first_overlap((5.0, 2.01, 0.0), 0.5) is None
    assert world.first_overlap((0.9, 0.3, 0.0), 0.5) == "plane 0"
    assert world.first_overlap((1.6, 0.3, 0.0), 0.5) is None  # beyond the square's edge
    with pytest.raises(ValueError, match="radius"):
        world.first_overlap((0, 5, 0), -1.0)
