"""The collide stage (step/collide.py): the balls' free motion at a step's start, and the kept pairs
measured, each handed on explicitly."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.step.collide import Collision, Motion, collide

from .stages import prepared

G = np.array([0.0, -9.81, 0.0])


def two_balls() -> ballpit.World:
    world = ballpit.World(sleep=True)
    world.add_plane()
    world.add_spheres([(0, 0.1, 0), (3, 2.0, 0)], radius=0.1)
    return world


def test_with_no_ball_asleep_the_motion_is_gravity_for_every_ball_and_every_ball_is_awake():
    world = two_balls()
    motion = Motion.of(world.model, world.state)
    assert np.array_equal(motion.lin, np.tile(G, (2, 1))) and not motion.ang.any()
    assert motion.unheld is motion.lin and motion.awake is None
    assert len(motion.forces) == len(world.model.forces())


def test_a_sleeping_ball_is_held_still_by_one_more_force_term_but_would_fall_once_woken():
    world = two_balls()
    for _ in range(200):  # the resting ball falls asleep after half a second; the other is still falling
        world.step(1 / 240)
    assert world.asleep.tolist() == [True, False]
    motion = Motion.of(world.model, world.state)
    assert np.array_equal(motion.lin[0], np.zeros(3)) and np.array_equal(motion.lin[1], G)
    assert np.array_equal(motion.unheld, np.tile(G, (2, 1)))  # as each would fall, held or not
    assert motion.awake.tolist() == [False, True]
    assert len(motion.forces) == len(world.model.forces()) + 1


def test_the_pairs_collided_are_those_with_an_awake_ball_in_them():
    world = two_balls()
    for _ in range(200):
        world.step(1 / 240)
    step = prepared(world, 1 / 240)
    collision = collide(step, Motion.of(world.model, world.state))
    pairs = collision.pairs
    assert 0 not in pairs.sphere.tolist()  # the sleeping ball's floor contact is not measured
    assert len(collision.contacts) == len(pairs)


def test_contacts_taken_are_no_longer_held_by_the_collision():
    world = two_balls()
    step = prepared(world, 1 / 240)
    collision = collide(step, Motion.of(world.model, world.state))
    contacts = collision.take()
    assert len(contacts) == len(collision.pairs)
    with pytest.raises(RuntimeError, match="taken"):
        _ = collision.contacts
    with pytest.raises(RuntimeError, match="taken"):
        collision.take()
    assert isinstance(collision, Collision)
