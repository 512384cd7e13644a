"""Touching balls struck together (impacts in waves) against the closed forms: Newton's cradle with no
gaps, the Galilean cannon, a ball struck from two sides at once, a touching line on a floor, and what
happens at the bound on the number of waves."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.collision import narrowphase
from ballpit.physics.contact import impacts, rows
from ballpit.physics.core.contacts import EventLog
from ballpit.physics.core.settings import MAX_WAVES
from ballpit.physics.dynamics.forces import free_acceleration

G = 9.81
R = 0.1  # m, the cradle's balls
STEPS = [1 / 240, 1 / 60]


def momentum(world: ballpit.World) -> np.ndarray:
    return (world.spheres.masses[:, None] * world.spheres.velocities).sum(axis=0)


def touching_cradle(world: ballpit.World, strikers: int, speed: float, y: float = 0.0) -> list:
    """A row of five touching balls at x = 0 … 0.8, and ``strikers`` touching balls moving at
    ``speed`` towards it, the first of them 0.05 m away; the balls are numbered left to right."""
    first = -2 * R - 0.05
    hit = [
        world.add_sphere(position=(first - 2 * R * k, y, 0), radius=R, velocity=(speed, 0, 0), friction=0.0)
        for k in reversed(range(strikers))
    ]
    row = [world.add_sphere(position=(2 * R * i, y, 0), radius=R, friction=0.0) for i in range(5)]
    return hit + row  # left to right, in the order added


@pytest.mark.parametrize("dt", STEPS)
@pytest.mark.parametrize("strikers", [1, 2])
def test_a_touching_cradle_struck_by_n_balls_sends_off_the_last_n_at_the_strikers_speed(strikers, dt):
    world = ballpit.World(gravity=(0, 0, 0), integrator="rk4")
    u = 1.0
    balls = touching_cradle(world, strikers, u)
    energy, p = world.kinetic_energy(), momentum(world)
    for _ in range(round(0.3 / dt)):
        world.step(dt)
    speeds = world.spheres.velocities[:, 0]
    assert speeds[-strikers:] == pytest.approx([u] * strikers, rel=0.02), speeds
    assert np.abs(world.spheres.velocities[:-strikers]).max() < 0.02 * u, speeds
    assert world.kinetic_energy() == pytest.approx(energy, rel=1e-3)
    assert momentum(world) == pytest.approx(p, abs=1e-12)
    assert len(balls) == 5 + strikers


def cannon_apex(big: float, small: float, drop: float, big_r: float, small_r: float) -> float:
    """The small ball's highest centre: it leaves the top of the big one (centre 2·R + r up) when
    the big ball, landing at v = √(2·g·h) and bounced back (e = 1), meets it still falling at v:
    u = (3M − m)/(M + m)·v, and rises u²/(2g) from there."""
    v = math.sqrt(2 * G * drop)
    u = (3 * big - small) / (big + small) * v
    return 2 * big_r + small_r + u * u / (2 * G)


@pytest.mark.parametrize("dt", STEPS)
def test_the_galilean_cannon_throws_the_small_ball_to_the_closed_form_height(dt):
    # 1 kg resting on 10 kg, dropped 1 m onto the floor, everything elastic: 7.65 m, not the 2.1 m
    # the two reached when solved together.
    M, m, big_r, small_r, h = 10.0, 1.0, 0.3, 0.1, 1.0
    world = ballpit.World(integrator="rk4")
    world.add_plane(restitution=1.0, friction=0.0)
    world.add_sphere(position=(0, big_r + h, 0), radius=big_r, mass=M, friction=0.0)
    top = world.add_sphere(position=(0, 2 * big_r + small_r + h, 0), radius=small_r, mass=m, friction=0.0)
    highest = 0.0
    for _ in range(round(2.5 / dt)):
        world.step(dt)
        highest = max(highest, float(top.position[1]))
    assert highest == pytest.approx(cannon_apex(M, m, h, big_r, small_r), rel=0.02)
    assert highest > 7.0


@pytest.mark.parametrize(
    ("left", "right", "expected"), [(1.0, -1.0, (-1.0, 0.0, 1.0)), (2.0, -1.0, (-4 / 3, 2 / 3, 5 / 3))]
)
def test_a_ball_struck_from_both_sides_at_once_takes_both_impacts_together(left, right, expected):
    # Both contacts arrive in the same wave and are solved together: each leaves at its approach
    # speed (e = 1), with momentum kept: equal balls at 2 and −1 m/s on a ball at rest leave at
    # −4/3, 2/3 and 5/3 m/s.
    world = ballpit.World(gravity=(0, 0, 0))
    a = world.add_sphere(position=(-2 * R, 0, 0), radius=R, velocity=(left, 0, 0), friction=0.0)
    b = world.add_sphere(position=(0, 0, 0), radius=R, friction=0.0)
    c = world.add_sphere(position=(2 * R, 0, 0), radius=R, velocity=(right, 0, 0), friction=0.0)
    energy = world.kinetic_energy()
    world.step(1 / 240)
    got = [a.velocity[0], b.velocity[0], c.velocity[0]]
    assert got == pytest.approx(list(expected), abs=1e-9)
    assert world.kinetic_energy() == pytest.approx(energy, rel=1e-9)


@pytest.mark.parametrize("dt", STEPS)
def test_a_touching_line_resting_on_a_floor_under_gravity_keeps_momentum_and_energy(dt):
    # Five balls resting on a frictionless floor (resting contacts that must take no part in the
    # impact), struck along the line: the striker stops, the last ball leaves at its speed, and the
    # horizontal momentum and the total energy are kept.
    world = ballpit.World(integrator="rk4")
    world.add_plane(restitution=0.5, friction=0.0)
    balls = touching_cradle(world, 1, 1.5, y=R)
    for _ in range(10):  # let the resting contacts settle in first
        world.step(dt)
    px, energy = momentum(world)[0], world.kinetic_energy() + world.potential_energy()
    for _ in range(round(0.3 / dt)):
        world.step(dt)
    v = world.spheres.velocities
    assert v[-1, 0] == pytest.approx(1.5, rel=0.02)
    assert np.abs(v[:-1]).max() < 0.02 * 1.5
    assert momentum(world)[0] == pytest.approx(px, rel=1e-9)
    assert world.kinetic_energy() + world.potential_energy() == pytest.approx(energy, rel=1e-3)
    assert all(b.position[1] == pytest.approx(R, abs=1e-6) for b in balls)


def test_a_line_longer_than_the_wave_bound_stops_the_rest_inelastically():
    # One wave per ball: after MAX_WAVES the ball holding the impulse is stopped against the rest
    # (e = 0), which keeps momentum and loses energy, never gains it.
    n = MAX_WAVES + 8
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_spheres([(2 * R * i, 0, 0) for i in range(n)], radius=R, friction=0.0)
    world.spheres[0].velocity = (1.0, 0, 0)
    energy, p = world.kinetic_energy(), momentum(world)
    world.step(1 / 240)
    v = world.spheres.velocities[:, 0]
    assert np.abs(v[:MAX_WAVES]).max() < 1e-12, "the waves passed the impulse that far"
    assert v[MAX_WAVES] < 0.5, "then it was shared out inelastically"
    assert world.kinetic_energy() < energy
    assert momentum(world) == pytest.approx(p, abs=1e-12)


def test_random_touching_clusters_struck_at_random_never_gain_energy():
    rng = np.random.default_rng(5)
    for _ in range(20):
        world = ballpit.World(gravity=(0, 0, 0))
        centres = [np.zeros(3)]
        while len(centres) < 12:  # each ball touching one already placed
            d = rng.normal(size=3)
            centres.append(centres[rng.integers(len(centres))] + 2 * R * d / np.linalg.norm(d))
        x = np.array(centres)
        far = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(len(x)) >= 2 * R - 1e-9
        if not far.all():
            continue
        world.add_spheres(x, radius=R, velocity=rng.normal(0, 1.0, x.shape), friction=rng.uniform(0, 0.5),
                          restitution=rng.uniform(0.5, 1.0))  # fmt: skip
        energy, p = world.kinetic_energy(), momentum(world)
        world.step(1 / 240)
        assert world.kinetic_energy() <= energy * (1 + 1e-12)
        assert momentum(world) == pytest.approx(p, abs=1e-9)


@pytest.mark.parametrize("gap", [0.0, 1e-3])
def test_waves_with_the_crowded_steps_min_normal_speeds_and_jacobi_solves_pass_the_cradle_impulse(gap):
    # How a crowded step calls the rule: every contact within reach, speculative ones allowed to close
    # by gap/dt, and every solve by Jacobi sweeps (jacobi_from=0). The line still passes the impulse on.
    dt = 1 / 240
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_spheres([((2 * R + gap) * i, 0, 0) for i in range(6)], radius=R, friction=0.0)
    world.spheres[0].velocity = (2 * gap / dt + 1.0, 0, 0)  # arrives within the step
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    pairs = world.parts.pairs.for_step(model, state, accel, dt, None)
    c = narrowphase.contact_points(model, state, pairs)
    min_normal_speed = np.where(c.gap < 1e-5, 0.0, -c.gap / dt)
    batch = rows.contact_rows(model, state, c)
    p = momentum(world)
    waves = impacts.in_waves(model, state, c, batch, 0.0, min_normal_speed, EventLog(), 0.0, jacobi_from=0)
    v = world.spheres.velocities[:, 0]
    assert waves == 5
    assert v[-1] == pytest.approx(2 * gap / dt + 1.0, rel=1e-12)
    assert np.abs(v[:-1]).max() < 1e-12
    assert momentum(world) == pytest.approx(p, abs=1e-12)


def crowded_floor(world: ballpit.World) -> None:
    """A frictionless floor under a 16 × 16 layer of balls resting on it apart (256 resting contacts,
    so every step with a meeting is a crowded one: softstep.py), beside the cradle."""
    world.add_plane(restitution=0.5, friction=0.0)
    g = np.stack(np.meshgrid(np.arange(16), np.arange(16), indexing="ij"), -1).reshape(-1, 2) * 0.25
    world.add_spheres(
        np.column_stack((g[:, 0] - 2, np.full(len(g), R), g[:, 1] + 1.0)), radius=R, friction=0.0
    )


@pytest.mark.parametrize(("dt", "substeps"), [(1 / 240, 1), (1 / 60, 4)])
@pytest.mark.parametrize("strikers", [1, 2])
def test_a_touching_cradle_in_a_crowded_scene_passes_the_impulse_on_and_keeps_momentum_and_energy(
    strikers, dt, substeps
):
    # The touching cradle on a floor under gravity, beside resting balls, every step a soft-step frame
    # (Box2D v3's soft step, with its restitution pass following impacts in waves, #24): the last
    # ``strikers`` balls leave at the strikers' speed, the others are left below 2 % of it, and the
    # line's horizontal momentum and energy are kept.
    world = ballpit.World(integrator="rk4", substeps=substeps)
    crowded_floor(world)
    first = len(world.spheres)
    u = 1.0
    touching_cradle(world, strikers, u, y=R)
    line = slice(first, None)
    for _ in range(3):  # the resting contacts settle in; the strikers are still 0.05 − 3·dt·u away
        world.step(dt)
    m = world.spheres.masses[line]
    px = float((m * world.spheres.velocities[line, 0]).sum())

    def energy() -> tuple[float, float]:  # the line's kinetic and potential energy
        v, y = world.spheres.velocities[line], world.spheres.positions[line, 1]
        return float((0.5 * m * (v * v).sum(axis=1)).sum()), float((m * G * y).sum())

    kinetic, potential = energy()
    crowded = world.crowded_steps
    steps = round(0.3 / dt)
    for _ in range(steps):
        world.step(dt)
    assert world.crowded_steps - crowded == steps, "every step was a soft-step frame"
    v = world.spheres.velocities[line]
    assert v[-strikers:, 0] == pytest.approx([u] * strikers, rel=0.02), v[:, 0]
    assert np.abs(v[:-strikers]).max() < 0.02 * u, v[:, 0]
    assert float((m * v[:, 0]).sum()) == pytest.approx(px, rel=1e-9)
    assert kinetic == pytest.approx(0.5 * strikers * u * u, rel=1e-3)
    assert energy()[0] == pytest.approx(kinetic, rel=1e-3)
    # the line rests on the soft floor: it settles by a few µm (measured: at most 0.10 % of the kinetic
    # energy lost, 1/240 s struck by one), and never rises
    assert potential - 2e-3 * kinetic < energy()[1] <= potential + 1e-12


@pytest.mark.parametrize(("dt", "substeps"), [(1 / 240, 1), (1 / 60, 4)])
def test_the_galilean_cannon_in_a_crowded_scene_throws_the_small_ball_at_the_closed_form_speed(dt, substeps):
    # The cannon of test_the_galilean_cannon_... dropped beside the resting layer, so its landing is a
    # soft-step frame. The frame bounces from the approach speed its contacts had when it began (Box2D's
    # restitution), so the small ball leaves at (3M − m)/(M + m) times the speed both had one step
    # before the landing, not the (faster) speed of the touch: at 1/60 s that is 4.25 m/s, not 4.43.
    M, m, big_r, small_r, h = 10.0, 1.0, 0.3, 0.1, 1.0
    world = ballpit.World(integrator="rk4", substeps=substeps)
    crowded_floor(world)
    world.planes[0].restitution = 1.0
    world.add_sphere(position=(0, big_r + h, -1.0), radius=big_r, mass=M, friction=0.0)
    top = world.add_sphere(position=(0, 2 * big_r + small_r + h, -1.0), radius=small_r, mass=m, friction=0.0)
    while top.velocity[1] <= 0.0:
        falling = float(top.velocity[1])
        before = world.crowded_steps
        world.step(dt)
    assert world.crowded_steps == before + 1, "the landing was a soft-step frame"
    assert float(top.velocity[1]) == pytest.approx((3 * M - m) / (M + m) * -falling, rel=0.02)


def cube(world: ballpit.World, restitution: float = 1.0, friction: float = 0.0) -> None:
    """Six infinite walls facing in: |x|, |y|, |z| ≤ 1."""
    for face in (*np.eye(3), *-np.eye(3)):
        world.add_plane(position=face, normal=-face, restitution=restitution, friction=friction)


# Three 1 mm balls pressed into the corner (−1, −1, −1) of the cube by gravity (−9.81, −9.81, −9.81),
# as a search found them: positions, then velocities.
CORNER_THREES = [
    (
        [
            [-0.999, -0.9953809, -0.99890502],
            [-0.999, -0.99510616, -0.99793818],
            [-0.99896115, -0.999, -0.999],
        ],
        [
            [-1.49285701, -0.07219059, -1.77790539],
            [0.91877888, 0.93414442, -0.76218333],
            [-0.36896465, -2.2109122, -0.26794576],
        ],
    ),
    (
        [[-0.999, -0.999, -0.99863195], [-0.999, -0.99527325, -0.999], [-0.99819836, -0.999, -0.99644872]],
        [
            [-0.75541953, 1.05321526, -0.33504815],
            [-0.66757282, 0.13828256, -1.41552595],
            [-1.13932772, 0.51032543, -0.30315349],
        ],
    ),
    ([[-0.999, -0.999, -0.999], [-0.997, -0.999, -0.999], [-0.999, -0.997, -0.999]], [[0.0] * 3] * 3),
]


@pytest.mark.parametrize("start", range(len(CORNER_THREES)))
def test_balls_pressed_into_a_corner_stay_in_the_box_under_explicit_euler_at_large_steps(start):
    """Three 1 mm balls in a corner of a closed elastic frictionless cube, gravity into the corner,
    explicit Euler at 0.1 s a step. The stop of the slow approaches (e = 0) left a ball pressed by the
    others still closing on a wall at a few cm/s (Gauss–Seidel hands the momentum down the column a
    little at a time), and explicit Euler moves a ball by its velocity at the interval's start, which no
    resting force changes: a ball went 1 mm beyond a wall at step 3 (23 mm at step 2 in another start)
    and fell on out of the box. Planes win at the interval's start too: no centre leaves the cube, and
    no ball sinks into a wall by a tenth of its radius."""
    positions, velocities = CORNER_THREES[start]
    world = ballpit.World(gravity=(-G, -G, -G), integrator="euler")
    cube(world)
    r = 0.001
    world.add_spheres(positions, radius=r, velocity=velocities, restitution=1.0, friction=0.0)
    for _ in range(40):
        world.step(0.1)
        reach = np.abs(world.spheres.positions).max(axis=1)
        assert (reach < 1.0).all()
        assert (reach - (1.0 - r) < 0.1 * r).all()
