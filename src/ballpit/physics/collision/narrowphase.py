"""Narrow phase: every kept pair measured at the current positions (gap, normal and point).

The geometry itself (sphere–rectangle with faces, edges and corners; sphere–sphere) is in
``geometry.py``; this stage gathers it for the kept pairs into one ``ContactPoints``, sphere–plane
pairs first. A plane's contacts name the static row N as their second body, so the solver treats a
plane as a ball that never moves.
"""

from __future__ import annotations

import numpy as np

from ..core.contacts import SPHERE_PLANE, SPHERE_SPHERE, ContactPoints
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
    gs, ns, ps = geometry.sphere_sphere(x, radius, c.pair_i, c.pair_j)
    static = np.full(len(c.sphere), model.spheres.count)
    kind = np.full(len(gp) + len(gs), SPHERE_SPHERE, np.int8)  # one byte a pair
    kind[: len(gp)] = SPHERE_PLANE
    return ContactPoints(
        kind=kind,
        a=np.concatenate((c.sphere, c.pair_i)),
        b=np.concatenate((static, c.pair_j)),
        other=np.concatenate((c.plane, c.pair_j)),
        gap=np.concatenate((gp, gs)),
        normal=np.concatenate((np_, ns)),
        point=np.concatenate((pp, ps)),
    )
