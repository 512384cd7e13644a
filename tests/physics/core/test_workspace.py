"""The workspace (workspace.py): a scratch array asked for again by name and shape is the same array,
so a step's hot path allocates nothing new."""

from __future__ import annotations

from ballpit.physics.core.workspace import Workspace


def test_the_same_name_and_shape_hand_back_the_same_array_and_another_shape_a_new_one():
    ws = Workspace()
    first = ws.get("k1", (10, 13))
    assert ws.get("k1", (10, 13)) is first
    assert ws.get("k1", (11, 13)) is not first and ws.get("k2", (10, 13)) is not first
    assert first.shape == (10, 13)


def test_stale_shapes_are_dropped_as_balls_are_added_so_it_never_grows_without_bound():
    ws = Workspace()
    for n in range(1000):
        ws.get("k1", (n, 13))
    assert len(ws._buffers) <= 65
