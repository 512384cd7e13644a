"""Penetration removal (penetration.py): overlapping balls are moved apart by positions alone, each in
proportion to its inverse mass, all contacts at once (``separate``) or colour by colour."""

import numpy as np
import pytest

from ballpit.physics.contact import penetration

from .test_jacobi import R, column


def test_separation_puts_an_overlapping_column_exactly_touching():
    n = 20
    rows = column(n)
    squeeze = 0.01  # every contact overlaps by 1 cm
    y = R + np.arange(n) * (2 * R - squeeze)
    pos = np.zeros((n + 1, 3))
    pos[:n, 1] = y
    gap = np.r_[y[0] - R, np.diff(y) - 2 * R]
    penetration.separate(rows.a, rows.b, rows.normal, gap, rows.inv_mass_a, rows.inv_mass_b, pos, 20_000)
    assert pos[:n, 1] == pytest.approx(R + 2 * R * np.arange(n), abs=1e-9)  # the floor does not move
    assert np.abs(pos[:n, [0, 2]]).max() == 0.0
