"""Camera maths: look direction, projection of known points, view matrix, flying and mouse look."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballpit.viewer.camera import PITCH_LIMIT, Camera


def test_looking_at_points_the_camera_at_the_target():
    cam = Camera.looking_at((0, 4, 12), (0, 2, 0))
    expected = np.array([0, -2, -12]) / np.linalg.norm([0, -2, -12])
    assert np.allclose(cam.forward, expected)
    side = Camera.looking_at((0, 0, 0), (5, 0, 0))
    assert np.allclose(side.forward, [1, 0, 0])
    assert np.allclose(side.right, [0, 0, 1])


def test_the_look_at_target_projects_to_the_image_centre():
    cam = Camera.looking_at((3, 4, 12), (-1, 2, 0))
    pixels, depth = cam.project(np.array([-1.0, 2.0, 0.0]), 800, 450)
    assert np.allclose(pixels, [400, 225], atol=1e-6)
    assert depth == pytest.approx(np.linalg.norm([4, 2, 12]))


def test_a_point_on_the_edge_of_the_vertical_field_of_view_projects_to_the_top_row():
    cam = Camera(position=np.zeros(3), fov_y_degrees=50.0)  # looking along −z
    d = 10.0
    top = np.array([0.0, d * math.tan(math.radians(25.0)), -d])
    right = np.array([d * math.tan(math.radians(25.0)) * 2.0, 0.0, -d])  # aspect 2 → right edge
    pixels, _ = cam.project(np.stack([top, right]), 400, 200)
    assert np.allclose(pixels[0], [200, 0], atol=1e-6)
    assert np.allclose(pixels[1], [400, 100], atol=1e-6)


def test_points_right_of_and_above_the_view_axis_land_right_and_up_in_the_image():
    cam = Camera.looking_at((0, 0, 10), (0, 0, 0))
    pixels, _ = cam.project(np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), 640, 480)
    assert pixels[0, 0] > 320 and pixels[0, 1] == pytest.approx(240)
    assert pixels[1, 1] < 240 and pixels[1, 0] == pytest.approx(320)


def test_behind_the_camera_has_negative_depth():
    cam = Camera.looking_at((0, 0, 10), (0, 0, 0))
    _, depth = cam.project(np.array([0.0, 0.0, 20.0]), 100, 100)
    assert depth == pytest.approx(-10.0)


def test_view_matrix_takes_the_eye_to_the_origin_and_the_target_down_minus_z():
    cam = Camera.looking_at((2, 3, 4), (2, 3, -6))
    view = cam.view_matrix().astype(float)
    assert np.allclose(np.array([2, 3, 4, 1.0]) @ view, [0, 0, 0, 1], atol=1e-5)
    assert np.allclose(np.array([2, 3, -6, 1.0]) @ view, [0, 0, -10, 1], atol=1e-5)


def test_flying_forward_follows_the_look_direction_at_the_fly_speed():
    cam = Camera.looking_at((0, 4, 12), (0, 2, 0), speed=4.0)
    start = cam.position.copy()
    cam.fly(np.array([0.0, 0.0, 1.0]), dt=0.5)
    assert np.allclose(cam.position - start, cam.forward * 2.0)


def test_flying_sideways_and_up_use_the_camera_right_and_world_up():
    cam = Camera.looking_at((0, 0, 0), (0, -5, -5), speed=2.0)  # pitched down 45°
    cam.fly(np.array([1.0, 0.0, 0.0]), dt=1.0)
    assert np.allclose(cam.position, [2, 0, 0])
    cam.fly(np.array([0.0, 1.0, 0.0]), dt=1.0, multiplier=4.0)
    assert np.allclose(cam.position, [2, 8, 0])


def test_mouse_look_turns_right_and_up_and_clamps_the_pitch():
    cam = Camera(position=np.zeros(3))
    cam.look(dx=100, dy=0)
    assert cam.forward[0] > 0  # turned right, towards +x
    cam.look(dx=0, dy=50)
    assert cam.forward[1] > 0  # looking up
    cam.look(dx=0, dy=1e6)
    assert cam.pitch == pytest.approx(PITCH_LIMIT)
