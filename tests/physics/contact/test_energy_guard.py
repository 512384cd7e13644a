"""The energy guards (energy_guard.py): each keeps one kind of contact stage from adding mechanical
energy. Each is shown against a case where, switched off, the energy rises, and, on, it does not."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.cli.peers.landing import RADIUS, pile_layout
from ballpit.physics.collision import narrowphase
from ballpit.physics.contact import energy_guard, impacts, rows
from ballpit.physics.core.contacts import EventLog
from ballpit.physics.core.settings import SLOP, EnergyGuards
from ballpit.physics.core.workspace import Workspace
from ballpit.physics.dynamics.forces import ConstantPerBall, free_acceleration
from ballpit.physics.dynamics.integrators import integrate
from tests.test_fuzz_box import COINCIDENT_MIXED_MASSES

G = 9.81


def energy(world: ballpit.World) -> float:
    return world.kinetic_energy() + world.potential_energy()


def momentum(world: ballpit.World) -> np.ndarray:
    return (world.spheres.masses[:, None] * world.spheres.velocities).sum(axis=0)


def struck_cluster(guards: EnergyGuards) -> tuple[ballpit.World, float, np.ndarray]:
    """A dozen balls nearly on top of each other (seed 171 of a search over random clusters), rough
    (μ 0.15) and nearly elastic (e 0.99), bounced in waves as the split step does; returns the world,
    its kinetic energy and its momentum before the bounce."""
    rng = np.random.default_rng(171)
    world = ballpit.World(gravity=(0, 0, 0))
    x, v = rng.normal(size=(12, 3)) * 0.15, rng.normal(size=(12, 3))
    world.add_spheres(x, radius=0.1, velocity=v, friction=rng.uniform(0, 1), restitution=rng.uniform(0.3, 1))
    world.model.guards = guards
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    pairs = world.parts.pairs.for_step(model, state, accel, 1 / 240, None)
    c = narrowphase.contact_points(model, state, pairs)
    touching = c.subset(c.gap < 1e-5)
    kinetic, p = world.kinetic_energy(), momentum(world)
    batch = rows.contact_rows(model, state, touching)
    impacts.in_waves(model, state, touching, batch, 0.0, np.zeros(len(touching)), EventLog(), 0.0)
    return world, kinetic, p


def test_the_impulse_guard_keeps_a_wave_of_rough_impacts_from_adding_kinetic_energy():
    # Newton's law with Coulomb friction, solved colour by colour to 50 sweeps, is not exactly the
    # frictionless LCP that never adds energy: here the waves add 38 mJ without the guard.
    off, kinetic, p = struck_cluster(EnergyGuards(impulses=False))
    assert off.kinetic_energy() > kinetic + 0.01
    on, kinetic, p = struck_cluster(EnergyGuards())
    assert on.kinetic_energy() <= kinetic
    assert momentum(on) == pytest.approx(p, abs=1e-12)  # the impulses were scaled, not dropped


def sunk_sliding_ball(guards: EnergyGuards) -> ballpit.World:
    """A ball sunk 5 mm into a frictionless floor, sliding at 1 m/s; steps split at impacts."""
    world = ballpit.World()
    world.crowd_limit = math.inf
    world.add_plane(friction=0.0)
    world.add_sphere(position=(0, 0.1 - 0.005, 0), radius=0.1, velocity=(1, 0, 0), friction=0.0)
    world.model.guards = guards
    return world


def test_the_lift_guard_pays_for_lifting_a_ball_out_of_the_floor_with_its_speed():
    # Moving the ball out lifts it 5 mm: m·g·5 mm = 49 mJ, paid out of its ½·m·v² = 0.5 J.
    for guards, gain in ((EnergyGuards(lift=False), 1.0 * G * 0.005), (EnergyGuards(), 0.0)):
        world = sunk_sliding_ball(guards)
        before = energy(world)
        world.step(1 / 240)
        assert world.spheres[0].position[1] == pytest.approx(0.1, abs=1e-12)  # moved out either way
        assert energy(world) - before == pytest.approx(gain, abs=1e-12)
    assert world.spheres[0].velocity[0] == pytest.approx(math.sqrt(1.0 - 2 * G * 0.005), rel=1e-12)


def sunk_row(guards: EnergyGuards) -> ballpit.World:
    """Five balls in a row on a floor, each sunk 20 % of a radius into the next: soft frames push them
    apart sideways."""
    world = ballpit.World(substeps=4)
    world.add_plane(friction=0.5)
    world.add_spheres([(0.16 * k, 0.1, 0) for k in range(5)], radius=0.1)
    world.model.guards = guards
    return world


def test_the_frame_guard_keeps_soft_frames_pushing_a_sunk_row_apart_from_gaining_energy():
    off, on = sunk_row(EnergyGuards(frame=False)), sunk_row(EnergyGuards())
    start = energy(on)
    for _ in range(3):
        off.step(1 / 60)
        on.step(1 / 60)
        assert on.crowded_steps == off.crowded_steps  # soft frames, both
        assert energy(on) <= start + 1e-12
    assert on.crowded_steps == 3
    assert energy(off) > start + 0.1  # the springs' push, half a joule and more, kept without the guard


def landed_grid(balls: int) -> ballpit.World:
    """The bench's landing grid (``pile_layout``) in its box, RK4, 1/60 s frames of 4 soft substeps,
    restitution and friction 0.25."""
    centres, half = pile_layout(balls)
    world = ballpit.World(integrator="rk4", substeps=4)
    world.add_plane(normal=(0, 1, 0), restitution=0.25, friction=0.25)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -half), normal=normal, restitution=0.25, friction=0.25)
    world.add_spheres(centres, radius=RADIUS, restitution=0.25, friction=0.25)
    return world


def test_a_landed_crowds_velocities_tell_how_its_balls_move():
    # 600 balls landed in a box, 1.9 to 2.0 s: every ball's displacement, less its velocity integrated
    # over the frames (the trapezoid rule, frame by frame), is within the slop of its radius, frame by
    # frame and over the 0.1 s. The frame guard once set every ball's velocity to the centre of mass's
    # while the pushes apart by positions moved them on: the balls reported one velocity while they
    # crept on (here 0.014 of a radius in the 0.1 s, 0.010 in one frame).
    world, dt = landed_grid(600), 1 / 60
    for _ in range(114):
        world.step(dt)
    start, told, worst = world.spheres.positions.copy(), np.zeros((600, 3)), 0.0
    for _ in range(6):
        x0, v0 = world.spheres.positions.copy(), world.spheres.velocities.copy()
        world.step(dt)
        frame = 0.5 * dt * (v0 + world.spheres.velocities)
        worst = max(worst, float(np.linalg.norm(world.spheres.positions - x0 - frame, axis=1).max()))
        told += frame
    over = float(np.linalg.norm(world.spheres.positions - start - told, axis=1).max())
    assert max(over, worst) <= SLOP * RADIUS, (over / RADIUS, worst / RADIUS)


def test_the_push_guard_keeps_a_resting_solve_at_a_hundred_to_one_from_doing_work():
    # The long fuzz's seed 301: 33 balls of 10 g to 1 kg at rest at one point of an elastic
    # frictionless box, RK2 at 1/60 s. In step 7, split at impacts, the resting solve (not converged at
    # a hundred to one) left pushing contacts separating, and its constant forces did 3 J of work in
    # one interval. With the guard they are scaled down until they do none.
    def run(guards: EnergyGuards) -> float:
        world = COINCIDENT_MIXED_MASSES.world()
        world.model.guards = guards
        start, most = energy(world), -math.inf
        for _ in range(8):
            world.step(COINCIDENT_MIXED_MASSES.dt)
            most = max(most, energy(world) - start)
        return most

    assert run(EnergyGuards(push=False)) > 1.0
    assert run(EnergyGuards()) <= 1e-9 * 348.0


def test_the_push_guard_takes_back_a_lift_the_pushed_balls_speed_cannot_pay():
    # A ball sliding at u = g·h/2 is pushed up at 2g for h by a constant contact force, integrated by
    # RK2 (exact under constant forces): it rises ½·g·h² and ends at (u, g·h). The push did
    # m·2g·½·g·h² = m·g²·h² of work, more than the ½·m·(u² + g²·h²) of speed it could be paid out of
    # (a light ball squeezed out of a corner's wedge, fuzz seed 410). The guard takes the interval
    # back by the one fraction λ that keeps the energy, λ²·K₁ + λ·ΔU = K₀: with K₀ = ½·m·u²,
    # K₁ = ½·m·(u² + g²·h²), ΔU = ½·m·g²·h², that is 5/4·λ² + λ = 1/4, λ = 1/5.
    h, mass = 0.1, 2.0
    u = G * h / 2
    world = ballpit.World(gravity=(0, -G, 0), integrator="rk2")
    world.add_sphere(position=(0, 1, 0), radius=0.1, mass=mass, velocity=(u, 0, 0))
    model, state = world.model, world.state
    start, before = energy(world), state.body[[0]].copy()
    push = ConstantPerBall(np.array([[0.0, 2.0 * G, 0.0]]), np.zeros((1, 3)))
    integrate(model.integrator, state.body, [*model.forces(), push], h, Workspace())
    ball = world.spheres[0]
    assert ball.position == pytest.approx((u * h, 1 + 0.5 * G * h * h, 0), abs=1e-12)  # the push's path
    assert energy(world) - start == pytest.approx(mass * G * G * h * h, rel=1e-12)  # its work

    energy_guard.keep_interval(model, state, np.array([0]), before)
    assert energy(world) <= start + 1e-12
    assert ball.position == pytest.approx((u * h / 5, 1 + G * h * h / 10, 0), abs=1e-12)
    assert ball.velocity == pytest.approx((u / 5, G * h / 5, 0), abs=1e-12)  # it still tells the move
