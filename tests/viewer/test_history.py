"""The viewer's history: seeking to step k gives exactly (bit for bit) the state the run had at step k."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit.viewer.history import History

SCENES = Path(__file__).resolve().parents[2] / "scenes"
DT = 1 / 240


def state_bytes(world: ballpit.World) -> bytes:
    return world.state.body.tobytes() + np.float64(world.time).tobytes()


def record_run(world: ballpit.World, history: History, steps: int, switch: dict | None = None) -> list:
    """Step live, telling the history, and keep every state the run passed through."""
    states = [state_bytes(world)]
    for k in range(steps):
        if switch and k in switch:
            world.integrator = switch[k]
        world.step(DT)
        history.recorded(world.integrator)
        states.append(state_bytes(world))
    return states


@pytest.mark.parametrize("scene", ["slopes", "cradle"])
def test_seeking_any_step_gives_the_run_state_bit_for_bit(scene):
    world = ballpit.load_scene(SCENES / f"{scene}.toml")
    history = History(world, DT, keep_seconds=30.0, anchor_seconds=0.1)  # an anchor every 24 steps
    states = record_run(world, history, 150)
    for k in [149, 0, 1, 23, 24, 25, 100, 60, 61, 62, 150, 7]:  # back, forward, across anchors
        assert history.seek(k) == k
        assert state_bytes(world) == states[k], k
    # stepping back one at a time from the end
    history.seek(150)
    for k in range(150, 120, -1):
        assert history.step_by(-1) == k - 1
        assert state_bytes(world) == states[k - 1]


def test_re_stepping_uses_the_integrator_each_step_had():
    world = ballpit.load_scene(SCENES / "slopes.toml")
    history = History(world, DT, anchor_seconds=0.5)  # 120 steps between anchors
    states = record_run(world, history, 100, switch={10: "euler", 40: "rk2", 70: "rk4"})
    for k in (5, 30, 55, 99, 0, 100):
        history.seek(k)
        assert state_bytes(world) == states[k], k


def test_only_the_last_keep_seconds_are_kept_and_always_reachable():
    world = ballpit.load_scene(SCENES / "cradle.toml")
    history = History(world, DT, keep_seconds=0.25, anchor_seconds=0.05)  # 60 steps kept, anchor every 12
    states = record_run(world, history, 200)
    assert history.latest == 200
    assert 200 - 60 - 12 < history.first <= 200 - 60
    assert history.memory_anchors() <= 60 // 12 + 2
    assert history.seek(0) == history.first  # clamped to the span
    assert state_bytes(world) == states[history.first]
    assert history.seek(500) == 200 and state_bytes(world) == states[200]


def test_stepping_live_from_the_past_drops_the_future_and_re_records():
    world = ballpit.load_scene(SCENES / "slopes.toml")
    reference = world.copy()
    history = History(world, DT, anchor_seconds=0.1)
    record_run(world, history, 120)
    history.seek(50)
    assert history.in_past
    world.integrator = "euler"  # a different future from step 50
    world.step(DT)
    history.recorded(world.integrator)
    assert history.latest == 51 and not history.in_past
    world.integrator = "rk4"
    states = record_run(world, history, 30)
    history.seek(60)
    assert state_bytes(world) == states[9]
    # the new timeline equals a straight run with the same integrators, bit for bit
    for k in range(81):
        reference.integrator = "euler" if k == 50 else "rk4"
        reference.step(DT)
        if k == 59:
            assert state_bytes(reference) == state_bytes(world)


def test_a_change_by_hand_becomes_an_anchor():
    world = ballpit.load_scene(SCENES / "slopes.toml")
    history = History(world, DT, anchor_seconds=0.1)
    record_run(world, history, 50)
    history.seek(30)
    world.spheres[0].velocity = (0.0, 5.0, 0.0)
    history.changed()
    assert history.latest == 30
    changed = state_bytes(world)
    states = record_run(world, history, 20)
    assert states[0] == changed
    history.seek(35)
    assert state_bytes(world) == states[5]
    history.seek(30)
    assert state_bytes(world) == changed


def test_scenes_with_many_balls_space_their_snapshots_wider():
    world = ballpit.World()
    world.add_spheres(np.column_stack([np.arange(20_000.0), np.ones(20_000), np.zeros(20_000)]), radius=0.1)
    history = History(world, DT)  # 30 s × 20,000 balls over a budget of 500,000 ball-states: 1.2 s
    assert history.every == round(1.2 / DT)
    assert History(ballpit.load_scene(SCENES / "slopes.toml"), DT).every == round(0.25 / DT)
