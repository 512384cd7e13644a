"""The resting solve's warm start is keyed by each pair's own identity, so adding balls mid-run never
hands one pair's contact force to another."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit

DT = 1 / 240
SHELF = (40.0, 0.0, 0.0)  # a far-away shelf, out of reach of the pile
SETTLE = 960  # steps (4 s: the column topples, and a ball rolls to a wall; all rest by about 3.3 s)


def settled_pile() -> ballpit.World:
    """Twelve balls of different masses piled in a narrow box and left to settle, beside an empty
    shelf far away."""
    world = ballpit.World()
    world.add_plane(normal=(0, 1, 0))
    world.add_plane(position=(-0.25, 0, 0), normal=(1, 0, 0))
    world.add_plane(position=(0.25, 0, 0), normal=(-1, 0, 0))
    world.add_plane(position=(0, 0, -0.25), normal=(0, 0, 1))
    world.add_plane(position=(0, 0, 0.25), normal=(0, 0, -1))
    world.add_plane(position=SHELF, size=2.0, restitution=0.0)
    rng = np.random.default_rng(7)
    positions = np.column_stack(
        (rng.uniform(-0.12, 0.12, 12), 0.1 + 0.21 * np.arange(12), rng.uniform(-0.12, 0.12, 12))
    )
    world.add_spheres(positions, radius=0.1, mass=rng.uniform(0.5, 3.0, 12), restitution=0.0)
    for _ in range(SETTLE):
        world.step(DT)
    return world


@pytest.mark.slow
def test_adding_a_ball_mid_run_leaves_every_other_contact_its_own_warm_start():
    # Two copies of the same run; one gets a ball on the far shelf. That ball touches nothing in the
    # pile, so the pile must go on exactly as in the other copy. Keys that depended on the ball count
    # (as they once did) handed, for example, pair (1, 5)'s force to pair (1, 3) once the count
    # changed, and the pile jolted.
    alone = settled_pile()
    joined = alone.copy()  # the same run from here on (a copy carries the warm starts too)
    joined.add_sphere(position=np.add(SHELF, (0, 0.1, 0)), radius=0.1, mass=5.0)
    pile = slice(0, 12)
    for _ in range(60):
        held = alone.step(DT)
        joined.step(DT)
        assert np.abs(joined.spheres.velocities[pile] - alone.spheres.velocities[pile]).max() < 1e-9
    assert np.count_nonzero(held.kind == 1) >= 10  # the pile really is held by ball-ball contacts
    assert np.abs(joined.spheres.positions[pile] - alone.spheres.positions[pile]).max() < 1e-9
