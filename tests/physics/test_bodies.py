"""The live views (bodies.py): a Sphere or Plane is the world and an index, never a copy, so reading
and writing it reads and writes the world's arrays; a plane answers distance queries for its face,
edges and corners."""

import numpy as np
import pytest

import ballpit


def test_views_read_and_write_the_world_arrays():
    world = ballpit.World()
    ball = world.add_sphere(position=(1, 2, 3), radius=0.25, mass=2.0)
    ball.velocity = (4.0, 0.0, 0.0)
    assert world.spheres.velocities[0] == pytest.approx([4.0, 0.0, 0.0])
    world.spheres.positions[0] = (7.0, 8.0, 9.0)
    assert ball.position == pytest.approx([7.0, 8.0, 9.0])
    assert (ball.radius, ball.mass, ball.index) == (0.25, 2.0, 0)
    assert ball.orientation == pytest.approx([0, 0, 0, 1])


def test_plane_queries_cover_face_edge_and_corner():
    world = ballpit.World()
    square = world.add_plane(position=(0, 1, 0), size=2.0)
    assert square.signed_distance([0.5, 3.0, 0.5]) == pytest.approx(2.0)
    assert square.signed_distance([0.5, -1.0, 0.5]) == pytest.approx(-2.0)
    assert square.closest_point([0.5, 3.0, -0.5]) == pytest.approx([0.5, 1.0, -0.5])  # face
    assert square.closest_point([3.0, 2.0, 0.2]) == pytest.approx([1.0, 1.0, 0.2])  # edge
    assert square.closest_point([3.0, 2.0, -4.0]) == pytest.approx([1.0, 1.0, -1.0])  # corner
    assert square.distance([4.0, 5.0, 1.0]) == pytest.approx(5.0)  # from the corner (1, 1, 1)
    many = square.closest_point(np.array([[0, 5, 0], [9, 1, 9]]))
    assert many == pytest.approx(np.array([[0, 1, 0], [1, 1, 1]]))


def test_a_view_of_a_ball_removed_says_so_instead_of_reading_another():
    world = ballpit.World()
    world.add_spheres([(0, 0, 0), (2, 0, 0)])
    last = world.spheres[1]
    world.remove_sphere(0)
    with pytest.raises(IndexError):
        _ = last.position
