"""Mechanical energy (energy.py): ½·m·v² + ½·I·ω² and −m·g·x, summed over the balls."""

from __future__ import annotations

import pytest

import ballpit


def test_kinetic_energy_counts_translation_and_spin_and_potential_is_zero_at_the_origin():
    world = ballpit.World(gravity=(0, -10, 0))
    world.add_sphere(
        position=(0, 2, 0), radius=0.5, mass=2.0, velocity=(3, 0, 4), angular_velocity=(0, 0, 10)
    )
    world.add_sphere(position=(5, -1, 0), radius=1.0, mass=1.0, hollow=True, angular_velocity=(2, 0, 0))
    spin_a = 0.5 * (0.4 * 2.0 * 0.25) * 100  # ½·I·ω², I = 2/5·m·r²
    spin_b = 0.5 * (2 / 3) * 4  # I = 2/3·m·r²
    assert world.kinetic_energy() == pytest.approx(0.5 * 2.0 * 25 + spin_a + spin_b, rel=1e-15)
    assert world.potential_energy() == pytest.approx(2.0 * 10 * 2 + 1.0 * 10 * -1, rel=1e-15)


def test_a_falling_ball_trades_potential_for_kinetic_energy():
    world = ballpit.World(gravity=(0, -9.81, 0))
    world.add_sphere(position=(0, 10, 0))
    total = world.kinetic_energy() + world.potential_energy()
    for _ in range(60):
        world.step(1 / 60)
    assert world.kinetic_energy() > 40 and world.kinetic_energy() + world.potential_energy() == pytest.approx(
        total, rel=1e-12
    )
