"""Time of impact: conservative advancement lands on the first contact, and a ball moving fast along
a surface it hovers just above does not make it crawl."""

from __future__ import annotations

import math

import pytest

import ballpit
from ballpit.physics.core.settings import CONTACT_SLOP, PENETRATION_TOLERANCE

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
