"""World.snapshot / restore / copy: stepping on from a snapshot repeats the run bit for bit."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit.scene import load_scene

SCENES = Path(__file__).resolve().parents[2] / "scenes"
DT = 1 / 240


def run_hash(world: ballpit.World, steps: int) -> str:
    """Step ``world`` and hash every contact it returns and its final state."""
    digest = hashlib.sha256()
    for _ in range(steps):
        c = world.step(DT)
        for column in (c.time, c.a, c.b, c.normal, c.impulse):
            digest.update(np.ascontiguousarray(column).tobytes())
    digest.update(world.state.body.tobytes())
    digest.update(np.float64(world.time).tobytes())
    return digest.hexdigest()


# slopes: impacts, rolling and resting on finite planes; cradle: momentum through touching balls;
# pile: a crowded landing with warm-started resting contacts and kept pairs.
@pytest.mark.parametrize(("scene", "before", "after"), [("slopes", 200, 240), ("cradle", 100, 240),
                                                        ("pile", 100, 30)])  # fmt: skip
def test_restoring_a_snapshot_repeats_the_run_bit_for_bit(scene, before, after):
    world = load_scene(SCENES / f"{scene}.toml")
    for _ in range(before):
        world.step(DT)
    snap = world.snapshot()
    first = run_hash(world, after)
    world.restore(snap)
    assert run_hash(world, after) == first
    world.restore(snap)  # a snapshot can be restored again
    assert run_hash(world, after) == first


def test_a_copy_steps_on_exactly_like_the_original_and_independently():
    world = load_scene(SCENES / "slopes.toml")
    for _ in range(200):
        world.step(DT)
    twin = world.copy()
    assert run_hash(twin, 240) == run_hash(world, 240)
    t = world.time
    twin.step(DT)
    twin.spheres[0].position = (9.0, 9.0, 9.0)
    assert world.time == t and not np.allclose(world.spheres[0].position, (9.0, 9.0, 9.0))


def test_restore_brings_back_balls_planes_parameters_and_time_after_changes():
    world = ballpit.World()
    world.add_plane(normal=(0, 1, 0))
    world.add_sphere(position=(0, 1, 0), radius=0.2)
    for _ in range(120):
        world.step(DT)
    snap = world.snapshot()
    expected = run_hash(world.copy(), 120)
    world.add_spheres([[1, 1, 0], [2, 1, 0]], radius=0.1)  # more balls than the snapshot had
    world.add_plane(position=(0, 0.5, 0), size=1.0)
    world.integrator, world.gravity = "euler", (0, -1, 0)
    world.spheres[0].velocity = (5, 0, 0)
    world.restore(snap)
    assert (len(world.spheres), len(world.planes), world.integrator) == (1, 1, "rk4")
    assert world.gravity == pytest.approx((0, -9.81, 0))
    assert run_hash(world, 120) == expected


def test_restore_refuses_what_is_not_a_snapshot():
    with pytest.raises(TypeError, match="Snapshot"):
        ballpit.World().restore({"time": 0})
