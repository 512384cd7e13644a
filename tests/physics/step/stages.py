"""Running a world's step stage by stage, as ``World.step`` does, so each stage's contract can be checked
on its own."""

from __future__ import annotations

import ballpit
from ballpit.physics import step as pipeline


def prepared(world: ballpit.World, dt: float) -> pipeline.Step:
    """The context ``World.step`` would give its stages for a step of ``dt``."""
    return pipeline.prepare(world.model, world.parts, world._workspace, dt, world._good_planes)


def pile_on_a_floor(side: int = 8, r: float = 0.1, **world: object) -> ballpit.World:
    """side × side × 2 balls touching in a square heap on a floor: hundreds of kept pairs, all touching."""
    w = ballpit.World(**world)
    w.add_plane(friction=0.5)
    xs = [(2 * r * i, r + 2 * r * k, 2 * r * j) for i in range(side) for j in range(side) for k in range(2)]
    w.add_spheres(xs, radius=r)
    return w
