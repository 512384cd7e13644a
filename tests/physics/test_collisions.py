"""Ball–ball impacts against the closed form: head-on, glancing, Newton's cradle, fast balls."""

import numpy as np
import pytest

import ballpit


def zero_g(**kwargs) -> ballpit.World:
    return ballpit.World(gravity=(0, 0, 0), **kwargs)


def run(world: ballpit.World, steps: int, dt: float = 1 / 240) -> list:
    return [world.step(dt) for _ in range(steps)]


@pytest.mark.parametrize(
    ("m1", "m2", "e"), [(1.0, 1.0, 1.0), (1.0, 3.0, 1.0), (2.0, 0.5, 0.6), (1.0, 1.0, 0.0)]
)
def test_head_on_collision_matches_the_closed_form(m1, m2, e):
    world = zero_g()
    u1, u2 = 3.0, -1.0
    a = world.add_sphere(position=(-1, 0, 0), radius=0.2, mass=m1, velocity=(u1, 0, 0), restitution=e)
    b = world.add_sphere(position=(1, 0, 0), radius=0.3, mass=m2, velocity=(u2, 0, 0), restitution=1.0)
    events = [c for c in run(world, 240) if len(c)]
    # v1' = (m1u1 + m2u2 − m2·e·(u1 − u2))/(m1 + m2), v2' = (m1u1 + m2u2 + m1·e·(u1 − u2))/(m1 + m2)
    p = m1 * u1 + m2 * u2
    assert a.velocity == pytest.approx([(p - m2 * e * (u1 - u2)) / (m1 + m2), 0, 0], abs=1e-12)
    assert b.velocity == pytest.approx([(p + m1 * e * (u1 - u2)) / (m1 + m2), 0, 0], abs=1e-12)
    assert len(events) == 1 and events[0].kind_names[0] == "sphere-sphere"
    assert events[0].time[0] == pytest.approx((2 - 0.5) / (u1 - u2))
    assert events[0].impulse[0] == pytest.approx(m1 * m2 / (m1 + m2) * (1 + e) * (u1 - u2))


def test_glancing_elastic_hit_between_equal_masses_leaves_at_ninety_degrees():
    world = zero_g()
    a = world.add_sphere(position=(-2, 0.13, 0.05), radius=0.25, velocity=(4.0, 0, 0), friction=0.0)
    b = world.add_sphere(position=(0, 0, 0), radius=0.25, friction=0.0)
    run(world, 240)
    va, vb = a.velocity, b.velocity
    assert np.linalg.norm(va) > 0.5 and np.linalg.norm(vb) > 0.5
    assert np.dot(va, vb) == pytest.approx(0.0, abs=1e-9)
    assert va + vb == pytest.approx([4.0, 0, 0], abs=1e-12)
    assert np.dot(va, va) + np.dot(vb, vb) == pytest.approx(16.0, rel=1e-12)


def test_newtons_cradle_passes_the_first_balls_velocity_to_the_last():
    world = zero_g()
    r, gap = 0.1, 1e-3
    balls = [world.add_sphere(position=(i * (2 * r + gap), 0, 0), radius=r, friction=0.0) for i in range(5)]
    balls[0].position = (-0.5, 0, 0)
    balls[0].velocity = (2.0, 0, 0)
    run(world, 240)
    for ball in balls[:-1]:
        assert np.linalg.norm(ball.velocity) < 1e-9
    assert balls[-1].velocity == pytest.approx([2.0, 0, 0], abs=1e-9)


def test_newtons_cradle_on_a_frictionless_floor_under_gravity():
    world = ballpit.World()
    world.add_plane(friction=0.0)
    r, gap = 0.1, 1e-3
    balls = [world.add_sphere(position=(i * (2 * r + gap), r, 0), radius=r, friction=0.0) for i in range(5)]
    balls[0].position = (-0.5, r, 0)
    balls[0].velocity = (2.0, 0, 0)
    run(world, 240)
    for ball in balls[:-1]:
        assert np.linalg.norm(ball.velocity) < 1e-6
    assert balls[-1].velocity == pytest.approx([2.0, 0, 0], abs=1e-6)
    assert all(b.position[1] == pytest.approx(r, abs=1e-6) for b in balls)


def test_500_m_per_s_balls_collide_instead_of_passing_through_each_other():
    world = zero_g()
    a = world.add_sphere(position=(-10, 0, 0), radius=0.05, velocity=(500.0, 0, 0))
    b = world.add_sphere(position=(10, 0, 0), radius=0.05, velocity=(-500.0, 0, 0))
    contacts = run(world, 3, 1 / 60)
    assert sum(len(c) for c in contacts) == 1
    assert a.velocity == pytest.approx([-500.0, 0, 0])
    assert b.velocity == pytest.approx([500.0, 0, 0])
    assert a.position[0] < b.position[0]


def test_momentum_is_conserved_exactly_in_ball_ball_contacts():
    rng = np.random.default_rng(7)
    world = zero_g()
    n = 40
    positions = rng.uniform(-1.5, 1.5, (n, 3))
    positions = positions[np.argsort(positions[:, 0])]
    kept = [p for i, p in enumerate(positions) if all(np.linalg.norm(p - q) > 0.3 for q in positions[:i])]
    world.add_spheres(
        np.array(kept),
        radius=0.12,
        mass=rng.uniform(0.5, 3.0, len(kept)),
        velocity=-2.0 * np.array(kept) + rng.normal(0, 0.5, (len(kept), 3)),  # converging on the centre
        restitution=0.7,
    )
    masses = world.spheres.masses[:, None]
    p0 = (masses * world.spheres.velocities).sum(axis=0)
    count = sum(len(c) for c in run(world, 240))
    assert count > 10
    assert (masses * world.spheres.velocities).sum(axis=0) == pytest.approx(p0, abs=1e-10)


@pytest.mark.slow
def test_stepping_the_same_scene_twice_is_bit_identical():
    def simulate() -> np.ndarray:
        rng = np.random.default_rng(3)
        world = ballpit.World()
        world.add_plane()
        world.add_plane(position=(0, 1, 0), rotation=(0, 0, 20), size=2.0)
        grid = np.stack(np.meshgrid(np.arange(4), np.arange(4), np.arange(4)), -1).reshape(-1, 3) * 0.25
        world.add_spheres(grid + rng.normal(0, 0.01, grid.shape) + [-0.4, 2.0, -0.4], radius=0.1)
        run(world, 240)
        return world.state.body.copy()

    assert np.array_equal(simulate(), simulate())
