"""Balls on an incline: rolling without slipping, or sliding with spin-up, per the textbook."""

import math

import numpy as np
import pytest

import ballpit

G = 9.81


def ball_on_incline(theta_deg: float, mu: float, integrator: str = "rk4", hollow: bool = False):
    world = ballpit.World(integrator=integrator)
    slope = world.add_plane(rotation=(0, 0, theta_deg), friction=mu)
    r = 0.2
    ball = world.add_sphere(position=slope.normal * r, radius=r, friction=mu, hollow=hollow)
    downhill = np.array([-math.cos(math.radians(theta_deg)), -math.sin(math.radians(theta_deg)), 0.0])
    return world, slope, ball, downhill


@pytest.mark.parametrize("integrator", ["rk2", "rk4"])
def test_ball_rolls_at_five_sevenths_g_sin_theta(integrator):
    theta = 25.0
    mu = 0.5  # ≥ (2/7)·tan θ = 0.133: static friction holds, the ball rolls
    world, slope, ball, downhill = ball_on_incline(theta, mu, integrator)
    t = 1.5
    for _ in range(round(t * 240)):
        world.step(1 / 240)
    a = 5 / 7 * G * math.sin(math.radians(theta))
    travelled = np.dot(ball.position - slope.normal * ball.radius, downhill)
    assert travelled == pytest.approx(0.5 * a * t * t, rel=1e-6)
    assert ball.velocity == pytest.approx(a * t * downhill, abs=1e-6)
    # rolling without slipping: ω = n × v / r
    assert ball.angular_velocity == pytest.approx(
        np.cross(slope.normal, ball.velocity) / ball.radius, abs=1e-6
    )
    assert np.dot(ball.position, slope.normal) == pytest.approx(
        ball.radius, abs=1e-6
    )  # neither sinks nor hops


def test_hollow_ball_rolls_at_three_fifths_g_sin_theta():
    theta = 20.0
    world, _slope, ball, downhill = ball_on_incline(theta, 0.5, hollow=True)
    for _ in range(240):
        world.step(1 / 240)
    # a = g sin θ / (1 + I/(m r²)) with I = 2/3 m r²
    assert np.dot(ball.velocity, downhill) == pytest.approx(
        3 / 5 * G * math.sin(math.radians(theta)), rel=1e-6
    )


def test_ball_slides_at_g_sin_minus_mu_cos_and_spins_up_at_five_halves_mu_g_cos_over_r():
    theta, mu = 30.0, 0.1  # < (2/7)·tan θ = 0.165: the ball slips
    world, slope, ball, downhill = ball_on_incline(theta, mu)
    t = 1.0
    for _ in range(240):
        world.step(1 / 240)
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    assert np.dot(ball.velocity, downhill) == pytest.approx(G * (s - mu * c) * t, rel=1e-6)
    spin_axis = np.cross(slope.normal, downhill)
    assert np.dot(ball.angular_velocity, spin_axis) == pytest.approx(
        2.5 * mu * G * c / ball.radius * t, rel=1e-6
    )
    # still slipping: the contact point moves downhill
    slip = ball.velocity + np.cross(ball.angular_velocity, -ball.radius * slope.normal)
    assert np.dot(slip, downhill) > 0.1


def test_ball_at_rest_on_level_ground_reports_zero_velocity_and_does_not_sink():
    world = ballpit.World()
    world.add_plane()
    ball = world.add_sphere(position=(0, 0.3, 0), radius=0.3)
    heights = []
    for _ in range(240 * 5):
        world.step(1 / 240)
        heights.append(ball.position[1])
        assert np.linalg.norm(ball.velocity) < 1e-9
    assert max(heights) - min(heights) < 1e-9  # no jitter
    assert min(heights) == pytest.approx(0.3, abs=1e-9)
