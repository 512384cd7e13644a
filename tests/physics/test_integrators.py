"""Integrators against closed-form free flight, drag and spin; the registry's paths against the
integrators' own steps; RK4's fast path against RK4."""

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics.core import quaternion
from ballpit.physics.core.settings import RK4_CHUNK
from ballpit.physics.core.state import Q, V, W, X
from ballpit.physics.dynamics.forces import ConstantPerBall, Gravity, constant_acceleration
from ballpit.physics.dynamics.integrators import (
    INTEGRATOR_NAMES,
    INTEGRATORS,
    Workspace,
    integrate,
    rk4,
    rk4_constant,
)

G = 9.81


def run(world: ballpit.World, dt: float, duration: float) -> None:
    for _ in range(round(duration / dt)):
        world.step(dt)


@pytest.mark.parametrize("integrator", ["rk2", "rk4"])
def test_rk_methods_reproduce_free_fall_exactly(integrator):
    world = ballpit.World(integrator=integrator)
    ball = world.add_sphere(position=(1.0, 30.0, -2.0), velocity=(2.0, 3.0, 0.5))
    run(world, 1 / 60, 2.0)
    t = 2.0
    expected = np.array([1.0 + 2.0 * t, 30.0 + 3.0 * t - 0.5 * G * t * t, -2.0 + 0.5 * t])
    assert np.max(np.abs(ball.position - expected)) < 1e-8
    assert np.max(np.abs(ball.velocity - [2.0, 3.0 - G * t, 0.5])) < 1e-8


def test_euler_free_fall_error_is_half_g_t_dt_and_halves_with_dt():
    errors = []
    for dt in (1 / 60, 1 / 120):
        world = ballpit.World(integrator="euler")
        ball = world.add_sphere(position=(0.0, 50.0, 0.0))
        run(world, dt, 2.0)
        exact = 50.0 - 0.5 * G * 2.0**2
        error = ball.position[1] - exact
        # Forward Euler lags by one step of velocity: y_n = y0 − ½g·t² + ½g·t·dt.
        assert error == pytest.approx(0.5 * G * 2.0 * dt, rel=1e-9)
        errors.append(error)
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=1e-6)


def test_symplectic_euler_free_fall_runs_half_g_t_dt_low_with_exact_velocity():
    """Kick then drift: v_n = v0 − g·n·dt exactly, y_n = y0 + Σ dt·v_k = y0 + v0·t − ½g·t² − ½g·t·dt."""
    for dt in (1 / 60, 1 / 120):
        world = ballpit.World(integrator="symplectic")
        ball = world.add_sphere(position=(0.0, 50.0, 0.0), velocity=(1.0, 4.0, 0.0))
        run(world, dt, 2.0)
        t = 2.0
        assert ball.velocity == pytest.approx([1.0, 4.0 - G * t, 0.0], abs=1e-11)
        exact = 50.0 + 4.0 * t - 0.5 * G * t * t
        assert ball.position[1] - exact == pytest.approx(-0.5 * G * t * dt, rel=1e-9)
        assert ball.position[0] == pytest.approx(t, abs=1e-11)


def drag_position(t: float, x0, v0, g, c):
    """Closed form of x'' = g − c·x': x = x0 + (g/c)t + (v0 − g/c)(1 − e^(−ct))/c."""
    x0, v0, g = (np.asarray(a, float) for a in (x0, v0, g))
    return x0 + g / c * t + (v0 - g / c) * (1 - math.exp(-c * t)) / c


@pytest.mark.parametrize(("integrator", "order"), [(i.name, i.order) for i in INTEGRATORS.values()])
def test_linear_drag_error_shrinks_at_the_integrators_order(integrator, order):
    """Every registered integrator, against the closed form, at the order the registry declares."""
    c, duration = 0.8, 2.0
    x0, v0, g = (0.0, 10.0, 0.0), (3.0, 12.0, -1.0), (0.0, -G, 0.0)
    exact = drag_position(duration, x0, v0, g, c)
    errors = []
    for dt in (0.1, 0.05, 0.025):
        world = ballpit.World(gravity=g, integrator=integrator, linear_drag=c)
        ball = world.add_sphere(position=x0, velocity=v0)
        run(world, dt, duration)
        errors.append(np.linalg.norm(ball.position - exact))
    observed = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert observed == pytest.approx([order, order], abs=0.15)


def test_angular_drag_decays_spin_exponentially():
    c = 1.5
    world = ballpit.World(gravity=(0, 0, 0), angular_drag=c)
    ball = world.add_sphere(angular_velocity=(0.0, 4.0, 3.0))
    run(world, 1 / 240, 1.0)
    assert ball.angular_velocity == pytest.approx(np.array([0.0, 4.0, 3.0]) * math.exp(-c), rel=1e-8)


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
def test_quarter_turn_about_y_takes_x_to_minus_z(integrator):
    world = ballpit.World(gravity=(0, 0, 0), integrator=integrator)
    ball = world.add_sphere(angular_velocity=(0.0, 2 * math.pi, 0.0))
    run(world, 1 / 240, 0.25)
    x_axis = quaternion.rotate(ball.orientation, np.array([1.0, 0.0, 0.0]))
    tolerance = {1: 1e-3, 2: 1e-4, 4: 1e-8}[INTEGRATORS[integrator].order]
    assert x_axis == pytest.approx([0.0, 0.0, -1.0], abs=tolerance)


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
def test_quaternion_stays_unit_and_on_course_over_ten_seconds_of_fast_spin(integrator):
    omega = np.array([30.0, -20.0, 45.0])
    world = ballpit.World(gravity=(0, 0, 0), integrator=integrator)
    ball = world.add_sphere(angular_velocity=omega)
    norms = []
    for _ in range(2400):
        world.step(1 / 240)
        norms.append(np.linalg.norm(ball.orientation))
    assert np.max(np.abs(np.array(norms) - 1.0)) < 1e-12


def test_rk4_orientation_follows_the_exact_rotation_over_ten_seconds_of_fast_spin():
    omega = np.array([30.0, -20.0, 45.0])  # 58 rad/s: 0.24 rad per step at 240 Hz
    world = ballpit.World(gravity=(0, 0, 0), integrator="rk4")
    ball = world.add_sphere(angular_velocity=omega)
    run(world, 1 / 240, 10.0)
    # Constant ω: the exact orientation is a rotation by |ω|·t about ω̂ (583 rad in all).
    speed = np.linalg.norm(omega)
    exact = quaternion.from_axis_angle(omega / speed, speed * 10.0)
    assert min(np.linalg.norm(ball.orientation - exact), np.linalg.norm(ball.orientation + exact)) < 1e-3


def test_integrator_can_be_switched_on_a_live_world():
    world = ballpit.World(integrator="euler")
    ball = world.add_sphere(position=(0, 10, 0))
    world.step(0.1)
    assert ball.position[1] == pytest.approx(10.0)  # Euler moves with the old velocity (zero)
    world.integrator = "rk4"
    world.step(0.1)
    # RK4 is exact from the state it was handed: y = 10 + v·t − ½g·t², v = −0.981.
    assert ball.position[1] == pytest.approx(10.0 - 0.0981 - 0.5 * G * 0.01, abs=1e-12)
    assert world.integrator == "rk4"


def random_states(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 13) states: positions, velocities, unit orientations and spins, with a share of balls that
    neither move nor spin and of orientations holding signed zeros (RK4's fast path treats them apart)."""
    state = np.empty((n, 13))
    state[:, X] = rng.uniform(-10.0, 10.0, (n, 3))
    state[:, V] = rng.normal(0.0, 5.0, (n, 3))
    q = rng.normal(size=(n, 4))
    state[:, Q] = q / np.linalg.norm(q, axis=1, keepdims=True)
    state[:, W] = rng.normal(0.0, 20.0, (n, 3))
    still = rng.random(n) < 0.3
    state[still, 3:6] = 0.0
    state[still, W] = 0.0
    state[still, Q] = [0.0, 0.0, 0.0, 1.0]
    signed = rng.random(n) < 0.1
    state[signed & still, 6] = -0.0
    return state


@pytest.mark.parametrize("n", [1, 7, RK4_CHUNK + 5])
@pytest.mark.parametrize("per_ball", [False, True])
@pytest.mark.parametrize("spun_up", [False, True])
def test_rk4_constant_equals_rk4_bit_for_bit(n, per_ball, spun_up):
    """The fast path for constant forces against the four-stage RK4 and ``normalize`` it stands for,
    on random states: every bit of every ball, across chunk boundaries, with one acceleration for all
    or one per ball, and with or without angular accelerations."""
    rng = np.random.default_rng(n + 2 * per_ball + 4 * spun_up)
    for h in (1 / 240, 0.037):
        state = random_states(rng, n)
        lin = rng.normal(0.0, 10.0, (n, 3)) if per_ball else np.zeros((n, 3))
        ang = rng.normal(0.0, 5.0, (n, 3)) if spun_up else np.zeros((n, 3))
        if spun_up:
            ang[rng.random(n) < 0.5] = 0.0
        forces = [Gravity(np.array([0.0, -9.81, 0.0]))]
        if per_ball or spun_up:
            forces.append(ConstantPerBall(lin, ang))
        accel = constant_acceleration(forces)
        assert accel is not None
        slow, fast = state.copy(), state.copy()
        rk4(slow, forces, h, Workspace())
        quaternion.normalize(slow[:, Q], out=slow[:, Q])
        rk4_constant(fast, *accel, h, Workspace())
        assert fast.tobytes() == slow.tobytes()


@pytest.mark.parametrize("integrator", INTEGRATOR_NAMES)
def test_each_registered_path_is_where_its_integrator_takes_a_ball(integrator):
    """What the broad phase and the time of impact assume about a step (``path_end``, ``position_at``,
    ``sag``, ``closing_speed_bound``) holds for the step the integrator takes, under constant
    acceleration: a new integrator whose ``bend`` is wrong fails here instead of tunnelling."""
    method = INTEGRATORS[integrator]
    rng = np.random.default_rng(1)
    n = 64
    state = random_states(rng, n)
    accel = rng.normal(0.0, 10.0, (n, 3))
    forces = [ConstantPerBall(accel, np.zeros((n, 3)))]
    x, v = state[:, X].copy(), state[:, V].copy()
    for h in (1 / 240, 0.05, 0.3):
        moved = state.copy()
        integrate(method, moved, forces, h, Workspace())
        end = method.path_end(x, v, accel, h)
        assert np.allclose(moved[:, X], end, rtol=0.0, atol=1e-12)
        assert np.allclose(method.position_at(x, v, accel, np.full((n, 1), h)), end, rtol=0.0, atol=1e-12)
        # the path's midpoint (its farthest from the chord, for a parabola) is within sag of the chord
        mid = method.position_at(x, v, accel, np.full((n, 1), h / 2))
        stray = np.linalg.norm(mid - (x + end) / 2, axis=1)
        sag = method.sag(np.linalg.norm(accel, axis=1), h)
        assert np.all(stray <= sag + 1e-12)
        assert np.allclose(stray, sag, rtol=1e-9, atol=1e-12)  # and the bound is tight
        # no pair closes faster than the bound at any time within the step
        ts = np.linspace(0.0, h, 9)[:, None, None]
        da, dv = accel[:32] - accel[32:], v[:32] - v[32:]
        path_speed = np.linalg.norm(dv + method.path_acceleration(da) * ts, axis=2)
        assert np.all(path_speed <= method.closing_speed_bound(dv, da, h) + 1e-12)


def test_the_registry_gives_each_integrator_its_own_name_label_colour_and_key():
    registered = list(INTEGRATORS.values())
    assert len(registered) >= 4
    for field in ("name", "label", "colour", "key"):
        values = [getattr(i, field) for i in registered]
        assert len(set(values)) == len(values), field
    for i in registered:
        assert len(i.colour) == 7 and i.colour[0] == "#" and all(0.0 <= c <= 1.0 for c in i.rgb)
    assert tuple(INTEGRATORS) == INTEGRATOR_NAMES
