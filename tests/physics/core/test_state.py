"""The state (state.py): one (N, 13) block of [x v q ω] rows that grows as balls are added, and a
checkpoint of it that puts back exactly what was there."""

from __future__ import annotations

import numpy as np

from ballpit.physics.core.state import STATE_WIDTH, Q, State, V, W, X


def test_the_block_grows_keeping_every_ball_and_its_columns_are_x_v_q_omega():
    state = State()
    first = state.reserve(3)
    first[:] = np.arange(3 * STATE_WIDTH).reshape(3, STATE_WIDTH)
    capacity = state.capacity
    state.reserve(capacity)  # beyond the room there was
    assert state.count == 3 + capacity and state.capacity >= state.count
    assert state.body[:3].tolist() == np.arange(39.0).reshape(3, 13).tolist()
    assert (X.stop, V.stop, Q.stop, W.stop) == (3, 6, 10, 13)


def test_removing_a_ball_moves_the_later_ones_up_and_wakes_everyone():
    state = State()
    state.reserve(4)[:, 0] = [0.0, 1.0, 2.0, 3.0]
    state.sleep.fit(4)
    state.remove(1)
    assert state.body[:, 0].tolist() == [0.0, 2.0, 3.0] and not state.sleep.any


def test_a_checkpoint_puts_back_the_balls_the_planes_and_the_time_even_after_balls_are_added():
    state = State()
    state.reserve(2)[:] = 1.0
    state.planes.reserve(1)
    state.planes.center[0] = (0.0, 2.0, 0.0)
    state.time = 1.5
    saved = state.checkpoint()
    state.body[:] = np.nan
    state.planes.center[0] = (9.0, 9.0, 9.0)
    state.reserve(5)
    state.time = 3.0
    state.restore(saved)
    assert state.count == 2 and (state.body == 1.0).all()
    assert state.planes.center.tolist() == [[0.0, 2.0, 0.0]] and state.time == 1.5
    state.restore(saved)  # it stays usable
    assert state.count == 2
