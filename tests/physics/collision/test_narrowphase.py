"""The narrow phase (narrowphase.py): every kept pair measured at the current positions, plane
contacts first, each with the analytic gap, the unit normal towards ball a and the contact point."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.collision import narrowphase
from ballpit.physics.core.contacts import SPHERE_PLANE, SPHERE_SPHERE
from ballpit.physics.dynamics.forces import free_acceleration


def measured(world: ballpit.World):
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    pairs = world.parts.pairs.for_step(model, state, accel, 1 / 240, None)
    return narrowphase.contact_points(model, state, pairs)


def test_a_ball_over_a_tilted_plane_and_a_ball_beside_it_are_measured_as_geometry_says():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0), rotation=(0, 0, 30))  # normal (−sin 30°, cos 30°, 0)
    world.add_sphere(position=(0, 0.6, 0), radius=0.5)
    world.add_sphere(position=(1.1, 0.6, 0), radius=0.5)
    c = measured(world)
    normal = np.array([-0.5, math.sqrt(3) / 2, 0.0])
    assert c.kind[: int((c.kind == SPHERE_PLANE).sum())].tolist() == [SPHERE_PLANE] * 2  # planes first
    first = (c.kind == SPHERE_PLANE) & (c.a == 0)
    assert c.gap[first][0] == pytest.approx(0.6 * normal[1] - 0.5, rel=1e-14)
    assert c.normal[first][0] == pytest.approx(normal, abs=1e-15)
    assert c.b[first][0] == 2  # the static row N: a plane moves as a ball that never does
    assert c.point[first][0] == pytest.approx([0, 0.6, 0] - 0.6 * normal[1] * normal, abs=1e-15)
    pair = c.kind == SPHERE_SPHERE
    assert c.gap[pair].tolist() == pytest.approx([0.1], rel=1e-12)
    # towards a (the lower index), pointing from b to a
    assert (c.a[pair][0], c.b[pair][0]) == (0, 1) and c.normal[pair][0] == pytest.approx([-1, 0, 0])


def test_a_ball_that_sank_into_a_plane_has_a_negative_gap_of_its_depth():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane()
    world.add_sphere(position=(3, 0.2, -1), radius=0.5)
    c = measured(world)
    assert c.gap.tolist() == pytest.approx([-0.3], rel=1e-14) and c.normal[0].tolist() == [0.0, 1.0, 0.0]
