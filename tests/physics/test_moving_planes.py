"""Kinematic planes: contacts use the plane's surface velocity, so the textbook answers hold on moving
and turning planes too, at 60 Hz and at 240 Hz, and nothing passes through a moving plane."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.core.settings import CONTACT_SLOP, PENETRATION_TOLERANCE

G = 9.81
RATES = [60, 240]


@pytest.mark.parametrize("hz", RATES)
def test_ball_rides_an_elevator_without_jitter(hz):
    u, r = 1.5, 0.25
    world = ballpit.World()
    lift = world.add_plane(size=2.0, velocity=(0, u, 0))
    ball = world.add_sphere(position=(0, r, 0), radius=r, velocity=(0, u, 0))
    for _ in range(2 * hz):
        world.step(1 / hz)
        assert ball.velocity == pytest.approx((0, u, 0), abs=1e-9)
        assert ball.position[1] - lift.position[1] == pytest.approx(r, abs=1e-9)
    assert lift.position[1] == pytest.approx(2 * u, rel=1e-12)  # the plane moved as told


@pytest.mark.parametrize("hz", RATES)
def test_a_bounce_on_a_plane_moving_at_constant_velocity_is_the_bounce_on_a_still_one(hz):
    # Galilean invariance: the same drop, once onto a still floor and once onto a floor moving at u,
    # with the ball given u as well. Seen from the floor, the two runs are the same, apexes e²·h and all.
    h, r, e = 1.0, 0.1, 0.8
    u = np.array([2.0, -0.5, 0.0])
    still, moving = ballpit.World(), ballpit.World()
    still.add_plane(restitution=e)
    floor = moving.add_plane(restitution=e, velocity=u)
    a = still.add_sphere(position=(0, h + r, 0), radius=r)
    b = moving.add_sphere(position=(0, h + r, 0), radius=r, velocity=u)
    apexes, rising = [], False
    for _ in range(round(2.5 * hz)):
        still.step(1 / hz)
        moving.step(1 / hz)
        seen_from_floor = b.position - floor.position
        assert seen_from_floor == pytest.approx(a.position, abs=2e-5)
        assert b.velocity - u == pytest.approx(a.velocity, abs=1e-4)
        if rising and b.velocity[1] - u[1] <= 0:
            apexes.append(seen_from_floor[1] - r)
        rising = b.velocity[1] - u[1] > 0
    # apex after the first bounce: e²·h (to within one step's rise near the top, g·dt²/8)
    assert apexes[0] == pytest.approx(e**2 * h, abs=G / hz**2)


@pytest.mark.parametrize("hz", RATES)
@pytest.mark.parametrize("e", [0.5, 1.0])
def test_paddle_moving_at_u_launches_a_resting_ball_at_one_plus_e_times_u(hz, e):
    u, r = 3.0, 0.2
    world = ballpit.World(gravity=(0, 0, 0))
    paddle = world.add_plane(position=(-r, 0, 0), normal=(1, 0, 0), size=1.0, restitution=e,
                             velocity=(u, 0, 0), friction=0.0)  # fmt: skip
    ball = world.add_sphere(position=(0, 0, 0), radius=r)
    for _ in range(hz // 4):
        world.step(1 / hz)
    assert ball.velocity == pytest.approx(((1 + e) * u, 0, 0), rel=1e-12, abs=1e-12)
    assert ball.position[0] - paddle.position[0] >= r - 1e-9


@pytest.mark.parametrize("hz", RATES)
def test_paddle_at_300_m_s_never_passes_a_small_ball(hz):
    u, r, e = 300.0, 0.01, 0.6
    world = ballpit.World(gravity=(0, 0, 0))
    paddle = world.add_plane(position=(-3.0, 0, 0), normal=(1, 0, 0), size=0.2, restitution=e,
                             velocity=(u, 0, 0))  # fmt: skip
    ball = world.add_sphere(position=(0, 0, 0), radius=r)
    for _ in range(hz // 10):  # the paddle moves 1.25 m (60 Hz) or 5 m (240 Hz) per step... 30 m in all
        world.step(1 / hz)
        assert ball.position[0] - paddle.position[0] >= r - 1e-6  # never behind the paddle
    assert ball.velocity[0] == pytest.approx((1 + e) * u, rel=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("hz", RATES)
def test_square_tilted_under_a_resting_ball_never_lets_it_sink_then_it_rolls_at_five_sevenths(hz):
    r, theta, rate = 0.2, math.radians(20.0), 0.25  # rad/s: about 1.4 s of tilting
    world = ballpit.World()
    square = world.add_plane(size=6.0, friction=0.5)  # μ ≥ (2/7)·tan θ: the ball rolls
    ball = world.add_sphere(position=(0, r, 0), radius=r, friction=0.5)
    dt = 1 / hz
    square.angular_velocity = (0, 0, rate)
    # Within one step the surface under the ball turns by ω·dt about a point beside it, which brings
    # it at most r·(1 − cos ω·dt) closer (second order: 1.7 µm at 60 Hz); the next step takes that
    # back, down to the overlap the engine leaves alone as rounding. Sinking would be that overlap
    # growing from step to step.
    turn_in_a_step = r * (1 - math.cos(rate * dt)) + PENETRATION_TOLERANCE
    for _ in range(round(theta / rate / dt)):
        world.step(dt)
        assert square.signed_distance(ball.position) >= r - turn_in_a_step
    square.angular_velocity = (0, 0, 0)
    n = square.normal
    sin_theta = math.hypot(n[0], n[2])  # the slope's actual tilt
    downhill = np.cross(np.cross(n, (0, -1, 0)), n)  # the slope's steepest descent
    downhill /= np.linalg.norm(downhill)
    for _ in range(hz // 4):  # let whatever the turning left behind settle into rolling
        world.step(dt)
    v0, t = float(ball.velocity @ downhill), 0.5
    for _ in range(round(t * hz)):
        world.step(dt)
        # on the surface: touching means within the contact slop (10 µm), which a ball the turning
        # left a few µm up keeps, as on a still slope
        assert square.signed_distance(ball.position) == pytest.approx(r, abs=1e-5)
    a = (float(ball.velocity @ downhill) - v0) / t
    assert a == pytest.approx(5 / 7 * G * sin_theta, rel=1e-6)
    assert ball.angular_velocity == pytest.approx(np.cross(n, ball.velocity) / r, abs=1e-6)


@pytest.mark.parametrize("hz", RATES)
@pytest.mark.parametrize("speed", [2.0, -2.0])
def test_ball_rolling_across_a_turning_plank_keeps_contact_in_one_interval_a_step(hz, speed):
    # A see-saw plank turning at constant ω under a ball rolling along it at s. Solved against the
    # contact as it is at the start of each step, the ball ended each step approaching or leaving the
    # plank at about 2·ω·s·dt (the turning frame's Coriolis term): rolling one way it sank 7 µm (240 Hz)
    # to 110 µm (60 Hz) into the plank, the other way it floated beyond the 10 µm contact slop and
    # every step split at its little falls (up to 9 intervals a step).
    rate, r = 0.2, 0.2
    world = ballpit.World()
    plank = world.add_plane(size=(12.0, 4.0), angular_velocity=(0, 0, rate), friction=0.6)
    ball = world.add_sphere(position=(0, r, 0), radius=r, velocity=(speed, 0, 0),
                            angular_velocity=(0, 0, -speed / r), friction=0.6)  # fmt: skip
    for _ in range(hz):  # one second: the plank tilts 11.5° and the ball rolls about 2 m along it
        world.step(1 / hz)
        assert world.profile.intervals == 1
        gap = plank.signed_distance(ball.position) - r
        assert -0.5e-6 < gap < CONTACT_SLOP  # touching, and not sinking
        # no jitter: the ball moves with the plank's surface under it along the normal (µm/s)
        under = ball.position - r * plank.normal - plank.position
        surface = np.cross(plank.angular_velocity, under)
        assert (ball.velocity - surface) @ plank.normal == pytest.approx(0.0, abs=2e-6)
    assert abs(ball.position[0]) > 1.5  # it did roll along the plank


def test_plane_motion_is_validated_and_kept_in_snapshots():
    world = ballpit.World()
    plane = world.add_plane(velocity=(0, 1, 0))
    with pytest.raises(ValueError, match="angular_velocity"):
        plane.angular_velocity = (0, float("nan"), 0)
    with pytest.raises(ValueError, match="velocity"):
        world.add_plane(velocity=(0, 1))
    snap = world.snapshot()
    world.step(0.5)
    assert plane.position[1] == pytest.approx(0.5)
    world.restore(snap)
    assert plane.position[1] == 0.0 and plane.velocity[1] == 1.0


def test_kept_pairs_of_still_planes_are_the_pairs_found_afresh_while_another_plane_moves():
    # While a plane moves, only the planes that move now or moved when their pairs were found have
    # them found again each step; the still planes' kept pairs must be exactly what finding every
    # plane's again gives, in the same order, also for a plane that has just stopped.
    import copy

    from ballpit.physics.collision.pairs import plane_pairs, refresh_moving

    dt = 1 / 240
    world = ballpit.World()
    world.add_plane(restitution=0.3)  # floor, still
    plank = world.add_plane(position=(0, 1, 0), size=(4, 2), angular_velocity=(0, 0, -0.3))
    paddle = world.add_plane(position=(2.5, 1, 0), normal=(-1, 0, 0), size=(2, 3), velocity=(-0.3, 0, 0))
    positions = np.random.default_rng(2).uniform((-1.5, 0.2, -0.5), (2.3, 2.5, 0.5), (12, 3))
    world.add_spheres(positions, radius=0.15)
    compared = 0
    for k in range(360):
        if k == 100:
            paddle.velocity = (0, 0, 0)  # its pairs were found while it moved: found again once
        if k == 220:
            plank.angular_velocity = (0, 0, 0)
            paddle.velocity = (0.2, 0, 0)
        kept = world.parts.pairs.kept
        if kept is not None:
            model, state = world.model, world.state
            refreshed = copy.deepcopy(kept)
            refresh_moving(model, state, refreshed, dt)
            sphere, plane = plane_pairs(model, state, kept.lo, kept.hi, dt)
            assert refreshed.sphere.tolist() == sphere.tolist()
            assert refreshed.plane.tolist() == plane.tolist()
            compared += len(sphere)
        world.step(dt)
    assert compared > 1000  # the balls were near the planes throughout


def test_a_turning_plane_is_moved_as_the_quaternion_functions_move_it_bit_for_bit():
    # advance works each plane in Python floats; its pose must be the one quaternion.from_axis_angle,
    # multiply, normalize and rotate give (exact.norm for the normal), to the last bit.
    from ballpit.physics.core import exact, quaternion
    from ballpit.physics.dynamics import moving_planes

    rng = np.random.default_rng(4)
    world = ballpit.World()
    for _ in range(3):
        world.add_plane(position=rng.standard_normal(3), rotation=rng.uniform(-180, 180, 3), size=1.0,
                        velocity=rng.standard_normal(3), angular_velocity=rng.standard_normal(3))  # fmt: skip
    pose, spin = world.state.planes, world.model.planes.angular_velocity
    for h in (1 / 240, 1 / 60, 3.7e-4, 1 / 240):
        center = pose.center + world.model.planes.velocity * h
        rate = np.linalg.norm(spin, axis=1)
        turn = quaternion.from_axis_angle(spin / rate[:, None], rate * h)
        q = quaternion.normalize(quaternion.multiply(turn, pose.orientation))
        axes = [quaternion.rotate(qi, np.eye(3)) for qi in q]
        moving_planes.advance(world.model, world.state, h)
        assert pose.center.tobytes() == center.tobytes()
        assert pose.orientation.tobytes() == q.tobytes()
        assert pose.axis_u.tobytes() == np.array([a[0] for a in axes]).tobytes()
        assert pose.normal.tobytes() == np.array([a[1] / exact.norm_rows(a[1]) for a in axes]).tobytes()
        assert pose.axis_v.tobytes() == np.array([a[2] for a in axes]).tobytes()
