"""Ball–plane impacts: bounce heights, reflection, edges, corners, two-sided planes, fast balls."""

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics import INTEGRATOR_NAMES

G = 9.81
# Time of impact stops a ball at most this far short of touching (half the engine's 10 µm contact
# slop), so a bounce may come up to this gap early: the one departure from an exact impact it allows.
IMPACT_GAP = 0.5e-5


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


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
@pytest.mark.parametrize("rate", [60, pytest.param(240, marks=pytest.mark.slow)])
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


def test_oblique_bounce_leaves_at_twenty_sevenths_and_spins_at_minus_forty_sevenths():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(restitution=0.8, friction=0.5)
    ball = world.add_sphere(position=(0, 1.0, 0), radius=0.5, velocity=(4.0, -3.0, 0))
    contacts = world.step(0.5)
    # The contact point is dragged back along +x, so the ball spins about −z (ω = n × v / r sense).
    assert ball.angular_velocity[2] < -1.0
    assert ball.velocity[0] < 4.0
    # A solid sphere (m = 1, r = 1/2, I = (2/5)·m·r² = 1/10), e = 0.8·1.0, μ = √(0.5·0.5) = 1/2.
    # Normal: J_n = m·(1 + e)·3 = 5.4, so v_y' = e·3 = 2.4.
    # Tangent: the contact point slips at v_x + r·ω_z = 4; stopping it takes J_t = slip / (1/m + r²/I)
    # = (2/7)·m·4 = 8/7 ≤ μ·J_n = 2.7, so the contact sticks and the ball leaves rolling:
    #   v_x' = (5/7)·v_x − (2/7)·r·ω_z = (5/7)·4 = 20/7,   ω_z' = ω_z − r·J_t/I = −(1/2)·(8/7)·10 = −40/7
    # (and v_x' + r·ω_z' = 0). For a sphere on a plane the normal and tangent rows are independent and the
    # solve is exact in one sweep, so only rounding separates the engine from the closed form.
    assert ball.velocity == pytest.approx([20 / 7, 2.4, 0.0], rel=1e-12, abs=1e-12)
    assert ball.angular_velocity == pytest.approx([0.0, 0.0, -40 / 7], rel=1e-12, abs=1e-12)
    assert len(contacts) == 1
    assert contacts.normal[0] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    assert contacts.impulse[0] == pytest.approx(5.4, rel=1e-12)
    # Time of impact stops the ball a gap δ ≤ IMPACT_GAP short of touching (here the face is infinite,
    # so the velocities above do not depend on δ). It bounces δ/3 s early, at y = 1/2 + δ, instead of at
    # t = 1/6: the exact x = 4·(1/6) + (20/7)·(1/3) = 34/21 and y = 1/2 + 2.4·(1/3) = 1.3 move by
    # −(4 − 20/7)·δ/3 = −(8/21)·δ and +(1 + 0.8)·δ.
    assert contacts.time[0] == pytest.approx(1 / 6, abs=IMPACT_GAP / 3 + 1e-12)
    assert ball.position[0] == pytest.approx(34 / 21, abs=8 / 21 * IMPACT_GAP + 1e-12)
    assert ball.position[1] == pytest.approx(1.3, abs=1.8 * IMPACT_GAP + 1e-12)


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


def dropped_past_a_rim(offset, height: float, radius: float, e: float, duration: float, gap: float = 0.0):
    """Closed form for a frictionless ball dropped from rest at ``height`` beside a level square at y = 0,
    its centre ``offset`` = (dx, dz) outside the rim point (an edge point or a corner) it clips.

    The ball touches when its centre is r + gap from the rim point (gap = 0: exactly touching), at height
    y_c = √((r + gap)² − dx² − dz²) and time t = √(2·(height − y_c)/g). It is deflected along the normal
    from the rim point to its centre, n = (dx, y_c, dz)/(r + gap): v' = v − (1 + e)·(v·n)·n, an impulse
    m·(1 + e)·|v·n|; without friction the tangential velocity and the spin (zero) are left alone. Then it
    flies off under gravity. Positions are relative to the rim point.
    """
    d = np.array([offset[0], 0.0, offset[1]])
    reach = radius + gap
    y_c = math.sqrt(reach**2 - d @ d)
    normal = (d + (0.0, y_c, 0.0)) / reach
    t = math.sqrt(2 * (height - y_c) / G)
    v_in = np.array([0.0, -G * t, 0.0])
    v_out = v_in - (1 + e) * (v_in @ normal) * normal
    flight = duration - t
    down = np.array([0.0, -G, 0.0])
    return {
        "time": t,
        "normal": normal,
        "impulse": -(1 + e) * (v_in @ normal),
        "velocity": v_out + down * flight,
        "position": d + (0.0, y_c, 0.0) + v_out * flight + 0.5 * down * flight**2,
    }


def assert_rim_bounce(world, ball, hits, rim, offset, height: float, e: float) -> None:
    """The ball clipped ``rim`` once and left as ``dropped_past_a_rim`` says (mass 1, frictionless)."""
    assert len(hits) == 1 and len(hits[0]) == 1
    hit = hits[0]
    assert hit.point[0] == pytest.approx(rim, abs=1e-12)
    got = {
        "time": hit.time[0],
        "normal": hit.normal[0],
        "impulse": hit.impulse[0],
        "velocity": ball.velocity,
        "position": ball.position - rim,
    }
    r, duration = ball.radius, world.time
    exact = dropped_past_a_rim(offset, height, r, e, duration)
    # Exactly touching, within what bouncing up to IMPACT_GAP early can change (a few µm; every quantity
    # here moves smoothly and monotonically with the gap over so short a range).
    early = dropped_past_a_rim(offset, height, r, e, duration, gap=IMPACT_GAP)
    for key, value in exact.items():
        assert got[key] == pytest.approx(value, abs=np.max(np.abs(early[key] - value)) + 1e-12), key
    # And tightly: the gap the ball actually bounced at follows from the reported time of impact (its
    # centre is then at y_c = height − g·t²/2); it lies within IMPACT_GAP, and at that gap the closed
    # form holds to rounding (a few 1e-14 relative: the free flight is a parabola the integrator follows
    # exactly, and a single frictionless contact is solved in one sweep).
    y_c = height - 0.5 * G * hit.time[0] ** 2
    gap = math.sqrt(offset[0] ** 2 + offset[1] ** 2 + y_c**2) - r
    assert -1e-12 <= gap <= IMPACT_GAP
    at_gap = dropped_past_a_rim(offset, height, r, e, duration, gap=gap)
    for key, value in at_gap.items():
        assert got[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
    assert ball.angular_velocity == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)


def test_ball_clipping_a_square_edge_leaves_along_the_normal_from_the_edge_to_its_centre():
    world = ballpit.World()
    world.add_plane(size=2.0, friction=0.0)
    ball = world.add_sphere(position=(1.3, 2.0, 0.0), radius=0.5, friction=0.0)
    hits = []
    for _ in range(480):
        contacts = world.step(1 / 240)
        if len(contacts):
            hits.append(contacts)
    assert ball.velocity[0] > 0.5
    assert ball.position[0] > 1.5
    assert abs(ball.velocity[2]) < 1e-9
    # Its centre falls 0.3 m outside the edge x = 1 of the 2 m square, e = 1.0·0.8: it touches the edge
    # point (1, 0, 0) with its centre at y_c = √(0.5² − 0.3²) = 0.4, so n = (0.3, 0.4, 0)/0.5 = (0.6, 0.8, 0),
    # after falling 1.6 m to speed s = √(2·g·1.6); it leaves at s·(0, −1, 0) + 1.8·(0.8·s)·n
    # = s·(0.864, 0.152, 0).
    s = math.sqrt(2 * G * 1.6)
    exact = dropped_past_a_rim((0.3, 0.0), 2.0, 0.5, 0.8, world.time)
    assert exact["normal"] == pytest.approx([0.6, 0.8, 0.0], rel=1e-14, abs=1e-14)
    assert exact["impulse"] == pytest.approx(1.8 * 0.8 * s, rel=1e-14)
    # (Bouncing up to IMPACT_GAP early tilts n and shortens the fall: v_x moves by at most 7e-6 relative.)
    assert ball.velocity[0] == pytest.approx(0.864 * s, rel=1e-5)
    assert_rim_bounce(world, ball, hits, rim=(1.0, 0.0, 0.0), offset=(0.3, 0.0), height=2.0, e=0.8)


def test_ball_clipping_a_square_corner_leaves_along_the_normal_from_the_corner_to_its_centre():
    world = ballpit.World()
    world.add_plane(size=2.0, friction=0.0)
    ball = world.add_sphere(position=(1.25, 2.0, 1.25), radius=0.5, friction=0.0)
    hits = []
    for _ in range(480):
        contacts = world.step(1 / 240)
        if len(contacts):
            hits.append(contacts)
    vx, _, vz = ball.velocity
    assert vx > 0.3 and vz > 0.3
    assert vx == pytest.approx(vz, rel=1e-9)
    # Its centre falls 0.25 m outside both edges, past the corner (1, 0, 1): it touches with its centre
    # at y_c = √(0.5² − 2·0.25²) = √(1/8), so n = (1/2, 1/√2, 1/2), after falling h = 2 − √(1/8) to speed
    # s = √(2·g·h); v·n = −s/√2, so it leaves at s·(0, −1, 0) + 1.8·(s/√2)·n = s·(0.9/√2, −0.1, 0.9/√2).
    s = math.sqrt(2 * G * (2.0 - math.sqrt(1 / 8)))
    exact = dropped_past_a_rim((0.25, 0.25), 2.0, 0.5, 0.8, world.time)
    assert exact["normal"] == pytest.approx([0.5, 1 / math.sqrt(2), 0.5], rel=1e-14, abs=1e-14)
    assert exact["impulse"] == pytest.approx(1.8 * s / math.sqrt(2), rel=1e-14)
    # (Bouncing up to IMPACT_GAP early moves v_x by at most 3e-6 relative.)
    assert vx == pytest.approx(0.9 / math.sqrt(2) * s, rel=1e-5)
    assert_rim_bounce(world, ball, hits, rim=(1.0, 0.0, 1.0), offset=(0.25, 0.25), height=2.0, e=0.8)


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
