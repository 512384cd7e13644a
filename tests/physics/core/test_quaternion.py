"""Unit quaternions, scalar last (quaternion.py), against scipy's rotations: the same Hamilton product,
rotations, extrinsic Euler angles and shortest turns."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ballpit.physics.core import quaternion


def random_turns(k: int, seed: int = 5) -> np.ndarray:
    return Rotation.random(k, random_state=seed).as_quat()  # scalar last, as ours


def test_the_product_applies_the_right_factor_first_as_scipys_composition_does():
    p, q = random_turns(6), random_turns(6, seed=6)
    expected = (Rotation.from_quat(p) * Rotation.from_quat(q)).as_matrix()
    assert Rotation.from_quat(quaternion.multiply(p, q)).as_matrix() == pytest.approx(expected, abs=1e-14)


def test_rotating_a_vector_matches_the_rotation_matrix():
    q, v = random_turns(8), np.random.default_rng(2).normal(size=(8, 3))
    assert quaternion.rotate(q, v) == pytest.approx(Rotation.from_quat(q).apply(v), abs=1e-14)


def test_extrinsic_euler_angles_turn_about_world_x_then_y_then_z():
    degrees = np.array([30.0, -45.0, 100.0])
    expected = Rotation.from_euler("xyz", degrees, degrees=True).as_matrix()
    assert Rotation.from_quat(quaternion.from_euler_xyz(degrees)).as_matrix() == pytest.approx(
        expected, abs=1e-14
    )


@pytest.mark.parametrize("normal", [(1.0, 0.0, 0.0), (0.0, 0.6, 0.8), (0.0, -1.0, 0.0), (0.0, 1.0, 0.0)])
def test_the_shortest_turn_from_up_lands_on_the_normal(normal):
    q = quaternion.from_up_to(np.array(normal))
    assert quaternion.rotate(q, np.array([0.0, 1.0, 0.0])) == pytest.approx(normal, abs=1e-15)
    if normal[1] > -1.0:  # the shortest: about an axis perpendicular to both
        assert q[:3] @ np.array(normal) == pytest.approx(0.0, abs=1e-15)


def test_turning_at_omega_for_a_small_step_turns_by_omega_h_about_omega():
    q = np.array([[0.0, 0.0, 0.0, 1.0]])
    w = np.array([[0.0], [0.0], [2.0]])  # (3, M): 2 rad/s about z
    quaternion.turn(q, w, 1e-4)
    assert np.linalg.norm(q) == pytest.approx(1.0, rel=1e-15)
    assert Rotation.from_quat(q[0]).as_rotvec() == pytest.approx([0, 0, 2e-4], rel=1e-8)
