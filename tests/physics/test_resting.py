"""Many balls: a settling pile, and an elastic gas that keeps its energy."""

import numpy as np
import pytest

import ballpit


def box(world: ballpit.World, half: float, height: float | None = None, **material) -> None:
    """A floor and four walls facing inwards (and a lid when ``height`` is given)."""
    world.add_plane(normal=(0, 1, 0), **material)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -half), normal=normal, **material)
    if height is not None:
        world.add_plane(position=(0, height, 0), normal=(0, -1, 0), **material)


@pytest.mark.slow
def test_a_few_hundred_balls_settle_into_a_still_pile():
    rng = np.random.default_rng(11)
    world = ballpit.World()
    # Ideal spheres without rolling resistance roll apart for ever, so the pile's balls have some.
    box(world, 0.3, restitution=0.3, friction=0.5, rolling_friction=0.05)
    r = 0.05
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(8), np.arange(5), indexing="ij"), -1).reshape(-1, 3)
    positions = grid * 0.11 + [-0.22, 0.3, -0.22] + rng.uniform(-0.004, 0.004, grid.shape)
    world.add_spheres(positions, radius=r, restitution=0.5, rolling_friction=0.05)
    for _ in range(240 * 5):
        world.step(1 / 240)
    speeds = np.linalg.norm(world.spheres.velocities, axis=1)
    assert speeds.max() < 1e-3
    x = world.spheres.positions
    d = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(len(x)) * 1e9
    assert (2 * r - d).max() < 0.02 * r  # overlaps under 2 % of a radius
    assert x[:, 1].min() > r - 0.02 * r  # nothing sinks into the floor
    assert np.abs(x[:, [0, 2]]).max() < 0.3 - r + 0.02 * r  # nor out through the walls
    heights_before = x[:, 1].copy()
    for _ in range(240):
        world.step(1 / 240)
    assert np.abs(world.spheres.positions[:, 1] - heights_before).max() < 1e-4  # still, not creeping


@pytest.mark.slow
def test_elastic_gas_in_a_closed_box_keeps_its_energy_for_a_minute():
    rng = np.random.default_rng(5)
    world = ballpit.World(gravity=(0, 0, 0))
    half = 1.0
    box(world, half, restitution=1.0, friction=0.0)
    world.add_plane(position=(0, 2 * half, 0), normal=(0, -1, 0), restitution=1.0, friction=0.0)
    grid = np.stack(np.meshgrid(np.arange(4), np.arange(4), np.arange(4), indexing="ij"), -1).reshape(-1, 3)
    positions = grid * 0.45 + [-0.675, 0.325, -0.675]
    world.add_spheres(positions, radius=0.1, velocity=rng.normal(0, 1.5, (len(grid), 3)), friction=0.0)
    energy = world.kinetic_energy()
    hits = 0
    for _ in range(60 * 60):
        hits += len(world.step(1 / 60))
    assert hits > 1000
    assert world.kinetic_energy() == pytest.approx(energy, rel=0.01)
    x = world.spheres.positions
    assert np.abs(x[:, [0, 2]]).max() <= half - 0.1 + 1e-6
