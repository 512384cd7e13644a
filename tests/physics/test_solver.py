"""The colour-by-colour solve (solver.py): a ball coming to rest on rolling friction stops."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.dynamics.integrators import INTEGRATOR_NAMES

G = 9.81


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
@pytest.mark.parametrize("rolling", [0.05, 0.3, 2.0])
def test_a_lone_ball_brought_to_rest_by_rolling_friction_reports_zero_velocity(integrator, rolling):
    """A ball thrown along the floor with slip and spin, μ = 0.3, rolling friction ρ: it slides, rolls,
    and rolling resistance stops it at (5/7)·ρ·g. Friction and
    rolling resistance solved one after the other each undid part of the other: the ball stopped with a
    slip left over, reversed at 1.1 mm/s, and its velocity then shrank by a factor a step without ever
    reaching zero (the convergence test, blind to rolling, also ended the sweeps early). Once still it
    reports exactly zero velocity and spin, step after step, and stays where it stopped."""
    dt = 1 / 120
    world = ballpit.World(integrator=integrator)
    world.add_plane(friction=0.3, rolling_friction=rolling, restitution=0.5)
    ball = world.add_sphere(
        position=(0, 0.5, 0),
        radius=0.5,
        friction=0.3,
        rolling_friction=rolling,
        velocity=(0.5, 0.0, 0.15),
        angular_velocity=(0.5, 2.0, -1.0),
    )
    stop = 0.6 / (5 / 7 * rolling * G)  # a bound on its rolling time: it rolls at less than 0.6 m/s
    for _ in range(int((stop + 0.5) / dt)):
        world.step(dt)
    rest = ball.position.copy()
    for _ in range(int(1.0 / dt)):
        world.step(dt)
        assert np.array_equal(ball.velocity, np.zeros(3))
        assert np.array_equal(ball.angular_velocity, np.zeros(3))
    assert np.array_equal(ball.position, rest)
    assert rest[1] == pytest.approx(0.5, abs=1e-9)
