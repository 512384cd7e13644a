"""Crowded steps: many impacts in one step are taken whole, with speculative contacts.

A speculative contact lets a pair close by at most the gap it has, and a pair arriving faster than the
restitution threshold leaves at e times the speed it had when the step began. The bounce then happens
early by at most the gap that was left, so results are checked against the analytic answer with
that bound, never against numbers the code printed.
"""

import math

import numpy as np
import pytest

import ballpit

G = 9.81


def grid(side: int, spacing: float, height: float) -> np.ndarray:
    """side × side ball centres in a horizontal square, ``spacing`` apart, at ``height``."""
    ix, iz = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    xz = (np.stack((ix.ravel(), iz.ravel()), axis=1) - 0.5 * (side - 1)) * spacing
    return np.column_stack((xz[:, 0], np.full(len(xz), height), xz[:, 1]))


def first_apexes(world: ballpit.World, dt: float, duration: float) -> np.ndarray:
    """Each ball's lowest point at its first apex after a bounce (y − r + v²/2g, exact in flight)."""
    spheres = world.spheres
    previous, apex = spheres.velocities[:, 1].copy(), np.full(len(spheres), np.nan)
    for _ in range(round(duration / dt)):
        world.step(dt)
        vy = spheres.velocities[:, 1]
        rising = (previous < 0) & (vy > 0) & np.isnan(apex)
        apex[rising] = spheres.positions[rising, 1] - spheres.radii[rising] + vy[rising] ** 2 / (2 * G)
        previous = vy.copy()
    return apex


@pytest.mark.parametrize("rate", [60, 240])
def test_a_crowd_landing_in_one_step_bounces_to_e_squared_h_within_one_steps_travel(rate):
    # 100 balls 1 m above the floor land in the same step. The soft step stops them at the floor and
    # sends them back at e times the speed they had when the step began, a gap g above the floor:
    # the apex is e²·(h − g), and g is less than one step's travel v·dt.
    dt, e, h, r = 1 / rate, 0.6, 1.0, 0.1
    world = ballpit.World()
    world.add_plane(restitution=e, friction=0.0)
    world.add_spheres(grid(10, 0.5, h + r), radius=r, restitution=1.0, friction=0.0)
    v_land = math.sqrt(2 * G * h)
    apex = first_apexes(world, dt, 1.2)
    assert world.crowded_steps >= 1
    assert not np.isnan(apex).any()
    assert apex.min() >= e**2 * (h - v_land * dt) - 1e-9
    assert apex.max() <= e**2 * h + 1e-9


def test_independent_head_on_impacts_in_a_crowded_step_match_the_closed_form():
    # 60 pairs of balls 1 cm apart meet head on in the same step; each pair is the textbook collision.
    world = ballpit.World(gravity=(0, 0, 0))
    m1, m2, e, u1, u2 = 2.0, 0.5, 0.6, 3.0, -1.0
    lanes = grid(8, 1.0, 0.0)[:60]
    left = world.add_spheres(lanes - [0.205, 0, 0], radius=0.2, mass=m1, velocity=(u1, 0, 0), restitution=e)
    right = world.add_spheres(
        lanes + [0.105, 0, 0], radius=0.1, mass=m2, velocity=(u2, 0, 0), restitution=1.0
    )
    contacts = world.step(1 / 60)
    assert world.crowded_steps == 1
    assert len(contacts) == 60
    p = m1 * u1 + m2 * u2
    v = world.spheres.velocities
    assert v[left] == pytest.approx(np.tile([(p - m2 * e * (u1 - u2)) / (m1 + m2), 0, 0], (60, 1)), abs=1e-12)
    assert v[right] == pytest.approx(
        np.tile([(p + m1 * e * (u1 - u2)) / (m1 + m2), 0, 0], (60, 1)), abs=1e-12
    )
    assert contacts.impulse == pytest.approx(np.full(60, m1 * m2 / (m1 + m2) * (1 + e) * (u1 - u2)))


def test_momentum_is_conserved_exactly_when_a_crowd_collides():
    rng = np.random.default_rng(2)
    world = ballpit.World(gravity=(0, 0, 0))
    world.crowd_limit = 0  # every step in which any pair meets is taken whole
    positions = grid(7, 0.3, 0.0)
    positions = np.vstack([positions + [0, y, 0] for y in np.arange(7) * 0.3]) + rng.normal(0, 0.01, (343, 3))
    world.add_spheres(
        positions,
        radius=0.12,
        mass=rng.uniform(0.5, 3.0, len(positions)),
        velocity=-2.0 * (positions - positions.mean(axis=0)) + rng.normal(0, 0.5, positions.shape),
        restitution=0.7,
    )
    masses = world.spheres.masses[:, None]
    p0 = (masses * world.spheres.velocities).sum(axis=0)
    hits = sum(len(world.step(1 / 240)) for _ in range(120))
    assert world.crowded_steps > 10
    assert hits > 100
    assert (masses * world.spheres.velocities).sum(axis=0) == pytest.approx(p0, abs=1e-10)


def test_fast_balls_in_a_crowd_are_split_at_their_impacts_and_stop_at_a_thin_plane():
    # 300 m/s is 50 radii a substep: more than the soft step can hold, so the step is split at impacts.
    world = ballpit.World()
    world.add_plane(size=10.0, restitution=0.5)
    world.add_spheres(grid(8, 0.5, 0.5), radius=0.1, velocity=(0, -300.0, 0))
    world.step(1 / 60)
    assert world.crowded_steps == 0
    y = world.spheres.positions[:, 1]
    assert y.min() >= 0.1 - 1e-6
    assert (world.spheres.velocities[:, 1] > 0).all()  # all bounced up, none passed through


@pytest.mark.slow
def test_a_crowded_pile_landing_never_gains_energy_and_nothing_sinks():
    # A block of 343 balls falls into a box; with restitution below one and friction, the total
    # energy can only fall, and the balls stay above the floor and apart from each other.
    rng = np.random.default_rng(4)
    world = ballpit.World()
    world.add_plane(normal=(0, 1, 0), restitution=0.5, friction=0.5, rolling_friction=0.02)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -0.45), normal=normal, restitution=0.5)
    r = 0.05
    layers = [grid(7, 0.11, 0.1 + 0.11 * k) for k in range(7)]
    world.add_spheres(np.vstack(layers) + rng.uniform(-0.003, 0.003, (343, 3)), radius=r, restitution=0.5)
    energy = world.kinetic_energy() + world.potential_energy()
    worst_overlap = 0.0
    for _ in range(240):
        world.step(1 / 240)
        assert world.kinetic_energy() + world.potential_energy() <= energy + 1e-9
        x = world.spheres.positions
        d = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(len(x)) * 1e9
        worst_overlap = max(worst_overlap, (2 * r - d).max())
        assert x[:, 1].min() > r - 0.1 * r
    assert world.crowded_steps > 20
    assert worst_overlap < 0.1 * r


@pytest.mark.parametrize(
    ("value", "error"), [(-1, ValueError), (float("nan"), ValueError), ("many", TypeError)]
)
def test_crowd_limit_rejects_bad_values_naming_it(value, error):
    world = ballpit.World()
    with pytest.raises(error, match="crowd_limit"):
        world.crowd_limit = value
    world.crowd_limit = float("inf")  # always split steps at impacts: allowed


def test_with_no_crowd_limit_a_crowd_landing_is_split_at_its_impacts_and_bounces_exactly():
    # The same 100 balls as above, with crowded steps switched off: every apex is e²·h.
    dt, e, h, r = 1 / 60, 0.6, 1.0, 0.1
    world = ballpit.World()
    world.crowd_limit = float("inf")
    world.add_plane(restitution=e, friction=0.0)
    world.add_spheres(grid(10, 0.5, h + r), radius=r, restitution=1.0, friction=0.0)
    apex = first_apexes(world, dt, 1.2)
    assert world.crowded_steps == 0
    assert apex == pytest.approx(np.full(100, e**2 * h), abs=1e-5)
