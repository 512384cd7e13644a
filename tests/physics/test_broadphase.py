"""The broad phase finds exactly the overlapping boxes a brute-force all-pairs test finds."""

import numpy as np
import pytest

from ballpit.physics.collision import broadphase


def brute_force_pairs(lo: np.ndarray, hi: np.ndarray) -> set[tuple[int, int]]:
    n = len(lo)
    return {
        (i, j) for i in range(n) for j in range(i + 1, n) if np.all(lo[i] <= hi[j]) and np.all(lo[j] <= hi[i])
    }


def random_boxes(rng: np.random.Generator, n: int, spread: float, sizes: np.ndarray):
    centre = rng.uniform(-spread, spread, (n, 3))
    half = 0.5 * sizes[:, None] * rng.uniform(0.5, 1.0, (n, 3))
    return centre - half, centre + half


@pytest.mark.parametrize(
    "case",
    ["similar sizes", "a few very large boxes", "two size classes", "all in one place"],
)
def test_sphere_pairs_match_brute_force(case: str) -> None:
    rng = np.random.default_rng(7)
    n = 400
    sizes = rng.uniform(0.9, 1.1, n)
    spread = 6.0
    if case == "a few very large boxes":  # fast balls sweep long boxes through the crowd
        sizes[rng.choice(n, 5, replace=False)] = 8.0
    elif case == "two size classes":  # most boxes near 1, a third up to 1.9 (no box counts as large)
        sizes[: n // 3] = rng.uniform(1.5, 1.9, n // 3)
    elif case == "all in one place":
        spread = 0.5
    lo, hi = random_boxes(rng, n, spread, sizes)
    i, j = broadphase.sphere_pairs(lo, hi)
    found = list(zip(i.tolist(), j.tolist(), strict=True))
    assert len(found) == len(set(found)), "a pair was reported twice"
    assert set(found) == brute_force_pairs(lo, hi)
    assert np.all(i < j)


def test_sphere_pairs_of_fewer_than_two_boxes_is_empty() -> None:
    lo = np.zeros((1, 3))
    i, j = broadphase.sphere_pairs(lo, lo + 1.0)
    assert len(i) == len(j) == 0


def test_within_reach_keeps_exactly_the_pairs_whose_spheres_overlap() -> None:
    rng = np.random.default_rng(3)
    centre = rng.uniform(-2.0, 2.0, (60, 3))
    reach = rng.uniform(0.2, 0.6, 60)
    i, j = np.triu_indices(60, 1)
    ki, kj = broadphase.within_reach(i, j, centre, reach)
    expected = {
        (a, b)
        for a, b in zip(i.tolist(), j.tolist(), strict=True)
        if np.linalg.norm(centre[a] - centre[b]) <= reach[a] + reach[b]
    }
    assert set(zip(ki.tolist(), kj.tolist(), strict=True)) == expected


def test_sphere_plane_pairs_find_boxes_near_the_rectangle_only() -> None:
    # A 2 m × 2 m floor at y = 0: a box resting on it, one beside it beyond the edge, one high above.
    lo = np.array([[-0.1, -0.05, -0.1], [2.5, -0.05, 0.0], [0.0, 3.0, 0.0]])
    hi = lo + 0.2
    centre, normal = np.zeros((1, 3)), np.array([[0.0, 1.0, 0.0]])
    axis_u, axis_v = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 0.0, 1.0]])
    s, p = broadphase.sphere_plane_pairs(lo, hi, centre, normal, axis_u, axis_v, np.array([[1.0, 1.0]]))
    assert s.tolist() == [0]
    assert p.tolist() == [0]


@pytest.mark.parametrize("n", [2, 5, 30, 48, 49, 60])
def test_few_boxes_give_the_same_pairs_in_the_same_order_either_way(n):
    # Up to ALL_PAIRS_UP_TO boxes every pair is tested at once; above it the grid is used. Either way
    # the pairs are the brute-force ones, ordered by i then j, so a step gives identical results.
    rng = np.random.default_rng(n)
    centre = rng.uniform(0, 1.5, (n, 3))
    half = rng.uniform(0.05, 0.3, (n, 1))
    lo, hi = centre - half, centre + half
    i, j = broadphase.sphere_pairs(lo, hi)
    bi, bj = np.triu_indices(n, 1)
    keep = np.all((lo[bi] <= hi[bj]) & (lo[bj] <= hi[bi]), axis=1)
    assert np.array_equal(i, bi[keep]) and np.array_equal(j, bj[keep])


@pytest.mark.parametrize("case", ["a packed pile", "balls spread far apart", "a few very large boxes"])
def test_the_sparse_and_the_dense_cell_lookups_find_the_same_pairs_in_the_same_order(case, monkeypatch):
    """The grid's two ways of finding neighbouring cells (a table over every cell, or a search of the
    sorted cell keys when the cells far outnumber the balls) give the same pairs, in the same order,
    and both give exactly the overlapping boxes."""
    rng = np.random.default_rng(11)
    n = 300
    sizes = rng.uniform(0.9, 1.1, n)
    spread = {"a packed pile": 3.0, "balls spread far apart": 1.5, "a few very large boxes": 6.0}[case]
    if case == "a few very large boxes":
        sizes[rng.choice(n, 4, replace=False)] = 9.0
    lo, hi = random_boxes(rng, n, spread, sizes)
    if case == "balls spread far apart":  # ten small clusters up to 200 m apart: most cells are empty
        shift = rng.uniform(-100.0, 100.0, (10, 3))[np.arange(n) % 10]
        lo, hi = lo + shift, hi + shift
    found = {}
    for path, cells_per_ball in (("dense", 10**9), ("sparse", 0)):
        monkeypatch.setattr(broadphase, "DENSE_CELLS_PER_BALL", cells_per_ball)
        found[path] = broadphase.sphere_pairs(lo, hi)
    assert np.array_equal(found["dense"][0], found["sparse"][0])
    assert np.array_equal(found["dense"][1], found["sparse"][1])
    pairs = set(zip(found["sparse"][0].tolist(), found["sparse"][1].tolist(), strict=True))
    assert len(pairs) == len(found["sparse"][0]) and pairs == brute_force_pairs(lo, hi)
    assert len(pairs) > 0
