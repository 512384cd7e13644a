"""Time of impact: conservative advancement lands on the first contact, a ball moving fast along a
surface it hovers just above does not make it crawl, and a pair met too late to change the merged
impact stops advancing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ballpit
from ballpit.physics.collision import toi
from ballpit.physics.core.settings import CONTACT_SLOP, MAX_ADVANCE_STEPS, PENETRATION_TOLERANCE

G = 9.81


@pytest.mark.parametrize("speed", [0.0, 3.0])
@pytest.mark.parametrize("hz", [60, 240])
def test_a_ball_rolling_fast_a_tenth_of_a_millimetre_up_lands_when_free_fall_says(speed, hz):
    # The closing-speed bound counts the 3 m/s along the floor, so stepping by gap / bound crawled:
    # 48 steps covered a small part of the fall, and the step was split there, again and again (5 to 7
    # intervals a step). The gap along the normal is a parabola that cannot close before
    # √(2·(h − target)/g); from there one step lands.
    r, h = 0.1, 1e-4
    world = ballpit.World()
    world.add_plane(restitution=0.0)
    ball = world.add_sphere(position=(0, r + h, 0), radius=r, velocity=(speed, 0, 0),
                            angular_velocity=(0, 0, -speed / r))  # fmt: skip
    # it lands once within the contact slop of the floor, and before it touches it
    earliest, latest = math.sqrt(2 * (h - CONTACT_SLOP) / G), math.sqrt(2 * h / G)
    times = []
    for _ in range(3):
        contacts = world.step(1 / hz)
        times += list(contacts.time)
        assert world.profile.intervals <= 2  # the step is split once, where the ball lands
    assert earliest <= times[0] <= latest
    assert ball.position[1] == pytest.approx(r, abs=CONTACT_SLOP)  # and it rests on the floor


@pytest.mark.parametrize("speed", [3.0, -3.0])
@pytest.mark.parametrize("hz", [60, 240])
def test_a_ball_rolling_fast_just_above_a_turning_plank_lands_in_few_intervals_and_never_sinks(speed, hz):
    # On a plane turning at ω the gap along the normal is no parabola, but its curvature is bounded
    # (toi.earliest): the same leap holds, and the landing split the step 5 to 8 times before.
    r, h, rate = 0.1, 1e-4, 0.3
    world = ballpit.World()
    plank = world.add_plane(size=(20.0, 4.0), angular_velocity=(0, 0, rate), restitution=0.0)
    # 1 m from the axis the plank's surface rises at ω·1 m: the ball starts moving with it
    ball = world.add_sphere(position=(1.0, r + h, 0), radius=r, velocity=(speed, rate * 1.0, 0),
                            angular_velocity=(0, 0, -speed / r))  # fmt: skip
    for _ in range(hz // 2):
        world.step(1 / hz)
        assert world.profile.intervals <= 3
        assert plank.signed_distance(ball.position) - r >= -PENETRATION_TOLERANCE
    assert plank.signed_distance(ball.position) - r < CONTACT_SLOP  # it landed and stays on the plank


def straight_gaps(gap: np.ndarray, closing: np.ndarray, calls: list[int]):
    """``first_contact``'s ``gap_at`` for pairs whose gaps close at constant speeds, counting calls."""

    def gap_at(k: np.ndarray, t: np.ndarray) -> np.ndarray:
        calls.append(len(k))
        return gap[k] - closing[k] * t

    return gap_at


def test_a_pair_met_too_late_to_change_the_merged_impact_stops_advancing():
    # Pair 0 closes head-on and meets at 1 µs. Pair 1 closes at 1 % of its speed bound, so
    # conservative advancement crawls (its gap shrinks 1 % a step): it cannot meet before 0.2 ms, when
    # pair 0 would be 0.2 mm deep, far beyond the 0.1 µm the merge allows. It stops after one step.
    gap, bound = np.array([1e-6, 1e-4]), np.array([1.0, 1.0])
    closing = np.array([1.0, 0.01])
    crawled, stopped = [], []
    whole = toi.first_contact(straight_gaps(gap, closing, crawled), bound, 0.01, 0.0)
    cut = toi.first_contact(straight_gaps(gap, closing, stopped), bound, 0.01, 0.0, overlap=1e-7)
    assert len(crawled) == MAX_ADVANCE_STEPS + 1 and len(stopped) == 2
    assert whole[0] == cut[0] == 1e-6 and whole[1] > 1e-4 and cut[1] == np.inf
    assert toi.merged(cut, bound, 1e-7) == toi.merged(whole, bound, 1e-7) == 1e-6


@settings(max_examples=300, deadline=None)
@given(
    pairs=st.lists(
        st.tuples(
            st.floats(0.0, 1e-3),  # gap (m)
            st.floats(0.01, 10.0),  # speed bound (m/s)
            st.sampled_from([0.0, 0.01, 0.3, 0.99, 1.0]),  # closing speed, a fraction of the bound
            st.booleans(),  # whether the pair is given a start (half its meeting time)
        ),
        min_size=1,
        max_size=8,
    ),
    allowed=st.sampled_from([0.0, 1e-7, 1e-5, 1e-3]),
)
def test_pairs_that_stop_advancing_never_change_the_merged_impact(pairs, allowed):
    gap, bound, part, started = (np.array(column) for column in zip(*pairs, strict=True))
    closing = part * bound
    meets = np.where(closing > 0.0, gap / np.where(closing > 0.0, closing, 1.0), np.inf)
    start = np.where(started, 0.5 * meets, 0.0)
    args = (bound, 2e-3, 1e-6)
    whole = toi.first_contact(straight_gaps(gap, closing, []), *args, start=start)
    cut = toi.first_contact(straight_gaps(gap, closing, []), *args, start=start, overlap=allowed)
    assert toi.merged(cut, bound, allowed) == toi.merged(whole, bound, allowed)
    # a pair left out is one that met too late; every other reports the same time
    assert np.array_equal(cut[np.isfinite(cut)], whole[np.isfinite(cut)])


def test_a_fast_pair_met_late_does_not_stop_a_slow_pair_that_meets_within_the_merge():
    # Pair 0 meets at 1 µs at 0.1 m/s; pair 2 meets at 1.5 ms at 10 m/s. Pair 1 crawls (it closes at
    # half its bound) to a meeting near 2 µs: 0.1 µm after pair 0's at 0.1 m/s, within the 0.2 µm the
    # merge allows, so the merged impact is pair 1's. Only the pairs met before a pair count against
    # it: measured by pair 2's speed it would be 5 µm deep after its second step.
    gap, bound = np.array([1e-7, 1e-7, 1.5e-2]), np.array([0.1, 0.1, 10.0])
    closing = np.array([0.1, 0.05, 10.0])
    whole = toi.first_contact(straight_gaps(gap, closing, []), bound, 2e-3, 1e-9)
    cut = toi.first_contact(straight_gaps(gap, closing, []), bound, 2e-3, 1e-9, overlap=2e-7)
    assert np.array_equal(cut, whole) and 1.9e-6 < whole[1] < 2e-6
    assert toi.merged(cut, bound, 2e-7) == whole[1]
