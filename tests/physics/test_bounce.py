"""Ball–plane impacts: bounce heights, reflection, edges, corners, two-sided planes, fast balls."""

import math

import numpy as np
import pytest

import ballpit

G = 9.81


def apexes(world: ballpit.World, ball, dt: float, duration: float) -> list[float]:
    """Heights of the ball's lowest point at each apex after a bounce (from y + v²/2g, exact in flight)."""
    found, previous = [], ball.velocity[1]
    for _ in range(round(duration / dt)):
        world.step(dt)
        vy = ball.velocity[1]
        if previous < 0 < vy:
            found.append(ball.position[1] - ball.radius + vy * vy / (2 * G))
        previous = vy
    return found


@pytest.mark.parametrize("integrator", ["rk2", "rk4"])
@pytest.mark.parametrize("rate", [60, 240])
def test_bounce_apex_is_e_squared_h_then_e_to_the_fourth_h(integrator, rate):
    e, h = 0.8, 1.0
    world = ballpit.World(integrator=integrator)
    world.add_plane(restitution=e)
    ball = world.add_sphere(position=(0, h + 0.5, 0), radius=0.5)
    first, second = apexes(world, ball, 1 / rate, 2.5)[:2]
    assert first == pytest.approx(e**2 * h, abs=1e-5)
    assert second == pytest.approx(e**4 * h, abs=1e-5)


@pytest.mark.parametrize("integrator", ["euler", "rk2", "rk4"])
@pytest.mark.parametrize("rate", [60, 240])
def test_a_bouncing_ball_comes_to_rest_with_every_integrator(integrator, rate):
    world = ballpit.World(integrator=integrator)
    world.add_plane()  # default restitution 0.8
    ball = world.add_sphere(position=(0, 2.0, 0), radius=0.25)
    for _ in range(8 * rate):
        world.step(1 / rate)
    assert np.linalg.norm(ball.velocity) < 1e-3
    assert ball.position[1] == pytest.approx(0.25, abs=1e-4)


def test_impact_impulse_is_m_one_plus_e_v():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(restitution=0.5)
    ball = world.add_sphere(position=(0, 1.0, 0), radius=0.5, mass=2.0, velocity=(0, -3.0, 0))
    contacts = world.step(0.5)
    assert len(contacts) == 1
    assert contacts.kind_names[0] == "sphere-plane"
    assert (contacts.a[0], contacts.b[0]) == (0, 0)
    assert contacts.impulse[0] == pytest.approx(2.0 * 1.5 * 3.0)
    assert contacts.time[0] == pytest.approx(0.5 / 3.0)
    assert contacts.point[0] == pytest.approx([0, 0, 0], abs=1e-5)
    assert contacts.normal[0] == pytest.approx([0, 1, 0])
    assert ball.velocity == pytest.approx([0, 1.5, 0])


def test_frictionless_elastic_slope_reflects_about_the_normal_without_spin():
    world = ballpit.World()
    slope = world.add_plane(rotation=(0, 0, 30), size=10.0, restitution=1.0, friction=0.0)
    n = slope.normal
    ball = world.add_sphere(position=(0, 3.0, 0), radius=0.2, friction=0.0)
    energy = world.kinetic_energy() + world.potential_energy()
    speed_before = None
    for _ in range(600):
        v_before = ball.velocity.copy()
        contacts = world.step(1 / 240)
        if len(contacts):
            speed_before = v_before
            break
    assert speed_before is not None
    # Reflection is instantaneous; compare the velocity just after with the mirror of the arrival.
    t_hit = contacts.time[0] - (world.time - 1 / 240)
    v_in = speed_before + np.array([0, -G, 0]) * t_hit
    v_out = ball.velocity - np.array([0, -G, 0]) * (1 / 240 - t_hit)
    assert v_out == pytest.approx(v_in - 2 * np.dot(v_in, n) * n, abs=1e-9)
    assert np.linalg.norm(ball.angular_velocity) == pytest.approx(0.0, abs=1e-12)
    assert world.kinetic_energy() + world.potential_energy() == pytest.approx(energy, rel=1e-9)


def test_oblique_bounce_with_friction_makes_the_ball_spin():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(restitution=0.8, friction=0.5)
    ball = world.add_sphere(position=(0, 1.0, 0), radius=0.5, velocity=(4.0, -3.0, 0))
    world.step(0.5)
    # The contact point is dragged back along +x, so the ball spins about −z (ω = n × v / r sense).
    assert ball.angular_velocity[2] < -1.0
    assert ball.velocity[0] < 4.0


@pytest.mark.parametrize("rotation", [(180, 0, 0), None])
def test_upside_down_plane_still_bounces_balls(rotation):
    world = ballpit.World()
    kwargs = {"rotation": rotation} if rotation else {"normal": (0, -1, 0)}
    world.add_plane(size=4.0, restitution=0.8, **kwargs)
    above = world.add_sphere(position=(0, 2.0, 0), radius=0.25)
    below = world.add_sphere(position=(1, -1.0, 0), radius=0.25, velocity=(0, 8.0, 0))
    lowest, highest, rebounds = np.inf, -np.inf, set()
    for _ in range(240):
        contacts = world.step(1 / 240)
        rebounds.update(contacts.a[contacts.kind == 0].tolist())
        lowest = min(lowest, above.position[1])
        highest = max(highest, below.position[1])
        if above.index in rebounds and below.index in rebounds:
            break
    assert rebounds == {above.index, below.index}
    assert lowest >= 0.25 - 1e-6 and above.velocity[1] > 0  # bounced up off the top face
    assert highest <= -0.25 + 1e-6 and below.velocity[1] < 0  # and down off the bottom face


def test_ball_clipping_a_square_edge_is_deflected_outwards():
    world = ballpit.World()
    world.add_plane(size=2.0, friction=0.0)
    ball = world.add_sphere(position=(1.3, 2.0, 0.0), radius=0.5, friction=0.0)
    for _ in range(480):
        world.step(1 / 240)
    assert ball.velocity[0] > 0.5
    assert ball.position[0] > 1.5
    assert abs(ball.velocity[2]) < 1e-9


def test_ball_clipping_a_square_corner_is_deflected_diagonally_outwards():
    world = ballpit.World()
    world.add_plane(size=2.0, friction=0.0)
    ball = world.add_sphere(position=(1.25, 2.0, 1.25), radius=0.5, friction=0.0)
    for _ in range(480):
        world.step(1 / 240)
    vx, _, vz = ball.velocity
    assert vx > 0.3 and vz > 0.3
    assert vx == pytest.approx(vz, rel=1e-9)


def test_ball_beside_a_square_falls_past_untouched():
    world = ballpit.World()
    world.add_plane(size=2.0)
    ball = world.add_sphere(position=(1.51, 2.0, 0.0), radius=0.5)
    touched = 0
    for _ in range(480):
        touched += len(world.step(1 / 240))
    assert touched == 0
    assert ball.position[1] == pytest.approx(2.0 - 0.5 * G * 4.0, abs=1e-8)


@pytest.mark.parametrize("restitution", [1.0, 0.5])
def test_a_500_m_per_s_ball_cannot_tunnel_through_a_thin_plane(restitution):
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0), normal=(1, 0, 0), size=1.0, restitution=restitution)
    ball = world.add_sphere(position=(-4.0, 0.0, 0.0), radius=0.05, velocity=(500.0, 0, 0))
    for _ in range(10):
        world.step(1 / 60)
    assert ball.position[0] < -0.05
    assert ball.velocity == pytest.approx([-500.0 * restitution, 0, 0])


def test_a_500_m_per_s_ball_falling_through_a_floor_under_gravity_stays_above_it():
    world = ballpit.World()
    world.add_plane(restitution=0.0)
    ball = world.add_sphere(position=(3.0, 10.0, -2.0), radius=0.1, velocity=(0, -500.0, 0))
    for _ in range(60):
        world.step(1 / 60)
        assert ball.position[1] >= 0.1 - 1e-6
    assert np.linalg.norm(ball.velocity) < 1e-3


def test_rolling_friction_stops_a_rolling_ball_after_v_squared_over_ten_sevenths_rho_g():
    rho, v0, r = 0.02, 2.0, 0.1
    world = ballpit.World()
    world.add_plane(friction=0.8, rolling_friction=rho)
    ball = world.add_sphere(
        position=(0, r, 0),
        radius=r,
        velocity=(v0, 0, 0),
        angular_velocity=(0, 0, -v0 / r),
        rolling_friction=1.0,
    )
    for _ in range(240 * 3):
        world.step(1 / 240)
    # Rolling resistance torque ρ·r·N with rolling kept by friction: a = −(5/7)·ρ·g.
    stop = v0**2 / (2 * (5 / 7) * math.sqrt(rho * 1.0) * G)
    assert ball.position[0] == pytest.approx(stop, rel=1e-3)
    assert np.linalg.norm(ball.velocity) < 1e-3
