"""The plan stage (step/plan.py): the crowd test returns how the step is taken, split at impacts or a
soft frame of the world's substeps."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.step import Plan, Strategy, plan
from ballpit.physics.step.collide import Motion, collide
from ballpit.physics.step.plan import SPLIT

from .stages import pile_on_a_floor, prepared


def planned(world: ballpit.World, dt: float = 1 / 60) -> Plan:
    step = prepared(world, dt)
    motion = Motion.of(world.model, world.state)
    return plan(step, collide(step, motion), motion)


def test_a_ball_in_free_flight_is_split_at_impacts():
    world = ballpit.World()
    world.add_plane()
    world.add_sphere(position=(0, 5, 0), radius=0.1)
    assert planned(world) == SPLIT and SPLIT.strategy is Strategy.SPLIT


def test_a_resting_heap_of_hundreds_of_touching_pairs_is_a_soft_frame_of_the_worlds_substeps():
    world = pile_on_a_floor(substeps=4)
    chosen = planned(world)
    assert chosen == Plan.soft(4) and chosen.strategy is Strategy.SOFT and chosen.substeps == 4


def test_a_deep_overlap_is_a_soft_frame_unless_the_crowd_limit_is_infinite():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_spheres([(0, 0, 0), (0.19, 0, 0)], radius=0.1)  # 5 % of a radius deep
    assert planned(world) == Plan.soft(1)
    world.crowd_limit = math.inf
    assert planned(world) == SPLIT


def test_more_meetings_than_the_crowd_limit_make_a_soft_frame():
    # three pairs of balls 1 cm apart closing at 2 m/s meet within a 1/60 s step
    world = ballpit.World(gravity=(0, 0, 0))
    lanes = np.array([(0, 0, 0), (0, 0, 1), (0, 0, 2)], float)
    world.add_spheres(lanes, radius=0.1, velocity=(1, 0, 0))
    world.add_spheres(lanes + (0.21, 0, 0), radius=0.1, velocity=(-1, 0, 0))
    world.crowd_limit = 3
    assert planned(world) == SPLIT
    world.crowd_limit = 2
    assert planned(world) == Plan.soft(1)


def test_touching_is_the_worlds_own_slop_for_the_crowd_test_too():
    # 100 µm balls 5 µm apart: apart for every stage, since a pair touches within a thousandth of the
    # smallest radius (0.1 µm) when that is under CONTACT_SLOP (10 µm); at rest, nothing meets
    world = pile_on_a_floor(side=8, r=1e-4, gravity=(0, 0, 0))
    world.spheres.positions[:] *= 1.05  # every gap 5 % of a radius, 5 µm
    world.spheres.positions[:, 1] += 1.0  # off the floor
    assert world.model.contact_slop() == pytest.approx(1e-7)
    assert planned(world) == SPLIT
    world.spheres.positions[:] /= 1.05  # touching again (gap 0): the heap is a soft frame
    world.spheres.positions[:, 1] -= 1.0 / 1.05
    assert planned(world) == Plan.soft(1)
