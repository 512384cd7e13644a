"""After a soft frame's substeps (separate.py): an overlap deeper than the slop is moved back to 0.8 of
it by positions alone, each ball by its share of inverse mass, and a ball left deeper in a plane than
it began is moved back out."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.contact import separate
from ballpit.physics.core.settings import SLOP, SLOP_RETURN

from .test_soft_frame import frame


def test_an_overlap_made_in_the_frame_goes_back_to_the_slops_return_shared_by_inverse_mass():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_sphere(position=(0, 5, 0), radius=0.5, mass=1.0)
    world.add_sphere(position=(1.0, 5, 0), radius=0.5, mass=3.0)  # touching
    f = frame(world)
    f.keep_start()  # as store_impulses does before it writes the balls back
    body = world.state.body
    body[0, 0] += 0.1  # the substeps drove the light ball 0.1 m into the heavy one
    f.x[0, 0] += 0.1
    separate.move_apart(f, world.model, world.state)
    overlap = SLOP_RETURN * SLOP * 0.5
    assert body[1, 0] - body[0, 0] == pytest.approx(1.0 - overlap, rel=1e-12)
    # moved apart 0.1 − overlap in all, three quarters by the ball of a quarter the mass
    assert 0.1 - body[0, 0] == pytest.approx(0.75 * (0.1 - overlap), rel=1e-12)


def test_a_ball_left_deeper_in_the_floor_than_it_began_is_moved_back_out_to_the_slop():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane()
    world.add_sphere(position=(0, 0.5, 0), radius=0.5, velocity=(0, -1, 0))  # touching, arriving
    f = frame(world)
    f.keep_start()  # as store_impulses does before it writes the balls back
    world.state.body[0, 1] = 0.4  # the frame left it 0.1 m into the floor
    separate.planes_win(f, world.model, world.state)
    assert world.state.body[0, 1] == pytest.approx(0.5 - SLOP * 0.5, rel=1e-12)
    assert np.array_equal(world.state.body[0, [0, 2]], [0.0, 0.0])
