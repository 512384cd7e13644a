"""A soft frame's shared data (soft_frame.py): the touched balls as columns, and each contact's
separation s = s₀ + n·(Δx_a − Δx_b) as the balls move."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.physics.collision import narrowphase
from ballpit.physics.contact.soft_frame import SoftFrame
from ballpit.physics.contact.warm_start import WarmStart
from ballpit.physics.dynamics.forces import free_acceleration

DT = 1 / 60


def frame(world: ballpit.World, substeps: int = 4) -> SoftFrame:
    model, state = world.model, world.state
    accel, _ = free_acceleration(state.body, model.forces())
    c = narrowphase.contact_points(model, state, world.parts.pairs.for_step(model, state, accel, DT, None))
    return SoftFrame(model, state, c, model.forces(), DT, WarmStart(), substeps)


def two_balls_on_a_floor() -> ballpit.World:
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane()
    world.add_spheres([(0, 0.5, 0), (0.9, 0.5, 0)], radius=0.5, velocity=[(1, 0, 0), (-1, 0, 0)])
    return world


def test_the_frame_holds_the_touched_balls_as_columns_and_the_static_row_last():
    world = two_balls_on_a_floor()
    f = frame(world)
    assert f.idx.tolist() == [0, 1] and f.k_balls.tolist() == [0, 1, 2]  # row 2: the floor
    assert f.x[:, f.live].T.tolist() == world.state.body[:, 0:3].tolist() and (f.x[:, 2] == 0).all()
    assert f.vw[:3, f.live].T.tolist() == [[1, 0, 0], [-1, 0, 0]]
    assert f.h == DT / 4


def test_the_separation_follows_the_balls_along_each_normal():
    world = two_balls_on_a_floor()
    f = frame(world)
    assert f.separation(0.0) == pytest.approx(f.c.gap, abs=1e-15)
    f.x[:, 0] += (0.05, -0.02, 0.3)  # ball 0 moves right (towards 1), down into the floor, and sideways
    s = f.separation(0.0)
    pair = np.flatnonzero(~f.on_plane)[0]
    floor_0 = np.flatnonzero(f.on_plane & (f.c.a == 0))[0]
    floor_1 = np.flatnonzero(f.on_plane & (f.c.a == 1))[0]
    assert s[pair] == pytest.approx(f.c.gap[pair] - 0.05) and s[floor_0] == pytest.approx(-0.02)
    assert s[floor_1] == pytest.approx(0.0, abs=1e-15)
