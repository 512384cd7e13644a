"""Narrow phase: exact distances and contact frames for sphere–rectangle and sphere–sphere pairs.

A plane is a rectangle (or an unbounded plane, with infinite half extents) in the frame
(center, u, v, normal). The closest point on it to a ball's centre is found by clamping the in-plane
coordinates, which covers the face, the four edges and the four corners exactly. The contact normal
points from the closest point to the ball's centre, so planes are two-sided.
"""

from __future__ import annotations

import numpy as np


def closest_point_on_planes(
    points: np.ndarray,
    plane: np.ndarray,
    center: np.ndarray,
    axis_u: np.ndarray,
    axis_v: np.ndarray,
    half_size: np.ndarray,
) -> np.ndarray:
    """Closest point on rectangle ``plane[k]`` to ``points[k]`` for every k (face, edge or corner)."""
    c = center[plane]
    u = axis_u[plane]
    v = axis_v[plane]
    d = points - c
    du = np.clip(np.einsum("ij,ij->i", d, u), -half_size[plane, 0], half_size[plane, 0])
    dv = np.clip(np.einsum("ij,ij->i", d, v), -half_size[plane, 1], half_size[plane, 1])
    return c + du[:, None] * u + dv[:, None] * v
