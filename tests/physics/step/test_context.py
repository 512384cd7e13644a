"""A step's context (step/context.py): the stages share the world's own parts, and an interval moves
the balls and the planes together and is counted."""

from __future__ import annotations

import pytest

import ballpit
from ballpit.physics.step.context import integrate_interval

from .stages import prepared


def test_the_steps_parts_are_the_worlds_own_not_copies():
    world = ballpit.World()
    step = prepared(world, 1 / 60)
    assert (
        step.state is world.parts.state and step.pairs is world.parts.pairs and step.warm is world.parts.warm
    )


def test_an_interval_moves_balls_and_planes_by_h_and_is_counted():
    world = ballpit.World(gravity=(0, -10, 0))
    world.add_plane(position=(0, -5, 0), velocity=(0, 2, 0))
    world.add_sphere(position=(0, 1, 0), velocity=(3, 0, 0))
    step = prepared(world, 1 / 60)
    integrate_interval(step, world.model.forces(), None, 0.1)
    assert world.spheres[0].position == pytest.approx([0.3, 1 - 0.5 * 10 * 0.01, 0], rel=1e-12)  # RK4: exact
    assert world.planes[0].position == pytest.approx([0, -5 + 0.2, 0], rel=1e-12)
    assert step.intervals == 1 and step.profile.seconds["integrate"] > 0.0
