"""Contact ends (ends.py): the balls K contacts touch, numbered compactly in increasing order, each
ball's share of contacts, and per-end values added back per ball in the order they come."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.physics.contact.ends import Ends


@pytest.mark.parametrize("world", [9, 10_000])  # a table over the world, or a sort of few contacts
def test_ends_number_the_touched_balls_compactly_and_share_each_by_its_contacts(world):
    a, b = np.array([5, 2, 5]), np.array([7, 5, world - 1])
    ends = Ends(a, b)
    assert ends.balls.tolist() == [2, 5, 7, world - 1]
    assert ends.balls[ends.ends].tolist() == [5, 2, 5, 7, 5, world - 1]
    assert ends.share.tolist() == [1.0, 3.0, 1.0, 1.0]


def test_adding_up_many_rows_at_once_gives_each_rows_own_sums_bit_for_bit():
    rng = np.random.default_rng(9)
    a, b = rng.integers(0, 50, 200), rng.integers(50, 100, 200)
    ends = Ends(a, b)
    values = rng.normal(size=(5, 400)) * 10.0 ** rng.integers(-8, 8, (5, 400))
    summed = ends.add_up(values)
    for r in range(5):
        assert summed[r].tobytes() == ends.add_row(values[r]).tobytes()
        expected = np.zeros(ends.m)
        for k, e in enumerate(ends.ends):  # in the order the ends come
            expected[e] += values[r, k]
        assert summed[r].tobytes() == expected.tobytes()
