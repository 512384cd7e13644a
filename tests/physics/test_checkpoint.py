"""One transaction for a step (checkpoint.py): a checkpoint holds every part a step changes, and both
undos of a step (a soft frame's retry, a non-finite step) put every one of them back, moving planes
included."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.step import soft
from ballpit.physics.step.checkpoint import Checkpoint, Parts
from ballpit.scene import load_scene, resolve_scene_path

G = 9.81


def rising_floor_world() -> ballpit.World:
    """An elevator floor rising at 0.5 m/s with a ball resting on it and two more falling onto it."""
    world = ballpit.World()
    world.add_plane(size=4.0, velocity=(0, 0.5, 0), friction=0.3)
    world.add_sphere(position=(0, 0.1, 0), radius=0.1)
    world.add_spheres([(0.5, 0.3, 0), (-0.5, 0.25, 0.2)], radius=0.1, velocity=(0, -1.0, 0))
    return world


def parts_bytes(parts: Parts) -> list[bytes]:
    """Everything a step can change, as bytes: ball states, plane poses, time, sleep, kept pairs and warm
    start."""
    state, sleep, warm, kept = parts.state, parts.state.sleep, parts.warm, parts.pairs.kept
    arrays = [state.body, *(getattr(state.planes, k) for k in ("center", "orientation", "normal"))]
    arrays += [np.float64(state.time), sleep.rest, sleep.asleep, sleep.island, sleep.pose]
    arrays += [warm.keys, warm.forces.normal, warm.forces.friction, warm.apart, *warm.asleep[:1]]
    if kept is not None:
        arrays += [kept.lo, kept.hi, kept.pair_i, kept.pair_j, kept.sphere, kept.plane, kept.side]
    return [np.ascontiguousarray(a).tobytes() for a in arrays]


def test_a_checkpoint_puts_back_every_part_a_run_of_steps_changed_and_can_be_restored_again():
    world = load_scene(resolve_scene_path("pile"))
    for _ in range(40):
        world.step(1 / 60)
    checkpoint = Checkpoint.of(world.parts)
    before = parts_bytes(world.parts)
    for _ in range(10):
        world.step(1 / 60)
    assert parts_bytes(world.parts) != before
    checkpoint.restore(world.parts)
    assert parts_bytes(world.parts) == before
    world.step(1 / 60)
    checkpoint.restore(world.parts)
    assert parts_bytes(world.parts) == before


def test_a_step_undone_for_leaving_the_steppable_range_puts_a_moving_plane_back_where_it_began():
    # step(1e6) lets a ball beside the floor fall 4.9e12 m: the step is undone, and so is the plane's
    # climb of 1e6 m.
    world = rising_floor_world()
    world.add_sphere(position=(10, 1, 0), radius=0.1)
    world.step(1 / 240)
    centre, state, time = world.planes[0].position.copy(), world.state.body.copy(), world.time
    with pytest.raises(ValueError, match="undone"):
        world.step(1e6)
    assert np.array_equal(world.planes[0].position, centre)
    assert np.array_equal(world.state.body, state) and world.time == time
    world.step(1 / 240)  # and the world steps on from there
    assert world.planes[0].position[1] == pytest.approx(centre[1] + 0.5 / 240, rel=1e-12)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the overflow the step is undone for
def test_a_step_made_non_finite_puts_a_turning_plane_back_where_it_began():
    # a drag of 1e300 /s on a ball flying at 1 m/s overflows its deceleration to inf: the step is undone,
    # and so is the turn of the plane
    world = rising_floor_world()
    world.planes[0].velocity = (0, 0, 0)
    world.planes[0].angular_velocity = (0, 0, 0.1)
    world.add_sphere(position=(10, 1, 0), radius=0.1, velocity=(1, 0, 0))
    world.linear_drag = 1e300
    orientation = world.planes[0].orientation.copy()
    with pytest.raises(FloatingPointError, match="undone"):
        world.step(1 / 240)
    assert np.array_equal(world.planes[0].orientation, orientation)


def test_a_soft_frame_undone_and_retried_moves_a_rising_floor_once_and_lands_as_a_frame_of_twice_the_substeps(
    monkeypatch,
):
    # A step with any meeting is a soft frame (crowd_limit 0): the first try of the landing frame is
    # judged untrustworthy, so it is undone and tried with twice the substeps. The retry starts from
    # where the step began, floor included: the floor rises by v·dt once in the step, and the balls end
    # exactly where a world whose first try has twice the substeps puts them (the steps before the
    # landing are split at impacts, which the substeps do not change).
    dt = 1 / 60
    tried, retried = rising_floor_world(), rising_floor_world()
    for world, substeps in ((tried, 2), (retried, 4)):
        world.crowd_limit = 0
        world.substeps = substeps
    judged = []
    real = soft.verdict

    def first_try_untrusted(*args):
        judged.append(real(*args))
        return soft.Verdict.MOVED_TOO_FAR if len(judged) == 1 else judged[-1]

    monkeypatch.setattr(soft, "verdict", first_try_untrusted)
    while not judged:
        floor = tried.planes[0].position.copy()
        tried.step(dt)
        if not judged:
            retried.step(dt)
    monkeypatch.undo()
    retried.step(dt)
    assert len(judged) == 2 and judged[1] is soft.Verdict.KEPT  # the retry was a frame, and kept
    assert tried.crowded_steps == retried.crowded_steps == 1
    assert tried.planes[0].position[1] == floor[1] + 0.5 * dt
    assert np.array_equal(tried.planes[0].position, retried.planes[0].position)
    assert np.array_equal(tried.state.body, retried.state.body)
