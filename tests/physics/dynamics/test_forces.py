"""Force terms (forces.py): gravity, linear and angular drag and a per-ball constant add the
accelerations their laws give, and the shortcut for state-free terms gives the same bits."""

from __future__ import annotations

import numpy as np

from ballpit.physics.core.state import V, W
from ballpit.physics.dynamics.forces import (
    AngularDrag,
    ConstantPerBall,
    Gravity,
    LinearDrag,
    column_accelerations,
    constant_acceleration,
    forces_of,
    free_acceleration,
)


def body(n: int = 4, seed: int = 0) -> np.ndarray:
    b = np.random.default_rng(seed).normal(size=(n, 13))
    return b


def test_drag_opposes_velocity_and_spin_in_proportion_and_gravity_adds_g():
    b = body()
    g = np.array([0.0, -9.81, 0.0])
    lin, ang = free_acceleration(b, [Gravity(g), LinearDrag(0.5), AngularDrag(2.0)])
    assert np.array_equal(lin, g - 0.5 * b[:, V])
    assert np.array_equal(ang, -2.0 * b[:, W])


def test_state_free_terms_add_up_once_to_the_same_bits_every_stage_would_see():
    b = body()
    per_ball = ConstantPerBall(np.random.default_rng(1).normal(size=(4, 3)), np.ones((4, 3)))
    terms = [Gravity(np.array([0.1, -9.81, 0.3])), per_ball]
    lin, ang = free_acceleration(b, terms)
    slow_lin, slow_ang = np.zeros((4, 3)), np.zeros((4, 3))
    for term in terms:
        term.add(b, slow_lin, slow_ang)
    assert lin.tobytes() == slow_lin.tobytes() and ang.tobytes() == slow_ang.tobytes()
    assert constant_acceleration([*terms, LinearDrag(1.0)]) is None  # drag depends on the state


def test_the_terms_of_some_balls_are_cut_down_to_their_rows():
    per_ball = ConstantPerBall(np.arange(12.0).reshape(4, 3), np.zeros((4, 3)))
    gravity = Gravity(np.array([0.0, -1.0, 0.0]))
    cut = forces_of([gravity, per_ball], np.array([1, 3]), 4)
    assert cut[0] is gravity and cut[1].lin.tolist() == [[3.0, 4.0, 5.0], [9.0, 10.0, 11.0]]


def test_columns_see_the_same_accelerations_as_rows():
    b = body(5)
    terms = [Gravity(np.array([0.0, -9.81, 0.0])), LinearDrag(0.3), AngularDrag(0.7)]
    lin, ang = free_acceleration(b, terms)
    col_lin, col_ang = column_accelerations(
        terms, None, b[:, 0:3].T, np.vstack((b[:, V].T, b[:, W].T)), b[:, 6:10]
    )
    assert np.array_equal(col_lin, lin.T) and np.array_equal(col_ang, ang.T)
