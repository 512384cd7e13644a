"""The landing grid every engine runs: balls on a grid falling into a box, and what is measured of it.

The workload is ``ballpit bench --workload pile``'s: ``n`` balls of radius 0.05 m and 1 kg on a grid
0.11 m apart (a little jitter, so the pile does not stack in perfect columns) above a floor at y = 0,
inside four walls, under g = 9.81 m/s² along −y. Every contact, ball on ball or ball on a wall, has
restitution 0.25 and Coulomb friction 0.25 and no rolling resistance; each engine's adapter says how
its own rule for mixing two bodies' materials gets there.

The measures are taken from positions and velocities alone, the same way for every engine, so they
do not trust any engine's own contact report.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RADIUS = 0.05  # m
MASS = 1.0  # kg
SPACING = 0.11  # m between grid points: balls start 1 cm apart
GRAVITY = 9.81  # m/s², along −y (y is up in every engine here)
DT = 1 / 240  # s: every engine solves its contacts this often
RESTITUTION = 0.25  # of every contact
FRICTION = 0.25  # Coulomb coefficient of every contact


def pile_layout(n: int, seed: int = 1) -> tuple[np.ndarray, float]:
    """``n`` ball centres on a grid 0.11 m apart above a floor at y = 0, and the box's half width."""
    side = int(np.ceil(np.sqrt(n / max(1, round(n ** (1 / 3))))))
    layers = int(np.ceil(n / (side * side)))
    ix, iy, iz = np.meshgrid(np.arange(side), np.arange(layers), np.arange(side), indexing="ij")
    cells = np.stack((ix.ravel(), iy.ravel(), iz.ravel()), axis=1)
    cells = cells[np.lexsort((cells[:, 2], cells[:, 0], cells[:, 1]))][:n]  # fill bottom layers first
    half = 0.5 * side * SPACING + RADIUS
    jitter = np.random.default_rng(seed).uniform(-0.002, 0.002, (n, 3))
    centres = (cells - [0.5 * (side - 1), 0.0, 0.5 * (side - 1)]) * SPACING + [0.0, 2 * RADIUS, 0.0] + jitter
    return centres, half


@dataclass(frozen=True)
class Landing:
    """Where the balls start, how fast (None: at rest), and how wide the box is (walls at x, z = ±half)."""

    centres: np.ndarray
    half: float
    velocities: np.ndarray | None = None

    @classmethod
    def of(cls, n: int) -> Landing:
        centres, half = pile_layout(n)
        return cls(centres, half)

    @property
    def n(self) -> int:
        return len(self.centres)


def pair_overlaps(positions: np.ndarray, radius: float) -> np.ndarray:
    """2r − d for every pair of balls closer than 2r (equal radii), from a grid of cells 2r wide.

    Two balls that touch have centres in the same or neighbouring cells, so each ball is checked
    against the balls of its 27 cells; each pair is kept once (i < j).
    """
    n = len(positions)
    if n < 2:
        return np.zeros(0)
    cell = np.floor(positions / (2 * radius)).astype(np.int64)
    cell -= cell.min(axis=0) - 1  # every cell index ≥ 1, so a neighbour's is ≥ 0 ...
    dims = cell.max(axis=0) + 2  # ... and < dims: keys of distinct cells never alias
    key = (cell[:, 0] * dims[1] + cell[:, 1]) * dims[2] + cell[:, 2]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    found = [np.zeros(0)]
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                target = key + (dx * dims[1] + dy) * dims[2] + dz
                lo = np.searchsorted(sorted_key, target, side="left")
                counts = np.searchsorted(sorted_key, target, side="right") - lo
                i = np.repeat(np.arange(n), counts)
                starts = np.repeat(lo - (np.cumsum(counts) - counts), counts)
                j = order[starts + np.arange(len(i))]
                keep = i < j
                i, j = i[keep], j[keep]
                gap = positions[i] - positions[j]
                d = np.sqrt(np.sum(gap * gap, axis=1))
                found.append((2 * radius - d)[d < 2 * radius])
    return np.concatenate(found)


def wall_overlaps(positions: np.ndarray, radius: float, half: float) -> np.ndarray:
    """r minus each ball's distance to the floor and to the nearest wall (positive: overlapping)."""
    distance = np.minimum(
        positions[:, 1], half - np.maximum(np.abs(positions[:, 0]), np.abs(positions[:, 2]))
    )
    return radius - distance


def max_overlap(positions: np.ndarray, radius: float, half: float) -> float:
    """The deepest overlap of any ball with another ball, the floor or a wall, as a fraction of r.

    0 when nothing overlaps; inf when a position is not finite (the engine blew up).
    """
    if not np.all(np.isfinite(positions)):
        return float("inf")
    deepest = max(0.0, float(wall_overlaps(positions, radius, half).max(initial=0.0)))
    deepest = max(deepest, float(pair_overlaps(positions, radius).max(initial=0.0)))
    return deepest / radius


def inside_box(positions: np.ndarray, half: float) -> int:
    """How many balls have their centres inside the box: above the floor and between the walls."""
    ok = np.isfinite(positions).all(axis=1)
    ok &= positions[:, 1] > 0
    ok &= np.maximum(np.abs(positions[:, 0]), np.abs(positions[:, 2])) < half
    return int(np.count_nonzero(ok))


def max_speed(velocities: np.ndarray) -> float:
    """The fastest ball's speed (m/s); inf when a velocity is not finite."""
    if not np.all(np.isfinite(velocities)):
        return float("inf")
    return float(np.sqrt(np.sum(velocities * velocities, axis=1)).max(initial=0.0))
