"""Sleeping: still islands fall asleep after half a second, cost nothing and wake when reached."""

import numpy as np
import pytest

import ballpit
from ballpit.physics.core.settings import SLEEP_SPEED, TIME_TO_SLEEP
from ballpit.physics.dynamics.sleeping import islands
from ballpit.scene import read_scene, resolve_scene_path

DT = 1 / 240


def resting_ball(sleep: bool = True) -> tuple[ballpit.World, object]:
    world = ballpit.World(sleep=sleep)
    world.add_plane(size=10.0)
    ball = world.add_sphere(position=(0, 0.5, 0), radius=0.5)
    return world, ball


def row_of_touching_balls(world: ballpit.World, count: int, r: float = 0.1, z: float = 0.0,
                          **material: float) -> np.ndarray:  # fmt: skip
    """``count`` balls touching in a row along x at ``z``, resting on the floor."""
    x = np.arange(count) * 2 * r
    return world.add_spheres(np.column_stack((x, np.full(count, r), np.full(count, z))), radius=r, **material)


def test_a_resting_ball_falls_asleep_after_the_time_to_sleep_and_then_does_not_move_at_all():
    world, _ = resting_ball()
    steps_to_sleep = round(TIME_TO_SLEEP / DT)
    for _ in range(steps_to_sleep - 2):
        world.step(DT)
    assert not world.asleep[0]
    for _ in range(4):
        world.step(DT)
    assert world.asleep[0]
    before = world.state.body.copy()
    for _ in range(240):
        contacts = world.step(DT)
        assert len(contacts) == 0  # nothing is solved for a sleeping ball
    assert np.array_equal(world.state.body, before)  # bit for bit where it fell asleep


def test_with_sleeping_off_a_resting_ball_never_falls_asleep():
    world, _ = resting_ball(sleep=False)
    for _ in range(480):
        world.step(DT)
    assert not world.asleep.any()
    assert ballpit.World().sleep is False


def test_a_moving_ball_never_falls_asleep():
    # sliding at 1 m/s on a frictionless floor for two seconds: never still
    world = ballpit.World(sleep=True)
    world.add_plane(friction=0.0)
    world.add_sphere(position=(0, 0.5, 0), radius=0.5, velocity=(1.0, 0, 0), friction=0.0)
    for _ in range(480):
        world.step(DT)
    assert not world.asleep.any()
    assert world.spheres.positions[0, 0] == pytest.approx(2.0 + 1 / 240, abs=0.02)


def test_touching_balls_sleep_together_only_when_all_are_still():
    world = ballpit.World(sleep=True)
    world.add_plane(friction=0.0)
    row = row_of_touching_balls(world, 5)
    # A second row whose last ball spins about the vertical at 10 rad/s (1 m/s at its surface), on
    # frictionless contacts: it stays in place touching its row, never still.
    spun = row_of_touching_balls(world, 5, z=1.0, friction=0.0)
    world.spheres[spun[-1]].angular_velocity = (0.0, 10.0, 0.0)
    far = world.add_sphere(position=(5.0, 0.1, 0.0), radius=0.1, velocity=(0.5, 0, 0), friction=0.0).index
    ever = np.zeros(len(world.spheres), bool)
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
        ever |= world.asleep
    assert world.asleep[row].all()
    assert not ever[
        spun
    ].any()  # four still balls never sleep, not even for a step: they touch one that spins
    assert not ever[far]


def test_a_ball_rolling_into_a_sleeping_row_wakes_it_and_the_impact_moves_the_row():
    world = ballpit.World(sleep=True)
    world.add_plane(friction=0.0)
    row = row_of_touching_balls(world, 5)
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    assert world.asleep[row].all()
    # a ball rolling along the floor hits the end of the row (Newton's cradle)
    striker = world.add_sphere(
        position=(-0.5, 0.1, 0.0), radius=0.1, velocity=(2.0, 0, 0), restitution=1.0, friction=0.0
    ).index
    for _ in range(120):
        world.step(DT)
    assert not world.asleep[row].any()
    v = world.spheres.velocities
    assert v[striker, 0] < 0.5  # it gave its momentum away instead of passing through
    assert v[row[-1], 0] > 0.5  # the far end of the row flew off
    x = world.spheres.positions[:, 0]
    assert np.all(np.diff(x[[striker, *row]]) >= 0.2 - 1e-3)  # nothing passed through anything


def test_setting_a_sleeping_balls_velocity_wakes_it():
    world, ball = resting_ball()
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    assert world.asleep[0]
    ball.velocity = (0.0, 3.0, 0.0)
    world.step(DT)
    assert not world.asleep[0]
    # thrown straight up: v = 3 − g·t after the first step
    assert ball.velocity[1] == pytest.approx(3.0 - 9.81 * DT, abs=1e-9)


def test_moving_a_sleeping_ball_by_hand_wakes_it_and_it_falls():
    world, ball = resting_ball()
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    ball.position = (0.0, 2.5, 0.0)
    for _ in range(24):
        world.step(DT)
    t = 24 * DT
    assert ball.position[1] == pytest.approx(2.5 - 0.5 * 9.81 * t * t, abs=1e-9)


def test_changing_gravity_wakes_every_ball():
    world, ball = resting_ball()
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    world.gravity = (0.0, 9.81, 0.0)  # upwards: the ball must fall off the floor, up
    for _ in range(24):
        world.step(DT)
    assert not world.asleep[0]
    assert ball.position[1] > 0.5 + 0.4 * 9.81 * (24 * DT) ** 2


def test_switching_sleeping_off_wakes_every_ball():
    world, _ = resting_ball()
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    world.sleep = False
    world.step(DT)
    assert not world.asleep.any()


@pytest.mark.slow
def test_a_restored_snapshot_repeats_a_run_with_sleeping_bit_for_bit():
    world = ballpit.World(sleep=True)
    world.add_plane(friction=0.5, rolling_friction=0.2)
    rng = np.random.default_rng(3)
    drop = rng.uniform((-1, 0.3, -1), (1, 1.5, 1), (30, 3))
    world.add_spheres(drop, radius=0.1, restitution=0.3, rolling_friction=0.2)
    for _ in range(400):
        world.step(DT)
    snap = world.snapshot()
    for _ in range(200):
        world.step(DT)
    first = world.state.body.copy(), world.asleep.copy()
    world.restore(snap)
    for _ in range(200):
        world.step(DT)
    assert np.array_equal(world.state.body, first[0])
    assert np.array_equal(world.asleep, first[1])
    assert first[1].any()


def test_sleep_rejects_what_is_not_true_or_false():
    with pytest.raises(TypeError, match="sleep"):
        ballpit.World(sleep="yes")


def test_islands_are_the_connected_groups_of_touching_balls():
    # 0-1-2 chained, 3-4, 5 alone, 6-7-8-6 a loop
    a = np.array([1, 2, 4, 6, 7, 8])
    b = np.array([0, 1, 3, 7, 8, 6])
    label = islands(9, a, b)
    assert label.tolist() == [0, 0, 0, 3, 3, 5, 6, 6, 6]


def test_still_means_below_the_sleep_speed_in_translation_and_in_spin():
    world = ballpit.World(sleep=True, gravity=(0, 0, 0))
    world.add_sphere(position=(0, 0, 0), radius=0.5, angular_velocity=(0, 0, 1.5 * SLEEP_SPEED / 0.5))
    world.add_sphere(position=(5, 0, 0), radius=0.5, velocity=(0.5 * SLEEP_SPEED, 0, 0))
    for _ in range(round(TIME_TO_SLEEP / DT) + 4):
        world.step(DT)
    assert world.asleep.tolist() == [False, True]  # spinning at 1.5× the sleep speed; drifting at half


@pytest.mark.slow
@pytest.mark.parametrize("sleep", [False, True])
def test_a_closed_elastic_frictionless_box_never_gains_energy_with_sleeping_on_or_off(sleep):
    # A layer of balls resting apart on the floor (they fall asleep after TIME_TO_SLEEP when sleeping
    # is on) and six balls flying above them; e = 1 and no friction anywhere, so no step may add
    # energy. Steps only lose it where slow arrivals stop (below the restitution threshold).
    from tests.physics.test_robustness import closed_box

    rng = np.random.default_rng(1)
    world = ballpit.World(sleep=sleep)
    closed_box(world, friction=0.0)
    r = 0.08
    layer = np.stack(np.meshgrid(np.arange(5), np.arange(5), indexing="ij"), -1).reshape(-1, 2) * 0.35 - 0.7
    world.add_spheres(np.column_stack((layer[:, 0], np.full(25, r), layer[:, 1])), radius=r, friction=0.0)
    above = np.column_stack((rng.uniform(-0.8, 0.8, 6), rng.uniform(1.0, 1.8, 6), rng.uniform(-0.8, 0.8, 6)))
    world.add_spheres(above, radius=r, friction=0.0, velocity=rng.normal(0, 1.0, (6, 3)))
    energy = world.kinetic_energy() + world.potential_energy()
    slept = 0
    for _ in range(720):
        world.step(DT)
        now = world.kinetic_energy() + world.potential_energy()
        assert now <= energy + 1e-12 * abs(energy)
        energy = now
        slept = max(slept, int(world.asleep.sum()))
    assert (slept >= 20) == sleep


@pytest.mark.slow
def test_the_bundled_pile_never_gains_energy_as_it_lands_settles_sleeps_and_is_woken():
    # pile.toml (sleep = true) lands, settles and falls asleep by about 3.9 s. No step may add
    # energy: not while it settles (a settled pile's soft springs lifted it as its load shifted, by up
    # to 1.6e-3 J in one frame at 2.8 s, more than its motion could pay), nor while it sleeps (the split
    # step once lifted a ball at rest out of the overlap the soft step had left it in: 1.7e-5 J in one
    # step). Woken, it may not end up above the energy it had when woken (its contacts' warm start used
    # to be forgotten while it slept, so it sagged and sprang back up: 0.37 J in one step). Free fall
    # exchanges potential for kinetic energy exactly but for rounding, 1e-13 of the two.
    scene = read_scene(resolve_scene_path("pile"))
    world, dt = scene.world, scene.timestep
    n = len(world.spheres)
    energy = world.kinetic_energy() + world.potential_energy()
    while world.asleep.sum() < 0.99 * n:
        world.step(dt)
        kinetic, potential = world.kinetic_energy(), world.potential_energy()
        assert kinetic + potential <= energy + 1e-12 * (kinetic + abs(potential)), (
            world.time,
            kinetic + potential - energy,
        )
        energy = kinetic + potential
        assert world.time < 6.0, "the pile falls asleep"
    for _ in range(30):
        world.step(dt)
        now = world.kinetic_energy() + world.potential_energy()
        assert now <= energy + 1e-12 * abs(energy), (world.time, now - energy)
        energy = now
    world.spheres[int(np.flatnonzero(world.asleep)[0])].velocity = (0.0, -0.01, 0.0)  # wakes its island
    woken = world.kinetic_energy() + world.potential_energy()
    world.step(dt)
    assert world.asleep.sum() < 0.5 * n, "woken"
    for _ in range(90):
        assert world.kinetic_energy() + world.potential_energy() <= woken + 1e-12 * abs(woken), world.time
        world.step(dt)


def test_a_sleeping_ball_struck_inside_a_step_is_woken_and_takes_the_strikers_momentum():
    """Three equal 1 kg balls on an elastic frictionless floor along x: A and B touching, S 5 cm past
    B. All sleep; then A is set moving at 6 m/s. A passes its speed to B at once (equal masses,
    e = 1), and B, 5 cm from S, strikes S 8 ms into the same 1/60 s step, beyond the
    reach the step's start foresaw (B was at rest then). Head-on between equal masses with e = 1 the
    struck ball leaves with the striker's speed and the striker stops: x momentum 6 kg·m/s, all of
    it S's. Held as a wall, S would throw B back into A."""
    world = ballpit.World(sleep=True)
    world.add_plane(restitution=1.0, friction=0.0)
    r, v = 0.15, 6.0
    x = [0.0, 2 * r, 4 * r + 0.05]  # A, B touching; S 5 cm beyond B, out of A's reach 2·v·dt = 0.2 m
    world.add_spheres([(xi, r, 0.0) for xi in x], radius=r, mass=1.0, restitution=1.0, friction=0.0)
    for _ in range(120):
        world.step(1 / 60)
    assert world.asleep.all()
    world.spheres[0].velocity = (v, 0.0, 0.0)
    world.step(1 / 60)
    vx = world.spheres.velocities[:, 0]
    assert not world.asleep[2]
    assert vx.sum() == pytest.approx(v, rel=1e-9)  # 1 kg each: the x momentum is kept
    assert vx[2] == pytest.approx(v, rel=1e-6)  # the struck ball leaves with the striker's speed
    assert np.abs(vx[:2]).max() < 1e-6 * v  # and the striker and the first ball stop
