"""Picking without GL: rays through window points, and which ball or plane they hit first."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.viewer.camera import Camera
from ballpit.viewer.picking import (
    INFINITE_PICK_DISTANCE,
    Ray,
    pick,
    pointer_ray,
    ray_plane_point,
    ray_planes,
    ray_spheres,
)


def _ray(origin, direction) -> Ray:
    d = np.asarray(direction, dtype=float)
    return Ray(np.asarray(origin, dtype=float), d / np.linalg.norm(d))


@pytest.mark.parametrize("size", [(1280, 720), (320, 180), (500, 800)])
def test_the_ray_through_a_points_projected_pixel_passes_through_the_point(size):
    camera = Camera.looking_at((3.0, 4.0, 9.0), (-1.0, 1.0, 0.5))
    rng = np.random.default_rng(4)
    points = camera.position + rng.uniform(-1, 1, (20, 3)) * 3 + camera.forward * 8
    pixels, _ = camera.project(points, *size)
    for point, (px, py_from_top) in zip(points, pixels, strict=True):
        ray = pointer_ray(camera, px, size[1] - py_from_top, *size)  # pyglet's y runs up
        along = (point - ray.origin) @ ray.direction
        assert np.linalg.norm(ray.origin + along * ray.direction - point) < 1e-5  # project() is float32
        assert np.linalg.norm(ray.direction) == pytest.approx(1.0)


def test_the_centre_of_the_window_is_the_view_direction():
    camera = Camera.looking_at((0.0, 2.0, 5.0), (1.0, 0.0, -3.0))
    ray = pointer_ray(camera, 160, 90, 320, 180)
    assert np.allclose(ray.direction, camera.forward, atol=1e-12)


def test_a_ray_enters_the_nearest_ball_at_its_surface():
    centers = np.array([[0.0, 0.0, -10.0], [0.0, 0.0, -5.0], [3.0, 0.0, -2.0]])
    radii = np.array([1.0, 0.5, 0.5])
    index, t = ray_spheres(_ray((0, 0, 0), (0, 0, -1)), centers, radii)
    assert (index, t) == (1, pytest.approx(4.5))
    # grazing a ball off axis: distance from the chord
    index, t = ray_spheres(_ray((0, 0.3, 0), (0, 0, -1)), centers, radii)
    assert index == 1 and t == pytest.approx(5.0 - math.sqrt(0.25 - 0.09))
    assert ray_spheres(_ray((0, 0, 0), (0, 0, 1)), centers, radii) == (-1, math.inf)  # behind
    assert ray_spheres(_ray((0, 5, 0), (0, 0, -1)), centers, radii) == (-1, math.inf)  # above
    assert ray_spheres(_ray((0, 0, -5.2), (0, 0, -1)), centers, radii) == (1, 0.0)  # inside one
    assert ray_spheres(_ray((0, 0, 0), (0, 0, -1)), np.zeros((0, 3)), np.zeros(0)) == (-1, math.inf)


def test_a_ray_hits_a_finite_plane_inside_its_rectangle_from_either_side():
    args = dict(
        centers=np.array([[0.0, 0.0, 0.0], [0.0, -1.0, 0.0]]),
        normals=np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]]),
        axis_u=np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
        axis_v=np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]),
        half_sizes=np.array([[1.0, 2.0], [np.inf, np.inf]]),
    )
    assert ray_planes(_ray((0.5, 3, 1.5), (0, -1, 0)), **args) == (0, pytest.approx(3.0))
    assert ray_planes(_ray((1.5, 3, 0), (0, -1, 0)), **args) == (1, pytest.approx(4.0))  # past its edge
    assert ray_planes(_ray((0.5, -0.5, 1.5), (0, 1, 0)), **args) == (0, pytest.approx(0.5))  # from below
    assert ray_planes(_ray((0, 3, 0), (1, 0, 0)), **args) == (-1, math.inf)  # parallel
    assert ray_planes(_ray((0, 3, 0), (0, 1, 0)), **args) == (-1, math.inf)  # away


def test_pick_finds_the_nearest_of_balls_and_planes_in_a_world():
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_plane(position=(0, 2, 0), rotation=(0, 0, 30), size=2.0)
    world.add_sphere(position=(3, 1, 0), radius=0.5)
    down = (0, -1, 0)
    hit = pick(_ray((3, 5, 0), down), world)
    assert (hit.kind, hit.index) == ("sphere", 0) and np.allclose(hit.point, [3, 1.5, 0])
    hit = pick(_ray((0, 5, 0), down), world)
    assert (hit.kind, hit.index) == ("plane", 1) and hit.distance == pytest.approx(3.0)
    hit = pick(_ray((-5, 5, 0), down), world)
    assert (hit.kind, hit.index) == ("plane", 0) and hit.distance == pytest.approx(5.0)
    assert pick(_ray((0, 5, 0), (0, 1, 0)), world) is None


def test_the_drag_plane_meets_the_ray_where_the_line_crosses_it():
    point = ray_plane_point(_ray((0, 0, 0), (1, 1, 0)), np.array([2.0, 0.0, 0.0]), np.array([1.0, 0, 0]))
    assert np.allclose(point, [2, 2, 0])
    assert ray_plane_point(_ray((0, 0, 0), (0, 1, 0)), np.array([2.0, 0, 0]), np.array([1.0, 0, 0])) is None


def test_the_ground_is_picked_only_where_the_fog_still_shows_it():
    """A click just above where the ground fades into the sky hits it hundreds of metres away: that
    selects nothing. Nearer than INFINITE_PICK_DISTANCE it is picked; a finite plane at any distance."""
    from ballpit.viewer.renderer import FOG_DENSITY  # the fog's constant (the module imports OpenGL)

    assert math.exp(-((FOG_DENSITY * INFINITE_PICK_DISTANCE) ** 2)) == pytest.approx(0.1, abs=0.01)
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    eye = np.array([0.0, 4.0, 0.0])

    def towards(distance: float) -> Ray:  # a ray meeting the ground ``distance`` m away along it
        down = 4.0 / distance
        return _ray(eye, (0.0, -down, -math.sqrt(1.0 - down * down)))

    assert pick(towards(300.0), world) is None  # just above the visible horizon: the faded ground
    near = pick(towards(40.0), world)
    assert near is not None and near.kind == "plane" and near.distance == pytest.approx(40.0)
    far_slope = ballpit.World()
    far_slope.add_plane(position=(0, 0, -300.0), size=40.0)
    hit = pick(towards(300.0), far_slope)
    assert hit is not None and hit.index == 0
