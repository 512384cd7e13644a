"""Kept pairs (pairs.py): every pair that can meet within a step is handed out, the pairs are kept
while every ball's path stays in the box it was paired from, and found afresh when it does not."""

from __future__ import annotations

import itertools

import numpy as np

import ballpit
from ballpit.physics.dynamics.forces import free_acceleration

DT = 1 / 240


def for_step(world: ballpit.World, awake=None):
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    return world.parts.pairs.for_step(model, state, accel, DT, awake)


def gas(n: int = 60, seed: int = 4) -> ballpit.World:
    rng = np.random.default_rng(seed)
    world = ballpit.World(gravity=(0, -9.81, 0))
    world.add_plane()
    world.add_spheres(
        rng.uniform((-3, 0.5, -3), (3, 2, 3), (n, 3)), radius=0.25, velocity=rng.normal(0, 2, (n, 3))
    )
    return world


def test_every_pair_closer_than_its_reach_over_the_step_is_among_the_kept_pairs():
    world = gas()
    world.add_sphere(position=(5, 0.26, 5), radius=0.25, velocity=(0, -5, 0))  # reaches the floor
    pairs = for_step(world)
    x, v = world.state.body[:, 0:3], world.state.body[:, 3:6]
    kept = set(zip(pairs.pair_i.tolist(), pairs.pair_j.tolist(), strict=True))
    meeting = 0
    for i, j in itertools.combinations(range(len(x)), 2):
        # the closest the two centres can come over the step, moving straight (gravity moves both alike)
        reach = np.linalg.norm(x[i] - x[j]) - np.linalg.norm(v[i] - v[j]) * DT
        if reach <= 0.5:
            assert (i, j) in kept
            meeting += 1
    assert meeting > 0
    near_floor = np.flatnonzero(x[:, 1] - np.abs(v[:, 1]) * DT - 0.5 * 9.81 * DT**2 <= 0.25)
    assert near_floor.size and set(near_floor.tolist()) <= set(pairs.sphere.tolist())


def test_pairs_are_kept_from_step_to_step_until_a_ball_leaves_its_box():
    world = ballpit.World()
    world.add_plane()
    world.add_spheres(
        [(0, 5, 0), (0.6, 5, 0), (3, 5, 0)], radius=0.25, velocity=(1, 0, 0)
    )  # a pair, no contact
    first = for_step(world)
    world.step(DT)
    assert for_step(world) is first  # paths still inside their boxes
    world.spheres[0].velocity = (500.0, 0.0, 0.0)  # now it leaves its box within the step
    assert for_step(world) is not first


def test_a_ball_added_finds_the_pairs_afresh():
    world = gas()
    first = for_step(world)
    world.add_sphere(position=(10, 0.3, 0), radius=0.25)
    again = for_step(world)
    assert again is not first and again.counts == (61, 1) and 60 in again.sphere.tolist()


def test_only_pairs_with_an_awake_ball_are_handed_out_and_the_kept_ones_stay_whole():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane()
    world.add_spheres([(0, 0.5, 0), (1.0, 0.5, 0), (2.0, 0.5, 0)], radius=0.5)
    awake = np.array([False, False, True])
    pairs = for_step(world, awake)
    assert list(zip(pairs.pair_i.tolist(), pairs.pair_j.tolist(), strict=True)) == [(1, 2)]
    assert pairs.sphere.tolist() == [2]
    assert len(world.parts.pairs.kept) == 2 + 3  # two touching pairs, three balls on the floor
