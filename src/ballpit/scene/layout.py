"""Grid layout: where the balls of a ``[[grid]]`` block go, and how they are named in messages."""

from __future__ import annotations

import numpy as np


def grid_positions(
    count: tuple[int, int, int],
    spacing: np.ndarray,
    corner: np.ndarray | None = None,
    center: np.ndarray | None = None,
) -> np.ndarray:
    """(nx·ny·nz, 3) ball centres in x-major order, from the first ball's centre or the block's centre."""
    idx = np.indices(count).reshape(3, -1).T.astype(float)
    offsets = idx * spacing
    if center is not None:
        corner = center - 0.5 * (np.array(count) - 1) * spacing
    return corner + offsets


def reach(
    count: tuple[int, int, int],
    spacing: np.ndarray,
    corner: np.ndarray | None = None,
    center: np.ndarray | None = None,
) -> float:
    """How far from the origin (largest coordinate) the block's centres go, before any jitter."""
    extent = (np.array(count) - 1) * spacing
    first = center - 0.5 * extent if center is not None else corner
    return float(np.maximum(np.abs(first), np.abs(first + extent)).max())


def jitter(
    positions: np.ndarray, velocity: np.ndarray, amount: float, velocity_amount: float, seed: int
) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities with seeded uniform noise: the same file always gives the same balls.

    Positions draw first, then velocities, each only when its amount is positive.
    """
    rng = np.random.default_rng(seed)
    if amount > 0:
        positions = positions + rng.uniform(-amount, amount, size=positions.shape)
    if velocity_amount > 0:
        velocity = velocity + rng.uniform(-velocity_amount, velocity_amount, size=(len(positions), 3))
    return positions, velocity


def crowded_axis(count: tuple[int, int, int], spacing: np.ndarray, need: float) -> int | None:
    """The first axis along which neighbouring centres are closer than ``need``, or None."""
    for axis in range(3):
        if count[axis] > 1 and spacing[axis] < need * (1 - 1e-12):
            return axis
    return None


def ball_name(count: tuple[int, int, int], k: int) -> str:
    """Ball ``k`` of a block as ``ball [i, j, m]``."""
    i, j, m = np.unravel_index(k, count)
    return f"ball [{i}, {j}, {m}]"
