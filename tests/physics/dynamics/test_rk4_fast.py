"""RK4's fast path (rk4_fast.py) against the four-stage RK4 and the renormalisation it stands for:
the same bits for every ball."""

import numpy as np
import pytest

from ballpit.physics.core import quaternion
from ballpit.physics.core.settings import RK4_CHUNK
from ballpit.physics.core.state import Q, V, W, X
from ballpit.physics.dynamics.forces import ConstantPerBall, Gravity, constant_acceleration
from ballpit.physics.dynamics.integrators import Workspace, rk4, rk4_constant


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
