"""Edits a user makes between steps (the viewer's inspector and panel): a ball's size, removing a
ball, moving a plane, and what a ball added by hand would overlap. Each is validated before anything is
written; after one, the kept pairs and warm start are found afresh and sleeping balls wake (``edited``).
"""

from __future__ import annotations

import numpy as np

from .collision import geometry
from .collision.pairs import PairCache
from .contact.resting import WarmStart
from .core import exact, quaternion, validation
from .core.state import State, X
from .dynamics import moving_planes
from .dynamics.model import HOLLOW_INERTIA, SOLID_INERTIA, Model
from .step.checkpoint import Parts


def index_of(kind: str, index: object, count: int) -> int:
    """``index`` checked as the index of one of ``count`` balls or planes (TypeError/ValueError naming it)."""
    if isinstance(index, bool) or not isinstance(index, int | np.integer):
        raise TypeError(f"index must be a {kind}'s index, got {index!r}")
    if not 0 <= index < count:
        raise ValueError(f"index must be a {kind}'s index from 0 to {count - 1}, got {index}")
    return int(index)


def set_sphere_size(
    model: Model, parts: Parts, index: object, radius: float | None, mass: float | None
) -> None:
    """Give ball ``index`` a new ``radius`` and/or ``mass``; its inverse mass and inertia follow
    (2/5·m·r² solid, 2/3·m·r² hollow). Both are checked before either is written."""
    i = index_of("ball", index, parts.state.count)
    cols = model.spheres
    r = cols.radius[i] if radius is None else validation.number("radius", radius, positive=True)
    m = cols.mass[i] if mass is None else validation.number("mass", mass, positive=True)
    cols.radius[i], cols.mass[i] = r, m
    cols.inv_mass[i] = 1.0 / m
    shape_factor = HOLLOW_INERTIA if cols.hollow[i] else SOLID_INERTIA
    cols.inv_inertia[i] = 1.0 / (shape_factor * m * r * r)
    edited(parts)


def remove_sphere(model: Model, parts: Parts, index: object) -> None:
    """Remove ball ``index``; the balls after it move down one index."""
    i = index_of("ball", index, parts.state.count)
    model.spheres.remove(i)
    parts.state.remove(i)
    edited(parts)


def move_plane(model: Model, parts: Parts, index: object, position: object, rotation: object) -> None:
    """Put plane ``index``'s centre at ``position`` and/or turn it to ``rotation`` (extrinsic x, y, z
    degrees from the +y plane, as ``add_plane``). Both are checked before either is written."""
    index = index_of("plane", index, model.planes.count)
    pose = parts.state.planes
    limit = validation.MAX_COORDINATE
    center = None if position is None else validation.vector("position", position, limit=limit)
    q = None if rotation is None else quaternion.from_euler_xyz(validation.vector("rotation", rotation))
    if center is not None:
        pose.center[index] = center
    if q is not None:
        moving_planes.set_orientation(pose, index, q)
    edited(parts)


def first_overlap(model: Model, state: State, position: object, radius: float) -> str | None:
    """What a ball of ``radius`` at ``position`` would overlap ("ball 3", "plane 0"), or None: the
    check a ball added by hand should pass (``add_sphere`` itself allows overlaps, which the step
    pushes apart)."""
    p = validation.vector("position", position, limit=validation.MAX_COORDINATE)
    r = validation.number("radius", radius, positive=True)
    balls = state.body[:, X] - p
    reach = model.spheres.radius + r
    hit = np.flatnonzero(exact.dot_rows(balls, balls) < reach * reach)
    if hit.size:
        return f"ball {hit[0]}"
    pose, shape = state.planes, model.planes
    k = np.arange(shape.count)
    points = np.broadcast_to(p, (shape.count, 3))
    near = geometry.closest_point_on_planes(points, k, pose.center, pose.axis_u, pose.axis_v, shape.half_size)
    gap = near - points
    hit = np.flatnonzero(exact.dot_rows(gap, gap) < r * r)
    return f"plane {hit[0]}" if hit.size else None


def edited(parts: Parts) -> None:
    """Something a step reads was changed by hand: the kept pairs and warm start are found afresh,
    and sleeping balls wake."""
    parts.pairs = PairCache()
    parts.warm = WarmStart()
    parts.state.sleep.wake_all()
