"""The sleep stages (step/sleep.py): ``wake`` owns the loop of waking what the awake balls reach and
measuring again, and returns what it measured; ``settle`` puts still islands to sleep."""

from __future__ import annotations

import ballpit
from ballpit.physics.core.settings import TIME_TO_SLEEP
from ballpit.physics.step import plan, settle, solve, wake
from ballpit.physics.step.checkpoint import Checkpoint

from .stages import prepared

DT = 1 / 240


def sleeping_ball_and_a_falling_one(height: float) -> ballpit.World:
    """Without gravity: a ball asleep on the floor, and one coming down at 2 m/s, now ``height`` above
    it (its bottom to the sleeper's top)."""
    world = ballpit.World(gravity=(0, 0, 0), sleep=True)
    world.add_plane()
    steps = round(TIME_TO_SLEEP / DT) + 60  # asleep well before the other comes within reach
    world.add_spheres([(0, 0.1, 0), (0, 0.3 + height + 2.0 * steps * DT, 0)], radius=0.1)
    world.spheres[1].velocity = (0, -2.0, 0)
    for _ in range(steps):
        world.step(DT)
    assert world.asleep.tolist() == [True, False]
    return world


def test_wake_wakes_the_island_a_ball_could_reach_in_the_step_and_measures_its_pairs_again():
    # 12 mm apart: within twice the 8.3 mm it closes in a step (SPECULATIVE_REACH), not within it the
    # step before
    world = sleeping_ball_and_a_falling_one(0.012)
    awake = wake(prepared(world, DT))
    assert not world.asleep.any()
    assert awake.motion.awake is None  # the motion and the collision are those with it awake
    pairs = awake.collision.pairs
    assert 0 in pairs.sphere.tolist()  # the woken ball's floor contact is measured
    assert {(int(i), int(j)) for i, j in zip(pairs.pair_i, pairs.pair_j, strict=True)} == {(0, 1)}
    a, b = awake.links  # the pair that joins their island
    assert (a.tolist(), b.tolist()) == ([0], [1])


def test_wake_leaves_asleep_what_no_ball_reaches_in_the_step():
    world = sleeping_ball_and_a_falling_one(1.0)
    awake = wake(prepared(world, DT))
    assert world.asleep.tolist() == [True, False]
    assert awake.motion.awake.tolist() == [False, True]
    assert 0 not in awake.collision.pairs.sphere.tolist()


def test_with_sleeping_off_wake_measures_once_and_keeps_no_island_links():
    world = ballpit.World()
    world.add_plane()
    world.add_sphere(position=(0, 0.1, 0), radius=0.1)
    awake = wake(prepared(world, DT))
    assert awake.links is None and len(awake.collision.contacts) == 1


def test_settle_puts_a_still_island_to_sleep_and_its_warm_start_aside():
    world = ballpit.World(sleep=True)
    world.add_plane()
    world.add_spheres([(0, 0.1, 0), (0.2, 0.1, 0)], radius=0.1)
    twin, steps = world.copy(), 0  # how many steps it takes to fall asleep (about TIME_TO_SLEEP's)
    while not twin.asleep.any():
        twin.step(DT)
        steps += 1
    assert abs(steps * DT - TIME_TO_SLEEP) <= 2 * DT
    for _ in range(steps - 1):
        world.step(DT)
    # the last step, stage by stage: still awake after the solve, asleep after settle
    step = prepared(world, DT)
    awake = wake(step)
    chosen = plan(step, awake.collision, awake.motion)
    solve(step, awake, chosen, Checkpoint.of(world.parts))
    assert not world.asleep.any() and len(world.parts.warm.keys) == 3
    settle(step, awake)
    assert world.asleep.all()
    assert len(world.parts.warm.asleep[0]) == 3  # the three contacts' warm start, put aside


def two_balls_asleep_on_a_floor() -> ballpit.World:
    world = ballpit.World(sleep=True)
    world.add_plane()
    world.add_spheres([(0, 0.1, 0), (0.5, 0.1, 0)], radius=0.1)
    for _ in range(round(TIME_TO_SLEEP / DT) + 60):
        world.step(DT)
    assert world.asleep.all()
    return world


def parts_bytes(world: ballpit.World) -> dict:
    """Every part a step reads or writes, pickled field by field (the time apart)."""
    import pickle

    state = world.parts.state
    out = {name: pickle.dumps(value) for name, value in vars(state).items() if name != "time"}
    out |= {"pairs": pickle.dumps(world.parts.pairs), "warm": pickle.dumps(world.parts.warm)}
    return out | {"model": pickle.dumps(world.model)}


def test_a_world_at_rest_is_stepped_as_the_full_stages_step_it_with_only_the_time_moving():
    from ballpit.physics import step as pipeline

    world = two_balls_asleep_on_a_floor()
    full = ballpit.World()
    full.restore(world.snapshot())
    before = parts_bytes(world)
    for _ in range(50):
        assert pipeline.at_rest(prepared(world, DT))
        assert len(world.step(DT)) == 0  # no contact resolved
        step = prepared(full, DT)  # every stage, as a world with a ball awake is stepped
        taken = pipeline.take(step)
        settle(taken.step, taken.awake)
        pipeline.finish(taken.step, taken.checkpoint, taken.plan, len(taken.awake.collision.pairs))
    assert parts_bytes(world) == parts_bytes(full) == before
    assert world.time == full.time  # the same sum of the same steps
    assert world.profile.pairs == 0


def test_a_world_at_rest_wakes_when_a_ball_is_set_moving_or_added_or_a_plane_moves():
    from ballpit.physics import step as pipeline

    world = two_balls_asleep_on_a_floor()
    world.spheres[1].velocity = (1.0, 0.0, 0.0)
    assert not pipeline.at_rest(prepared(world, DT))
    x = world.spheres[1].position[0]
    world.step(DT)
    assert world.spheres[1].position[0] > x and not world.asleep[1]  # the by-hand push moves it
    world = two_balls_asleep_on_a_floor()
    world.add_sphere(position=(0, 1.0, 0), radius=0.1)
    assert not pipeline.at_rest(prepared(world, DT))  # the new ball is awake: it falls
    world.step(DT)
    assert world.spheres[2].velocity[1] < 0.0
    world = two_balls_asleep_on_a_floor()
    world.planes[0].velocity = (0.0, 0.1, 0.0)
    assert not pipeline.at_rest(prepared(world, DT))
