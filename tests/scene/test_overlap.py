"""The start-overlap check: exactly the brute-force answer, linear in the number of balls, and safe
on crowds and on one huge ball beside many small ones."""

from __future__ import annotations

import time

import numpy as np
import pytest

import ballpit
from ballpit.scene import overlap
from ballpit.scene.overlap import first_overlap, first_plane_cut


def brute_force(positions: np.ndarray, radii: np.ndarray, tolerance: float) -> tuple[int, int] | None:
    d = np.linalg.norm(positions[:, None] - positions[None], axis=2)
    bad = np.triu(d < radii[:, None] + radii[None] - tolerance, k=1)
    if not bad.any():
        return None
    i, j = np.nonzero(bad)
    k = np.lexsort((i, j))[0]  # the smallest later ball, then its smallest partner
    return int(i[k]), int(j[k])


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("tolerance", [0.0, 0.01])
def test_first_overlap_is_the_brute_force_first_pair(seed, tolerance):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 600))
    positions = rng.uniform(0, 4, size=(n, 3))
    radii = rng.uniform(0.01, 0.12, size=n) * rng.choice([1.0, 4.0], size=n)  # two sizes of ball
    assert first_overlap(positions, radii, tolerance) == brute_force(positions, radii, tolerance)


def test_touching_within_the_tolerance_is_not_an_overlap():
    positions = np.array([[0.0, 0.0, 0.0], [1.0 - 1e-7, 0.0, 0.0]])
    radii = np.array([0.5, 0.5])
    assert first_overlap(positions, radii, 1e-6) is None
    assert first_overlap(positions, radii, 0.0) == (0, 1)


def test_a_crowd_in_one_place_is_found_quickly():
    started = time.process_time()
    assert first_overlap(np.zeros((3000, 3)), np.full(3000, 0.1)) == (0, 1)
    assert time.process_time() - started < 1.0


def test_a_crowd_behind_a_clean_grid_is_reported_inside_the_crowd():
    grid = np.indices((10, 10, 10)).reshape(3, -1).T * 1.0
    crowd = np.full((2000, 3), 50.0)
    positions = np.vstack([grid, crowd])
    pair = first_overlap(positions, np.full(len(positions), 0.3))
    assert pair == (1000, 1001)


def test_one_huge_ball_beside_a_small_grid_is_fast():
    grid = np.indices((22, 22, 22)).reshape(3, -1).T * 0.25  # 10,648 balls of r = 0.1, 0.05 apart
    positions = np.vstack([grid, [[-1e4 - 1.0, 1.0, 1.0]]])
    radii = np.r_[np.full(len(grid), 0.1), 1e4]
    started = time.process_time()
    assert first_overlap(positions, radii, 1e-6) is None
    assert time.process_time() - started < 1.0
    positions[-1, 0] += 1.0  # now it reaches into the grid
    i, j = first_overlap(positions, radii, 1e-6)
    assert j == len(grid) and np.linalg.norm(positions[i] - positions[j]) < radii[j] + 0.1


def test_a_hundred_thousand_balls_check_in_seconds():
    grid = np.indices((50, 50, 40)).reshape(3, -1).T * 0.25
    positions = grid + np.random.default_rng(1).uniform(-0.02, 0.02, grid.shape)
    radii = np.full(len(positions), 0.1)
    started = time.process_time()
    assert first_overlap(positions, radii, 1e-6) is None
    assert time.process_time() - started < 5.0


def test_plane_cuts_are_found_on_faces_edges_and_not_beyond_a_square():
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0), size=2.0)  # square from -1 to 1 in x and z
    positions = np.array([[3.0, 0.0, 0.0], [1.2, 0.1, 0.0], [0.5, 0.3, 0.5], [0.0, 0.6, 0.0]])
    radii = np.full(4, 0.5)
    # ball 1 is 0.2236 m from the edge, ball 2 is 0.3 m above the face; ball 0 is beyond the square
    p, k, dist = first_plane_cut(positions, radii, world.planes, 1e-6)
    assert (p, k) == (0, 1) and dist == pytest.approx(np.hypot(0.2, 0.1))
    assert first_plane_cut(positions[[0, 3]], radii[[0, 3]], world.planes, 1e-6) is None


@pytest.mark.parametrize("seed", range(8))
def test_checked_in_slabs_the_first_overlap_is_still_the_brute_force_first_pair(seed, monkeypatch):
    # A million-ball grid is checked a slab at a time (its pair lists took 1 GB at once): every pair
    # that overlaps must still be seen, whichever slabs its two balls fall in.
    monkeypatch.setattr(overlap, "SLAB", 40)
    rng = np.random.default_rng(seed)
    shape = (12, 8, 6) if seed % 2 else (200, 2, 1)  # a block, or a long row
    positions = np.indices(shape).reshape(3, -1).T * 1.0 + rng.uniform(-0.05, 0.05, (int(np.prod(shape)), 3))
    radii = np.full(len(positions), 0.3)
    movers = rng.choice(len(positions), size=3, replace=False)
    targets = rng.choice(len(positions), size=3, replace=False)
    positions[movers] = positions[targets] + rng.uniform(-0.4, 0.4, (3, 3))  # a few overlaps, anywhere
    if seed % 4 == 3:
        radii[rng.integers(len(radii))] = 3.0  # one ball reaching across many slabs
    expected = brute_force(positions, radii, 0.0)
    assert expected is not None
    assert first_overlap(positions, radii, 0.0) == expected
