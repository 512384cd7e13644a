"""Broad phase: which pairs could touch during the step, from each ball's swept bounding box.

Sphere pairs come from a uniform grid built by sorting cell keys (no Python loop over balls, cost
linear in N plus the sort). The cell is as large as the largest box, so two overlapping boxes sit in the
same or neighbouring cells, but never more than twice a typical box: the rare box larger than that (a
very fast ball) is tested against every box directly. Sphere–plane pairs test each box against each
rectangle's extent.
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.settings import ALL_PAIRS_UP_TO, CELL_PER_MEDIAN_BOX, DENSE_CELLS_PER_BALL, PLANE_PAIRS_AT_ONCE

# The cell and its 13 "forward" neighbours: every unordered pair of neighbouring cells once.
_OFFSETS = np.array(
    [(0, 0, 0)]
    + [
        (dx, dy, dz)
        for dx in (-1, 0, 1)
        for dy in (-1, 0, 1)
        for dz in (-1, 0, 1)
        if (dx, dy, dz) > (0, 0, 0)
    ],
    dtype=np.int64,
)


def _ranges(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each k, the integers starts[k] … starts[k]+counts[k]−1, flattened, with their owner k."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    first = np.cumsum(counts) - counts
    return owner, np.arange(total) - first[owner] + starts[owner]


def _overlap(lo: np.ndarray, hi: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Whether boxes i and j overlap, axis by axis on contiguous coordinates (several times faster
    than comparing gathered (K, 3) rows)."""
    ok = np.ones(len(i), bool)
    if len(i) == 0:
        return ok
    for lo_axis, hi_axis in zip(np.ascontiguousarray(lo.T), np.ascontiguousarray(hi.T), strict=True):
        ok &= np.take(lo_axis, i) <= np.take(hi_axis, j)
        ok &= np.take(lo_axis, j) <= np.take(hi_axis, i)
    return ok


def within_reach(
    i: np.ndarray, j: np.ndarray, centre: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs whose bounding spheres (``centre``, ``reach``) overlap.

    Boxes are a loose fit in a packed pile: a box of side 2.2·r overlaps its diagonal neighbours, whose
    balls are 2.8·r apart and cannot touch. The spheres around each ball's swept path cut those out,
    about three candidates in four there.
    """
    d = np.take(centre, i, axis=0) - np.take(centre, j, axis=0)
    keep = np.einsum("ij,ij->i", d, d) <= (np.take(reach, i) + np.take(reach, j)) ** 2
    return i[keep], j[keep]


def sphere_pairs(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All pairs (i < j) of boxes that overlap, ordered by i, then j."""
    n = len(lo)
    if n < 2:
        empty = np.zeros(0, np.intp)
        return empty, empty
    if n <= ALL_PAIRS_UP_TO:  # a handful of balls: every pair in one go, already in order
        i, j = _every_pair(n)
        hit = _overlap(lo, hi, i, j)
        return i[hit], j[hit]
    # the largest side of each box, axis by axis on columns (a max is exact, in any order)
    extent = np.maximum(np.maximum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1]), hi[:, 2] - lo[:, 2])
    cell = min(CELL_PER_MEDIAN_BOX * float(np.median(extent)), float(extent.max()))
    big = extent > cell
    small = np.flatnonzero(~big)
    pairs_i, pairs_j = [], []

    if len(small) > 1:
        center = 0.5 * (lo + hi) if len(small) == n else 0.5 * (lo[small] + hi[small])
        c = np.floor(center / cell).astype(np.int64)
        # keep neighbour cells non-negative (column by column: a reduction down a (N, 3) array is slow)
        c -= np.array([c[:, k].min() for k in range(3)]) - 1
        dims = np.array([c[:, k].max() for k in range(3)]) + 2
        key = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
        cells = int(np.prod(dims))
        if cells <= DENSE_CELLS_PER_BALL * len(small):
            i, j = _dense_candidates(key, dims, cells)
        else:
            i, j = _sparse_candidates(key, dims)
        i, j = np.take(small, i), np.take(small, j)
        hit = _overlap(lo, hi, i, j)
        pairs_i.append(i[hit])
        pairs_j.append(j[hit])

    for b in np.flatnonzero(big):
        others = np.flatnonzero(np.all((lo <= hi[b]) & (lo[b] <= hi), axis=1))
        others = others[(others != b) & (~big[others] | (others > b))]
        pairs_i.append(np.full(len(others), b))
        pairs_j.append(others)

    if not pairs_i:
        empty = np.zeros(0, np.intp)
        return empty, empty
    i = np.concatenate(pairs_i)
    j = np.concatenate(pairs_j)
    # a fixed order keeps the whole step deterministic: by i, then j, sorted as one key i·n + j (each
    # pair appears once, so any sort gives the order ``np.lexsort`` would, at a third of its cost)
    key = np.minimum(i, j).astype(np.int64) * n + np.maximum(i, j)
    key.sort()
    first = key // n
    return first.astype(np.intp), (key - first * n).astype(np.intp)


# Every pair (i < j) of n boxes, by n (np.triu_indices, read only): made once for each small n.
_EVERY_PAIR: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _every_pair(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.triu_indices(n, 1)``, kept (it costs a dozen NumPy calls, more than the test it feeds)."""
    pairs = _EVERY_PAIR.get(n)
    if pairs is None:
        i, j = np.triu_indices(n, 1)
        i.flags.writeable = j.flags.writeable = False
        pairs = _EVERY_PAIR[n] = (i, j)
    return pairs


def _neighbour_steps(dims: np.ndarray) -> np.ndarray:
    """The key differences of the _OFFSETS for a grid of ``dims`` cells."""
    return (_OFFSETS[:, 0] * dims[1] + _OFFSETS[:, 1]) * dims[2] + _OFFSETS[:, 2]


def _dense_candidates(key: np.ndarray, dims: np.ndarray, cells: int) -> tuple[np.ndarray, np.ndarray]:
    """Candidate pairs (places in ``key``) from a table of every cell's first ball and count: each ball
    with the later balls of its own cell and every ball of its 13 forward neighbours."""
    n = len(key)
    order = np.argsort(key, kind="stable")
    per_cell = np.bincount(key, minlength=cells + 1)
    first_in_cell = np.cumsum(per_cell) - per_cell
    # every ball's own cell and its 13 forward neighbours at once
    neighbour = (key[None, :] + _neighbour_steps(dims)[:, None]).ravel()  # offset-major: own cells first
    neighbour = np.minimum(neighbour, cells)  # past the last cell: the empty sentinel
    start, count = np.take(first_in_cell, neighbour), np.take(per_cell, neighbour)
    owner, pos = _ranges(start, count)
    i, j = owner % n, np.take(order, pos)
    keep = (owner >= n) | (i < j)  # own cell: each pair once, never a ball with itself
    return i[keep], j[keep]


def _sparse_candidates(key: np.ndarray, dims: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The same candidate pairs as ``_dense_candidates`` (places in ``key``) when the grid has far more
    cells than balls (balls spread apart), found from the occupied cells alone.

    A forward neighbour is the next cell along z, or one of three cells (z − 1 … z + 1) in one of four
    forward rows (a row: the cells sharing x and y). Rows are matched first, so only the cells of rows
    with an occupied neighbour row are looked up: balls far apart cost a sort and a few passes.
    """
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    n = len(key)
    starts = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
    cell_key = sorted_key[starts]  # the occupied cells in key order, their balls at places starts…ends
    ends = np.r_[starts[1:], n]
    row = cell_key // dims[2]
    row_starts = np.flatnonzero(np.r_[True, row[1:] != row[:-1]])
    row_key = row[row_starts]  # the occupied rows, their cells at row_starts…row_ends
    row_ends = np.r_[row_starts[1:], len(cell_key)]
    # own cell: every place p with the later places of its cell (stable sort: later is larger)
    place = np.arange(n)
    cell_end = np.repeat(ends, ends - starts)
    first, second = _ranges(place + 1, cell_end - place - 1)
    pi, pj = [place[first]], [second]
    # the next cell along z
    a = np.flatnonzero(cell_key[1:] == cell_key[:-1] + 1)
    cell_a, cell_b = [a], [a + 1]
    # cells z − 1 … z + 1 of each forward row (dx, dy) = (0, 1), (1, −1), (1, 0), (1, 1)
    for dx, dy in ((0, 1), (1, -1), (1, 0), (1, 1)):
        delta = dx * dims[1] + dy
        at = np.minimum(np.searchsorted(row_key, row_key + delta), len(row_key) - 1)
        rows_a = np.flatnonzero(row_key[at] == row_key + delta)
        if rows_a.size == 0:
            continue
        _, ca = _ranges(row_starts[rows_a], row_ends[rows_a] - row_starts[rows_a])
        target = cell_key[ca] + delta * dims[2]
        lo_cell = np.searchsorted(cell_key, target - 1, "left")
        hi_cell = np.searchsorted(cell_key, target + 1, "right")
        which, cb = _ranges(lo_cell, hi_cell - lo_cell)
        cell_a.append(ca[which])
        cell_b.append(cb)
    cell_a, cell_b = np.concatenate(cell_a), np.concatenate(cell_b)
    # every ball of cell a with every ball of cell b
    pair, pa = _ranges(starts[cell_a], ends[cell_a] - starts[cell_a])
    which, pb = _ranges(starts[cell_b][pair], (ends[cell_b] - starts[cell_b])[pair])
    pi.append(pa[which])
    pj.append(pb)
    return np.take(order, np.concatenate(pi)), np.take(order, np.concatenate(pj))


def sphere_plane_pairs(
    lo: np.ndarray,
    hi: np.ndarray,
    center: np.ndarray,
    normal: np.ndarray,
    axis_u: np.ndarray,
    axis_v: np.ndarray,
    half_size: np.ndarray,
    sweep=None,
    only: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (sphere, plane) whose box reaches the plane's rectangle, plane by plane (the planes
    ``only`` names, in order; all of them when None), each plane's balls in order.

    ``sweep(p, d)``, when given, is how far a point of plane ``p`` at distance ``d`` from its centre
    may move (a moving plane); a box that close counts too.
    """
    if len(center) == 0:  # no planes
        empty = np.zeros(0, np.intp)
        return empty, empty
    box_center = 0.5 * (lo + hi)
    box_radius = 0.5 * exact.norm_rows(hi - lo)
    chosen = np.arange(len(center)) if only is None else np.asarray(only, np.intp)
    group = max(1, PLANE_PAIRS_AT_ONCE // max(len(lo), 1))  # planes per pass
    spheres, planes = [], []
    for first in range(0, len(chosen), group):
        ps = chosen[first : first + group]
        # (planes, balls) at once: the same elementwise operations for each pair as one plane at a time
        d = box_center[None, :, :] - center[ps][:, None, :]
        du = np.abs(exact.dot_rows(d, axis_u[ps][:, None, :])) - half_size[ps, 0][:, None]
        dv = np.abs(exact.dot_rows(d, axis_v[ps][:, None, :])) - half_size[ps, 1][:, None]
        dn = exact.dot_rows(d, normal[ps][:, None, :])
        # distance from the box centre to the rectangle, against the box's bounding-sphere radius
        dist2 = np.maximum(du, 0.0) ** 2 + np.maximum(dv, 0.0) ** 2 + dn**2
        if sweep is None:
            hit = dist2 <= box_radius**2
        else:
            hit = np.empty(dist2.shape, bool)
            for row, p in enumerate(ps.tolist()):
                grown = box_radius + sweep(p, exact.norm_rows(d[row]) + box_radius)
                hit[row] = dist2[row] <= grown**2
        row, ball = hit.nonzero()  # plane by plane, each plane's balls in order
        spheres.append(ball)
        planes.append(ps[row])
    if not spheres:
        empty = np.zeros(0, np.intp)
        return empty, empty
    return np.concatenate(spheres), np.concatenate(planes)
