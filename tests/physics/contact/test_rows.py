"""Contact rows (rows.py): the masses and mixed materials a solve reads, and colours that never hold
one ball twice."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.collision import narrowphase
from ballpit.physics.contact import rows
from ballpit.physics.dynamics.forces import free_acceleration


def built(world: ballpit.World) -> tuple:
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    c = narrowphase.contact_points(
        model, state, world.parts.pairs.for_step(model, state, accel, 1 / 240, None)
    )
    return c, rows.contact_rows(model, state, c)


def test_materials_mix_as_the_readme_says_and_rolling_acts_through_the_rolling_radius():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(restitution=0.5, friction=0.8, rolling_friction=0.2)
    world.add_sphere(position=(0, 0.4, 0), radius=0.4, restitution=0.9, friction=0.2, rolling_friction=0.05)
    world.add_sphere(
        position=(1.0, 0.6, 0), radius=0.6, mass=3.0, restitution=0.4, friction=0.5, rolling_friction=0.1
    )
    _, r = built(world)
    on_plane = r.b == 2
    plane_row, pair_row = np.flatnonzero(on_plane & (r.a == 0))[0], np.flatnonzero(~on_plane)[0]
    assert r.restitution[plane_row] == pytest.approx(0.9 * 0.5) and r.friction[plane_row] == pytest.approx(
        0.4
    )
    assert r.rolling[plane_row] == pytest.approx(math.sqrt(0.05 * 0.2) * 0.4)  # ρ·r on a plane
    assert r.restitution[pair_row] == pytest.approx(0.36) and r.friction[pair_row] == pytest.approx(
        math.sqrt(0.1)
    )
    reduced = 2 * 0.4 * 0.6 / (0.4 + 0.6)
    assert r.rolling[pair_row] == pytest.approx(math.sqrt(0.005) * reduced)
    assert r.inv_mass_b[plane_row] == 0.0 and r.inv_inertia_b[plane_row] == 0.0
    assert r.inv_mass_b[pair_row] == pytest.approx(1 / 3) and r.inv_inertia_b[pair_row] == pytest.approx(
        1 / (0.4 * 3 * 0.36)
    )


def test_a_sleeping_ball_holds_like_a_plane_for_an_awake_one_leaning_on_it():
    world = ballpit.World(gravity=(0, 0, 0), sleep=True)
    world.add_spheres([(0, 0, 0), (1.0, 0, 0)], radius=0.5)
    world.state.sleep.fit(2)
    world.state.sleep.asleep[1] = True
    _, r = built(world)
    assert r.inv_mass_b.tolist() == [0.0] and r.inv_inertia_b.tolist() == [0.0] and r.inv_mass_a[0] == 1.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_colours_hold_every_contact_once_and_no_ball_twice_but_the_static_row(seed):
    rng = np.random.default_rng(seed)
    balls = 40
    a = rng.integers(0, balls, 300)
    b = np.where(rng.random(300) < 0.3, balls, rng.integers(0, balls, 300))
    keep = a != b
    a, b = a[keep], b[keep]
    colours = rows.colour(a, b, balls)
    assert sorted(np.concatenate(colours).tolist()) == list(range(len(a)))
    for group in colours:
        ends = np.concatenate((a[group], b[group][b[group] != balls]))
        assert len(np.unique(ends)) == len(ends)
    assert rows.colour(a, b, balls)[0].tolist() == colours[0].tolist()  # deterministic


def test_normal_speeds_read_a_moving_plane_under_the_contact():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(velocity=(0, 2.0, 0))  # rising at 2 m/s
    world.add_sphere(position=(0, 0.5, 0), radius=0.5, velocity=(0, -1.0, 0))
    _, r = built(world)
    v = np.vstack([world.state.body[:, 3:6], np.zeros((1, 3))])
    assert r.moving and r.normal_speeds(v).tolist() == pytest.approx([-3.0])  # closing at 3 m/s


def test_every_pair_of_colours_is_disjoint():
    a, b = np.array([0, 1, 2, 0, 3]), np.array([1, 2, 3, 4, 4])
    colours = rows.colour(a, b, 5)
    for x, y in itertools.combinations(colours, 2):
        assert not set(x.tolist()) & set(y.tolist())


def test_rows_that_let_go_of_their_radii_keep_each_contacts_lever_arms_in_subsets_and_copies():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane()
    radii = (0.2, 0.3, 0.5)
    world.add_spheres([(0, 0.2, 0), (0.5, 0.3, 0), (1.3, 0.5, 0)], radius=list(radii))
    _, r = built(world)
    r.forget_radii()
    assert r.radius_a is None and r.radius_b is None
    pairs = r.b != 3  # ball against ball: both arms are the balls' radii; on the plane, b's arm is 0
    sub = r.subset(pairs)
    copy = dataclasses.replace(sub, friction=np.zeros(len(sub)))
    expected_a = [radii[a] for a in sub.a]
    expected_b = [radii[b] for b in sub.b]
    for rows_ in (sub, copy):
        arm_a, arm_b = rows_.arm_lengths()
        assert arm_a == pytest.approx(expected_a, rel=1e-15) and arm_b == pytest.approx(expected_b, rel=1e-15)
    plane = r.subset(~pairs)
    assert plane.arm_lengths()[1].tolist() == [0.0] * 3
    assert plane.arm_lengths()[0] == pytest.approx([radii[a] for a in plane.a], rel=1e-15)
