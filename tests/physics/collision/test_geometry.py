"""Exact distances (geometry.py): a ball against a square's face, edge and corner, against either
side of a plane, and against another ball, as the closed forms give them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballpit.physics.collision import geometry

# one square of side 2 in the xz-plane at the origin, normal +y
FRAME = {
    "center": np.zeros((1, 3)),
    "normal": np.array([[0.0, 1.0, 0.0]]),
    "axis_u": np.array([[1.0, 0.0, 0.0]]),
    "axis_v": np.array([[0.0, 0.0, 1.0]]),
    "half_size": np.array([[1.0, 1.0]]),
}


def against_square(centres, side=1.0, radius=0.5):
    x = np.array(centres, float)
    k = len(x)
    return geometry.sphere_plane(
        x, np.full(k, radius), np.arange(k), np.zeros(k, int), np.full(k, side), **FRAME
    )


def test_a_ball_over_the_face_the_edge_and_the_corner_of_a_square_is_as_far_as_pythagoras_says():
    gap, normal, point = against_square([(0.3, 2.0, -0.2), (2.0, 1.0, 0.0), (2.0, 1.0, 3.0)])
    assert gap == pytest.approx([1.5, math.sqrt(2) - 0.5, math.sqrt(1 + 1 + 4) - 0.5], rel=1e-15)
    assert point.tolist() == [[0.3, 0.0, -0.2], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]]
    assert normal[0].tolist() == [0.0, 1.0, 0.0]
    assert normal[1] == pytest.approx([math.sqrt(0.5), math.sqrt(0.5), 0.0], rel=1e-15)  # off the edge
    assert normal[2] == pytest.approx(np.array([1.0, 1.0, 2.0]) / math.sqrt(6), rel=1e-15)  # off the corner


def test_a_plane_is_two_sided_and_a_ball_that_crossed_it_is_pushed_back_the_way_it_came():
    below, _, _ = against_square([(0.0, -2.0, 0.0)], side=-1.0)
    gap, normal, _ = against_square([(0.0, -0.1, 0.0)], side=1.0)  # started above, now 0.1 below
    assert below.tolist() == [1.5]
    assert gap.tolist() == pytest.approx([-0.6]) and normal[0].tolist() == [0.0, 1.0, 0.0]


def test_two_balls_are_measured_from_j_towards_i_with_the_point_in_the_middle_of_the_gap():
    x = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    gap, normal, point = geometry.sphere_sphere(
        x, np.array([1.0, 2.0, 0.5]), np.array([0, 1]), np.array([1, 2])
    )
    assert (
        gap[0] == 2.0
        and normal[0] == pytest.approx([0.6, 0.8, 0.0])
        and point[0] == pytest.approx([1.8, 2.4, 0])
    )
    # coincident centres have no normal: +y, so the pair separates vertically
    assert gap[1] == -2.5 and normal[1].tolist() == [0.0, 1.0, 0.0]


def test_the_closest_point_on_an_unbounded_plane_is_the_foot_of_the_perpendicular():
    frame = {**FRAME, "half_size": np.array([[math.inf, math.inf]])}
    del frame["normal"]
    points = np.array([[1e6, 5.0, -3e5]])
    near = geometry.closest_point_on_planes(points, np.zeros(1, int), **frame)
    assert near.tolist() == [[1e6, 0.0, -3e5]]
