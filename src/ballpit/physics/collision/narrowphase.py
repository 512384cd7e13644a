"""Narrow phase: every kept pair measured at the current positions (gap, normal and point).

The geometry itself (sphere–rectangle with faces, edges and corners; sphere–sphere) is in
``geometry.py``; this stage gathers it for the kept pairs into one ``ContactPoints``, sphere–plane
pairs first. A plane's contacts name the static row N as their second body, so the solver treats a
plane as a ball that never moves.
"""

from __future__ import annotations

import numpy as np

from ..core.contacts import SPHERE_PLANE, SPHERE_SPHERE, ContactPoints
from ..core.settings import SWEEP_CHUNK
from ..core.state import State, X
from ..dynamics.model import Model
from . import geometry
from .pairs import KeptPairs


def contact_points(model: Model, state: State, pairs: KeptPairs) -> ContactPoints:
    """Gap, normal and point of every kept pair at the current positions."""
    x, radius = state.body[:, X], model.spheres.radius
    c = pairs
    pose = state.planes
    gp, np_, pp = geometry.sphere_plane(
        x,
        radius,
        c.sphere,
        c.plane,
        c.side,
        pose.center,
        pose.normal,
        pose.axis_u,
        pose.axis_v,
        model.planes.half_size,
    )
    # the pairs' own index type (int32 while the balls' rows fit, ``pairs.find_pairs``): 4 bytes an
    # index, not 8, in every array the frame takes of them
    index = c.pair_i.dtype
    static = np.full(len(c.sphere), model.spheres.count, index)
    kind = np.full(len(gp) + len(c.pair_i), SPHERE_SPHERE, np.int8)  # one byte a pair
    kind[: len(gp)] = SPHERE_PLANE
    gap, normal, point = _measured(x, radius, c.pair_i, c.pair_j, (gp, np_, pp))
    return ContactPoints(
        kind=kind,
        a=np.concatenate((c.sphere, c.pair_i), dtype=index),
        b=np.concatenate((static, c.pair_j), dtype=index),
        other=np.concatenate((c.plane, c.pair_j), dtype=index),
        gap=gap,
        normal=normal,
        point=point,
    )


def _measured(
    x: np.ndarray, radius: np.ndarray, i: np.ndarray, j: np.ndarray, first: tuple[np.ndarray, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap, normal and point of the sphere pairs ``i``, ``j`` after those of ``first`` (the plane
    contacts'). Beyond SWEEP_CHUNK pairs they are measured a chunk at a time into the whole arrays:
    the temporaries of a chunk, not two copies of every pair's normal and point."""
    if len(i) <= SWEEP_CHUNK:
        return tuple(
            np.concatenate(pair) for pair in zip(first, geometry.sphere_sphere(x, radius, i, j), strict=True)
        )
    p = len(first[0])
    whole = tuple(np.empty((p + len(i), *part.shape[1:])) for part in first)
    for out, part in zip(whole, first, strict=True):
        out[:p] = part
    x = np.ascontiguousarray(x)  # gathered rows come from a copy: taking from a view copies it each time
    for lo in range(0, len(i), SWEEP_CHUNK):
        hi = min(lo + SWEEP_CHUNK, len(i))
        measured = geometry.sphere_sphere(x, radius, i[lo:hi], j[lo:hi])
        for out, part in zip(whole, measured, strict=True):
            out[p + lo : p + hi] = part
    return whole
