"""The landing's measures: overlaps, balls in the box and speeds, against cases worked by hand."""

import numpy as np
import pytest

from ballpit.cli.peers.landing import (
    RADIUS,
    Landing,
    inside_box,
    max_overlap,
    max_speed,
    pair_overlaps,
    wall_overlaps,
)

R = RADIUS


def brute_pair_overlaps(p: np.ndarray, radius: float) -> np.ndarray:
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    i, j = np.triu_indices(len(p), 1)
    return np.sort((2 * radius - d[i, j])[d[i, j] < 2 * radius])


def test_two_balls_0_09_m_apart_overlap_by_a_fifth_of_a_radius():
    p = np.array([[0.0, 1.0, 0.0], [0.09, 1.0, 0.0], [5.0, 1.0, 0.0]])
    assert pair_overlaps(p, R) == pytest.approx([0.01])
    assert max_overlap(p, R, half=10.0) == pytest.approx(0.2)


@pytest.mark.parametrize("seed", range(5))
def test_pair_overlaps_find_every_overlapping_pair_a_search_of_all_pairs_finds(seed):
    # a crowd packed closer than a diameter, so that many pairs overlap across cell borders
    p = np.random.default_rng(seed).uniform(-0.4, 0.4, (400, 3))
    expected = brute_pair_overlaps(p, R)
    assert len(expected) > 100
    assert np.sort(pair_overlaps(p, R)) == pytest.approx(expected, abs=1e-15)


def test_balls_just_apart_or_touching_have_no_overlap():
    p = np.array([[0.0, 0.5, 0.0], [2 * R, 0.5, 0.0], [0.0, 0.5, 2 * R + 1e-9]])
    assert max_overlap(p, R, half=1.0) == 0.0


@pytest.mark.parametrize(
    ("centre", "depth"),
    [((0.0, 0.04, 0.0), 0.01), ((0.97, 0.5, 0.0), 0.02), ((0.0, 0.5, -0.99), 0.04), ((0.0, 0.5, 0.0), -0.45)],
    ids=["into the floor", "into the +x wall", "into the -z wall", "in the middle"],
)
def test_wall_overlap_is_the_depth_into_the_floor_or_the_nearest_wall(centre, depth):
    assert wall_overlaps(np.array([centre]), R, half=1.0) == pytest.approx([depth])


def test_a_position_that_is_not_finite_is_an_infinite_overlap():
    p = np.array([[0.0, 0.5, 0.0], [np.nan, 0.5, 0.0]])
    assert max_overlap(p, R, half=1.0) == np.inf
    assert max_speed(np.array([[0.0, np.inf, 0.0]])) == np.inf


def test_inside_box_counts_the_centres_between_the_walls_and_above_the_floor():
    p = np.array([[0.0, 0.05, 0.0], [0.99, 0.05, -0.99], [1.01, 0.05, 0.0], [0.0, -0.01, 0.0], [np.nan] * 3])
    assert inside_box(p, half=1.0) == 2


def test_max_speed_is_the_fastest_balls_speed():
    assert max_speed(np.array([[3.0, 4.0, 0.0], [0.0, -1.0, 0.0]])) == pytest.approx(5.0)


def test_the_landing_grid_starts_inside_the_box_with_nothing_overlapping():
    landing = Landing.of(1000)
    assert landing.n == 1000
    assert inside_box(landing.centres, landing.half) == 1000
    assert max_overlap(landing.centres, R, landing.half) == 0.0
