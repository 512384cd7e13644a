"""The split step (step/split.py) counts a step's intervals itself: the profile a step is timed into only
measures."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics import step as pipeline
from ballpit.physics.core.profile import StepProfile
from ballpit.physics.core.settings import CONTACT_SLOP, MAX_INTERVALS
from ballpit.physics.dynamics.integrators import INTEGRATOR_NAMES

G = 9.81


def landing_world() -> ballpit.World:
    """A ball 1 cm above the floor, falling at 1 m/s: it lands within the next 1/60 s step, so the step
    is split at the impact (two intervals)."""
    world = ballpit.World()
    world.add_plane(restitution=0.5)
    world.add_sphere(position=(0, 0.1 + 0.01, 0), radius=0.1, velocity=(0, -1.0, 0))
    return world


def test_a_step_lands_the_same_whatever_count_its_profile_starts_from(monkeypatch):
    # A profile whose counter says the step is already at its last allowed interval: when the split
    # step read its first interval and its bound on intervals from the profile, this one stopped the
    # ball in the air (finish_conservatively) instead of bouncing it.
    dt = 1 / 60
    plain, timed = landing_world(), landing_world()
    plain.step(dt)
    monkeypatch.setattr(pipeline, "StepProfile", lambda: StepProfile(intervals=MAX_INTERVALS - 1))
    timed.step(dt)
    assert np.array_equal(timed.state.body, plain.state.body)
    assert timed.profile.intervals == plain.profile.intervals == 2
    # and the step did what free fall and Newton's impact law say: landed at v₁ after t₁, left at e·v₁.
    # It lands within the contact slop of the floor, up to slop/v₁ early: (1 + e)·g·slop/v₁ in speed.
    v1 = math.sqrt(1.0 + 2 * G * 0.01)
    t1 = (v1 - 1.0) / G
    expected = 0.5 * v1 - G * (dt - t1)
    assert timed.spheres[0].velocity[1] == pytest.approx(expected, abs=1.5 * G * CONTACT_SLOP / v1)


def turned(degrees: float) -> np.ndarray:
    """A rotation by ``degrees`` about z after half as much about x."""
    a, b = math.radians(degrees), math.radians(degrees / 2)
    about_z = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    about_x = np.array([[1, 0, 0], [0, math.cos(b), -math.sin(b)], [0, math.sin(b), math.cos(b)]])
    return about_z @ about_x


def turned_box(world: ballpit.World, turn: np.ndarray, restitution: float = 0.8) -> None:
    """Six infinite walls facing in, |x|, |y|, |z| ≤ 1 in the frame ``turn`` takes to the world's."""
    for face in (*np.eye(3), *-np.eye(3)):
        world.add_plane(position=turn @ face, normal=-(turn @ face), restitution=restitution)


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
@pytest.mark.parametrize("degrees", [0.0, 20.0, 45.0])
def test_a_small_ball_pushed_out_of_a_big_one_beside_a_wall_does_not_fly_through_the_wall(
    integrator, degrees
):
    """A 0.316 m, 100 kg ball touching the wall x = −1 and a 1 mm ball inside its shell, 5.7 cm deep
    (a scene with overlap_tolerance = 0.06 may start so), moving at 10 m/s towards that wall. The
    push-apart moves the small ball 5.5 cm, to the wall; the interval was planned from the gaps
    measured before the move, so it flew on through the wall, 3 mm beyond it after step 0 and 42 mm
    a step after that. Measured again after the move, it meets the wall and bounces: its centre stays
    in the box, and it sinks into a wall by less than a tenth of its radius."""
    turn = turned(degrees)
    world = ballpit.World(integrator=integrator)
    turned_box(world, turn)
    big, small = 0.316, 0.001
    world.add_sphere(position=turn @ np.array([-1 + big, 0, 0]), radius=big, mass=100.0)
    world.add_sphere(
        position=turn @ np.array([-1 + big - 0.26, 0, 0]),
        radius=small,
        velocity=turn @ np.array([-10.0, 0, 0]),
    )
    radii = world.spheres.radii
    for _ in range(120):
        world.step(1 / 240)
        local = np.abs(world.spheres.positions @ turn).max(axis=1)
        assert (local < 1.0).all()  # no centre beyond a wall
        assert (local - (1.0 - radii) < 0.1 * radii).all()
