"""The model (model.py): what a step reads but never changes; its derived values follow the laws and
rules its docstrings state."""

from __future__ import annotations

import pytest

import ballpit
from ballpit.physics.core.settings import CONTACT_SLOP, SLOP_PER_RADIUS
from ballpit.physics.dynamics.forces import AngularDrag, Gravity, LinearDrag


def test_a_solid_ball_has_inertia_two_fifths_m_r_squared_and_a_hollow_one_two_thirds():
    world = ballpit.World()
    world.add_sphere(radius=0.5, mass=2.0)
    world.add_sphere(position=(3, 0, 0), radius=0.5, mass=2.0, hollow=True)
    inv_inertia = world.model.spheres.inv_inertia
    assert 1 / inv_inertia[0] == pytest.approx(0.4 * 2.0 * 0.25) and 1 / inv_inertia[1] == pytest.approx(
        2 / 3 * 0.5
    )
    assert world.model.spheres.inv_mass.tolist() == [0.5, 0.5]


def test_the_restitution_threshold_is_a_few_steps_of_gravity_unless_it_is_set():
    world = ballpit.World(gravity=(0, -10, 0), integrator="rk4")
    assert world.model.restitution_threshold_for(0.01) == pytest.approx(2 * 10 * 0.01)
    world.integrator = "euler"
    assert world.model.restitution_threshold_for(0.01) == pytest.approx(8 * 10 * 0.01)
    world.restitution_threshold = 0.3
    assert world.model.restitution_threshold_for(0.01) == 0.3


def test_touching_is_the_contact_slop_or_less_for_small_balls():
    world = ballpit.World()
    assert world.model.contact_slop() == CONTACT_SLOP
    world.add_sphere(radius=1.0)
    assert world.model.contact_slop() == CONTACT_SLOP
    world.add_sphere(position=(5, 0, 0), radius=1e-4)
    assert world.model.contact_slop() == SLOP_PER_RADIUS * 1e-4


def test_the_force_terms_are_gravity_then_the_drags_switched_on():
    world = ballpit.World()
    assert [type(t) for t in world.model.forces()] == [Gravity]
    world.linear_drag, world.angular_drag = 0.1, 0.2
    assert [type(t) for t in world.model.forces()] == [Gravity, LinearDrag, AngularDrag]


def test_a_plane_moves_when_it_has_a_velocity_or_a_spin():
    world = ballpit.World()
    world.add_plane()
    world.add_plane(position=(0, 5, 0), velocity=(0, 1, 0))
    world.add_plane(position=(0, 9, 0), angular_velocity=(0, 0, 0.5))
    assert world.model.moving_planes() and world.model.moving_plane_mask().tolist() == [False, True, True]
    assert world.model.plane_spin().tolist() == [[0, 0, 0], [0, 0, 0], [0, 0, 0.5]]
