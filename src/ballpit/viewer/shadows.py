"""Ball shadows and contact darkening on the planes: the balls binned in a grid seen from the sun.

A ball shades a point p of a plane in two ways. It blocks the sun when the ray from p towards the sun
passes within its radius (a soft edge: the sun is a disc, not a point), and it darkens the ambient
light when it is close, by the cosine-weighted part of the sky it hides, (r/l)²·cos θ (contact
darkening, so a ball resting on the floor sits on a dark spot). Both are exact for spheres and are
computed in the plane shader. Neither reaches farther than ``REACH`` radii from the ball's centre
measured across the sun's direction, so each plane fragment only needs the balls near its own ray.

Every frame the balls are binned into a 2-D grid on a plane perpendicular to the sun: a ball goes
into every cell its reach overlaps (at most 2 x 2, as a cell is at least as wide as the widest reach),
nearest the sun first, and at most ``LIMIT`` balls per cell are kept. A fragment projects its position
into the grid and reads its one cell (one fetch of the cell's range, then its balls), so its cost is
bounded by ``LIMIT`` whatever the number of balls. Cells are only crowded inside piles, where the balls
nearest the sun (kept first) are the ones that shade whatever can be seen. No GL here: the arrays go
into two texture buffers (see renderer.py).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

SUN_DIRECTION = np.array([0.35, 0.85, 0.40]) / np.linalg.norm([0.35, 0.85, 0.40])  # towards the sun
REACH = 2.5  # ball radii, across the sun direction, beyond which a ball neither shadows nor darkens
LIMIT = 12  # balls kept per cell: the most a fragment reads
MAX_CELLS = 65_535  # cells in the grid at most (about 256 x 256; a cell number fits 16 bits)


@functools.lru_cache(maxsize=8)
def _basis(direction: tuple[float, float, float]) -> np.ndarray:
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    helper = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, d)
    u /= np.linalg.norm(u)
    axes = np.stack([u, np.cross(d, u)])
    axes.flags.writeable = False
    return axes


def sun_basis(direction: np.ndarray = SUN_DIRECTION) -> np.ndarray:
    """Two unit vectors (2, 3) perpendicular to the sun direction and to each other: the grid axes."""
    return _basis(tuple(float(v) for v in np.asarray(direction).reshape(3)))


@dataclass
class ShadowGrid:
    """The balls binned by cell, ready to upload.

    ``balls`` (E, 4) float32 holds centre and radius, grouped by cell, nearest the sun first within a
    cell; cell k's balls are ``balls[ranges[k, 0]:ranges[k, 1]]``. Cell (i, j) is number j·nx + i and
    covers grid coordinates [i, i + 1) x [j, j + 1), where a point p has grid coordinates
    (axes @ p − origin) / cell_size.
    """

    axes: np.ndarray  # (2, 3) grid axes in the world
    origin: np.ndarray  # (2,) grid coordinates of the corner of cell (0, 0), metres
    cell_size: float
    shape: tuple[int, int]  # (nx, ny) cells
    ranges: np.ndarray  # (nx·ny, 2) int32: first and end row of each cell's balls
    balls: np.ndarray  # (E, 4) float32
    dropped: int = 0  # balls left out of crowded cells

    @property
    def cells(self) -> int:
        return self.shape[0] * self.shape[1]


def empty_grid(direction: np.ndarray = SUN_DIRECTION) -> ShadowGrid:
    return ShadowGrid(
        sun_basis(direction),
        np.zeros(2),
        1.0,
        (0, 0),
        np.zeros((0, 2), np.int32),
        np.zeros((0, 4), np.float32),
    )


def build(
    positions: np.ndarray,
    radii: np.ndarray,
    direction: np.ndarray = SUN_DIRECTION,
    reach: float = REACH,
    limit: int = LIMIT,
    max_cells: int = MAX_CELLS,
) -> ShadowGrid:
    """Bin balls (centres (N, 3), radii (N,)) into the sun's grid; whole-array NumPy, no loop per ball."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    n = len(positions)
    if n == 0:
        return empty_grid(direction)
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (n,))
    axes = sun_basis(direction)
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    # nearest the sun first, so a crowded cell keeps the balls that shade what can be seen
    by_sun = np.argsort(-(positions @ d))
    flat = axes @ positions[by_sun].T  # (2, N) across the sun; rows, as reductions along rows are fast
    spread = reach * radii[by_sun]
    low = (flat - spread).min(axis=1)
    extent = np.maximum((flat + spread).max(axis=1) - low, 1e-9)
    cell = max(2.0 * float(spread.max()), float(np.sqrt(extent[0] * extent[1] / max_cells)), 1e-6)
    shape = np.floor(extent / cell).astype(np.int64) + 1
    while shape[0] * shape[1] > max_cells:  # a long thin spread: widen the cells
        cell *= 1.25
        shape = np.floor(extent / cell).astype(np.int64) + 1
    cells = int(shape[0] * shape[1])
    first = [np.floor((flat[k] - spread - low[k]) / cell).astype(np.int64) for k in (0, 1)]
    last = [np.minimum(((flat[k] + spread - low[k]) / cell).astype(np.int64), shape[k] - 1) for k in (0, 1)]
    # a ball's reach covers at most 2 x 2 cells (a cell is at least as wide as the widest reach): four
    # candidates per ball, those outside its span go to an extra bin (number ``cells``) that is
    # dropped. A stable sort by cell (a radix sort on 16 bits) keeps each cell's balls nearest the
    # sun first.
    candidates = np.empty((n, 4), dtype=np.uint16)
    for k, (dx, dy) in enumerate(((0, 0), (1, 0), (0, 1), (1, 1))):
        inside = (first[0] + dx <= last[0]) & (first[1] + dy <= last[1])
        candidates[:, k] = np.where(inside, (first[1] + dy) * shape[0] + first[0] + dx, cells)
    ids = candidates.reshape(-1)
    by_cell = np.argsort(ids, kind="stable")
    counts = np.bincount(ids, minlength=cells + 1)
    sorted_ids = ids[by_cell]
    rank = np.arange(len(ids)) - (np.cumsum(counts) - counts)[sorted_ids]
    keep = (rank < limit) & (sorted_ids < cells)
    chosen = by_sun[by_cell[keep] // 4]
    kept = np.minimum(counts[:cells], limit)
    ranges = np.empty((cells, 2), dtype=np.int32)
    ranges[:, 1] = np.cumsum(kept)
    ranges[:, 0] = ranges[:, 1] - kept
    balls = np.empty((len(chosen), 4), dtype=np.float32)
    balls[:, :3] = positions[chosen]
    balls[:, 3] = radii[chosen]
    return ShadowGrid(
        axes=axes,
        origin=low,
        cell_size=cell,
        shape=(int(shape[0]), int(shape[1])),
        ranges=ranges,
        balls=balls,
        dropped=int(counts[:cells].sum() - kept.sum()),
    )
