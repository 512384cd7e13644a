"""Many balls: a settling pile, an elastic gas that keeps its energy, and a chain held by the walls."""

import itertools

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
def test_elastic_gas_in_a_closed_box_keeps_its_energy_through_thousands_of_collisions():
    """64 elastic, frictionless balls in a closed box without gravity: 15 s and more than 3,000
    collisions later the kinetic energy is the same to 1e-9 (a resting solve that did work on
    separating or sliding contacts would drain or feed it far beyond that)."""
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
    for _ in range(15 * 60):
        hits += len(world.step(1 / 60))
    assert hits > 3000
    assert world.kinetic_energy() == pytest.approx(energy, rel=1e-9)
    x = world.spheres.positions
    assert np.abs(x[:, [0, 2]]).max() <= half - 0.1 + 1e-6


def chain_in_a_corner(integrator: str, masses: list[float], radii: list[float]) -> ballpit.World:
    """Balls stacked from a corner of a 0.6 m closed box along the line of a sideways gravity
    (5, −7, 4), the lightest in the corner, each 1 % of the sum of radii apart; split at impacts."""
    world = ballpit.World(gravity=(5.0, -7.0, 4.0), integrator=integrator)
    box(world, 0.3, height=0.6, restitution=0.0, friction=0.5)
    world.crowd_limit = np.inf
    up = -np.array(world.gravity) / np.linalg.norm(world.gravity)
    x = [np.array([0.3 - radii[0], radii[0], 0.3 - radii[0]])]
    for below, r in itertools.pairwise(radii):
        x.append(x[-1] + up * (below + r) * 1.01)
    world.add_spheres(x, radius=radii, mass=masses, restitution=0.0)
    return world


def sink_in_radii(world: ballpit.World) -> np.ndarray:
    """How far each ball reaches beyond the box's walls, floor and lid, in radii (0: it does not)."""
    x, r = world.spheres.positions, world.spheres.radii
    beyond = np.maximum(np.abs(x[:, [0, 2]]) + r[:, None] - 0.3, 0.0).max(axis=1)
    return np.maximum(beyond, np.maximum(r - x[:, 1], x[:, 1] + r - 0.6)) / r


@pytest.mark.slow  # eight chains, the slowest tests make check ran (66 s of its 268 s under load 7)
@pytest.mark.parametrize("integrator", ["euler", "rk2", "rk4", "symplectic"])
@pytest.mark.parametrize(
    ("masses", "radii"),
    [
        ([0.016, 0.11, 0.75], [0.0098, 0.0092, 0.0085]),
        ([0.01, 0.1, 1.0, 10.0], [0.0098, 0.0092, 0.0085, 0.008]),
    ],
)
def test_a_heavy_medium_light_chain_in_a_corner_is_held_by_the_walls(integrator, masses, radii):
    """A light, a medium and a heavy ball (16 g, 110 g, 750 g; or four balls, ten times heavier each)
    stacked into a corner along gravity, 1/60 s steps split at impacts. The hold of planes reached one
    layer: it held the light ball and stopped the medium one pressing it, but the heavy ball kept
    pressing the medium one, and the light ball sank 0.19 of its radius into the walls (0.37 under
    explicit Euler, 0.8 with four balls). Held layer by layer, no ball reaches into a wall by more than
    5 % of its radius, and once settled (the second half of 3 s) the chain stands still: no ball moves
    by a micrometre (but under explicit Euler, whose chain rocks by up to 1 cm with or without the hold:
    not solved here)."""
    world = chain_in_a_corner(integrator, masses, radii)
    late = []
    for k in range(180):
        world.step(1 / 60)
        assert (sink_in_radii(world) < 0.05).all()
        if k >= 90:
            late.append(world.spheres.positions.copy())
    late = np.array(late)
    if integrator != "euler":  # explicit Euler's chain keeps rocking by millimetres, as it did before
        assert (late.max(axis=0) - late.min(axis=0)).max() < 1e-6


def _closed_elastic_cube(integrator: str, **balls) -> ballpit.World:
    """Six elastic frictionless walls |x|, |y|, |z| ≤ 1 round the ``balls``, gravity −9.81 along y."""
    world = ballpit.World(integrator=integrator)
    for face in (*np.eye(3), *-np.eye(3)):
        world.add_plane(position=face, normal=-face, restitution=1.0, friction=0.0)
    world.add_spheres(restitution=1.0, friction=0.0, **balls)
    return world


@pytest.mark.parametrize("integrator", ["rk2", "rk4", "symplectic"])
@pytest.mark.parametrize(
    "balls",
    [
        # lifting off the floor at 1 cm/s, slower than gravity takes away in a step (g·dt = 16 cm/s)
        dict(positions=[(0.0, -0.9, 0.0)], radius=0.1, velocity=[(0.0, 0.01, 0.0)]),
        # ten balls created at one point (found by the long fuzz search)
        dict(positions=np.zeros((10, 3)), radius=[0.0625] * 8 + [0.0078125, 0.0625]),
        # a 0.5 mm ball inside the shell of a 25 cm one that touches three walls (long fuzz search)
        dict(
            positions=[(-0.75, -0.75, -0.75), (-0.75, -0.5949668382248494, -0.5949668382248494)],
            radius=[0.25, 0.0005],
            mass=[1.0, 0.01],
        ),
    ],
    ids=["lifting-off", "coincident", "shell"],
)
def test_resting_forces_do_no_work_on_a_separating_contact(integrator, balls):
    """In a closed elastic frictionless box under gravity the total energy may only stay or fall.

    A touching contact separating slowly at an interval's start, which gravity closes within it, must
    not be brought to rest by the resting solve: a constant force that ends it at v_n = 0 lifts it by
    h·v_n0/2 on the way and does positive work."""
    world = _closed_elastic_cube(integrator, **balls)
    start = world.kinetic_energy() + world.potential_energy()
    highest = start
    for _ in range(60):
        world.step(1 / 60)
        highest = max(highest, world.kinetic_energy() + world.potential_energy())
    assert highest - start <= 1e-12 * abs(start) + 1e-12
