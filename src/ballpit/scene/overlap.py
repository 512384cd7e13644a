"""The start-overlap check: no two balls, and no ball and plane, may interpenetrate at the start.

Ball pairs come from the physics broad phase (``sphere_pairs`` over a box around each ball), so the
check is linear in the number of balls and there is one spatial hash in ballpit, not two. The broad
phase lists every candidate pair, which is quadratic when many balls sit in one place; such a crowd is
looked at first, on its own, so a hostile file cannot make the check run out of memory.
"""

from __future__ import annotations

import numpy as np

from ..physics.collision.broadphase import sphere_pairs

CROWD = 64  # balls in one broad-phase cell beyond which the cell is checked on its own first
CROWD_SAMPLE = 256  # how many of a crowd's balls (the first, by index) that check compares
# Balls per slab: more are checked a slab at a time, so the broad phase's pair lists (about 700 bytes a
# ball) stay some 25 MB, not 700 MB for a million-ball grid.
SLAB = 1 << 15


def first_overlap(positions: np.ndarray, radii: np.ndarray, tolerance: float = 0.0) -> tuple[int, int] | None:
    """The first pair (i, j), i < j, of balls that interpenetrate by more than ``tolerance``, or None.

    First means the smallest later ball j, then the smallest partner i, so an error names the ball
    that a file added last. Where more than ``CROWD`` balls crowd one cell, the pair reported is the
    first among the crowd's first ``CROWD_SAMPLE`` balls, when they overlap at all.

    More than ``SLAB`` balls are cut into slabs of about that many along the axis they spread most on;
    a slab checks its balls with those of the others that reach into it, so every pair that overlaps
    is seen in a slab where both ends are (where their boxes meet along the axis).
    """
    positions = np.asarray(positions, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if len(positions) <= SLAB:
        return _first_overlap(positions, radii, tolerance)
    axis = int(np.argmax(positions.max(axis=0) - positions.min(axis=0)))
    x = positions[:, axis]
    reach = radii + max(tolerance, 0.0)
    starts = np.unique(np.sort(x)[::SLAB])
    found: list[tuple[int, int]] = []
    for k, start in enumerate(starts):
        end = starts[k + 1] if k + 1 < len(starts) else np.inf
        members = np.flatnonzero((x + reach >= start) & (x - reach < end))
        pair = _first_overlap(positions[members], radii[members], tolerance)
        if pair is not None:
            found.append((int(members[pair[0]]), int(members[pair[1]])))
    return min(found, key=lambda p: (p[1], p[0])) if found else None


def _first_overlap(positions: np.ndarray, radii: np.ndarray, tolerance: float) -> tuple[int, int] | None:
    if len(positions) < 2:
        return None
    pair = _crowd_overlap(positions, radii, tolerance)
    if pair is not None:
        return pair
    reach = (radii + max(tolerance, 0.0))[:, None]
    i, j = sphere_pairs(positions - reach, positions + reach)
    return _first_bad(positions, radii, tolerance, i, j)


def _first_bad(
    positions: np.ndarray, radii: np.ndarray, tolerance: float, i: np.ndarray, j: np.ndarray
) -> tuple[int, int] | None:
    """The first (by j, then i) of the candidate pairs (i < j) that interpenetrate, or None."""
    d = np.linalg.norm(positions[i] - positions[j], axis=1)
    bad = d < radii[i] + radii[j] - tolerance
    if not bad.any():
        return None
    bi, bj = i[bad], j[bad]
    k = np.lexsort((bi, bj))[0]
    return int(bi[k]), int(bj[k])


def _crowd_overlap(positions: np.ndarray, radii: np.ndarray, tolerance: float) -> tuple[int, int] | None:
    """The first overlapping pair among the first balls of the fullest cell, if that cell is crowded.

    Cells are as the broad phase sizes them (twice the median ball's box), so a crowd here is a crowd
    there; balls that fit so many to a cell without overlapping are rare enough to leave to it.
    """
    extent = 2.0 * radii
    cell = min(2.0 * float(np.median(extent)), float(extent.max()))
    cells = np.floor(positions / cell)
    _, inverse, counts = np.unique(cells, axis=0, return_inverse=True, return_counts=True)
    fullest = int(np.argmax(counts))
    if counts[fullest] <= CROWD:
        return None
    members = np.flatnonzero(inverse.reshape(-1) == fullest)[:CROWD_SAMPLE]
    a, b = np.triu_indices(len(members), k=1)
    return _first_bad(positions, radii, tolerance, members[a], members[b])


def first_plane_cut(
    positions: np.ndarray, radii: np.ndarray, planes: object, tolerance: float = 0.0
) -> tuple[int, int, float] | None:
    """The first (plane p, ball k, distance) where ball k cuts into plane p by more than ``tolerance``.

    Planes are taken in order, and for each the lowest-numbered ball; ``planes`` is ``world.planes``.
    """
    centers = np.asarray(planes.centers)  # type: ignore[attr-defined]
    half = np.asarray(planes.half_sizes)  # type: ignore[attr-defined]
    for p, plane in enumerate(planes):  # type: ignore[attr-defined]
        u, v = plane.axes
        d = positions - centers[p]
        du = np.clip(np.einsum("ij,j->i", d, u), -half[p, 0], half[p, 0])
        dv = np.clip(np.einsum("ij,j->i", d, v), -half[p, 1], half[p, 1])
        closest = centers[p] + du[:, None] * u + dv[:, None] * v
        dist = np.linalg.norm(positions - closest, axis=1)
        inside = np.flatnonzero(dist < radii - tolerance)
        if len(inside):
            k = int(inside[0])
            return p, k, float(dist[k])
    return None


def deepest_overlap(positions: np.ndarray, radii: np.ndarray, planes: object) -> float:
    """How far (m) the balls press into each other or into a plane at most now; 0 when none do.

    What a scene saved from a running world must allow at its start (``[world] overlap_tolerance``).
    """
    positions = np.asarray(positions, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if len(positions) == 0:
        return 0.0
    deepest = 0.0
    if len(positions) > 1:
        reach = radii[:, None]
        i, j = sphere_pairs(positions - reach, positions + reach)
        if len(i):
            d = np.linalg.norm(positions[i] - positions[j], axis=1)
            deepest = max(deepest, float((radii[i] + radii[j] - d).max()))
    for plane in planes:  # type: ignore[attr-defined]
        deepest = max(deepest, float((radii - np.asarray(plane.distance(positions))).max()))
    return deepest
