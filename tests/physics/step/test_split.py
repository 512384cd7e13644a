"""The split step (step/split.py) counts a step's intervals itself: the profile a step is timed into only
measures."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.physics import step as pipeline
from ballpit.physics.profile import StepProfile
from ballpit.physics.settings import CONTACT_SLOP, MAX_INTERVALS

G = 9.81


def landing_world() -> ballpit.World:
    """A ball 1 cm above the floor, falling at 1 m/s: it lands within the next 1/60 s step, so the step
    is split at the impact (two intervals)."""
    world = ballpit.World()
    world.add_plane(restitution=0.5)
    world.add_sphere(position=(0, 0.1 + 0.01, 0), radius=0.1, velocity=(0, -1.0, 0))
    return world


def test_a_step_lands_the_same_whatever_count_its_profile_starts_from(monkeypatch):
    # A profile whose counter says the step is already at its last allowed interval: when the split
    # step read its first interval and its bound on intervals from the profile, this one stopped the
    # ball in the air (finish_conservatively) instead of bouncing it.
    dt = 1 / 60
    plain, timed = landing_world(), landing_world()
    plain.step(dt)
    monkeypatch.setattr(pipeline, "StepProfile", lambda: StepProfile(intervals=MAX_INTERVALS - 1))
    timed.step(dt)
    assert np.array_equal(timed.state.body, plain.state.body)
    assert timed.profile.intervals == plain.profile.intervals == 2
    # and the step did what free fall and Newton's impact law say: landed at v₁ after t₁, left at e·v₁.
    # It lands within the contact slop of the floor, up to slop/v₁ early: (1 + e)·g·slop/v₁ in speed.
    v1 = math.sqrt(1.0 + 2 * G * 0.01)
    t1 = (v1 - 1.0) / G
    expected = 0.5 * v1 - G * (dt - t1)
    assert timed.spheres[0].velocity[1] == pytest.approx(expected, abs=1.5 * G * CONTACT_SLOP / v1)
