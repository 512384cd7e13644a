"""Narrow phase: exact distances and contact frames for sphere–rectangle and sphere–sphere pairs.

A plane is a rectangle (or an unbounded plane, with infinite half extents) in the frame
(center, u, v, normal). The closest point on it to a ball's centre is found by clamping the in-plane
coordinates, which covers the face, the four edges and the four corners exactly. The contact normal
points from the closest point to the ball's centre, so planes are two-sided.
"""

from __future__ import annotations

import numpy as np

from ..core.settings import TINY


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
    # clamped as np.clip does (its bounds are never zero, so no sign of zero can differ), without its
    # wrapper's cost
    du_max, dv_max = half_size[plane, 0], half_size[plane, 1]
    du = np.minimum(np.maximum(np.einsum("ij,ij->i", d, u), -du_max), du_max)
    dv = np.minimum(np.maximum(np.einsum("ij,ij->i", d, v), -dv_max), dv_max)
    return c + du[:, None] * u + dv[:, None] * v


def sphere_plane(
    x: np.ndarray,
    radius: np.ndarray,
    sphere: np.ndarray,
    plane: np.ndarray,
    side: np.ndarray,
    center: np.ndarray,
    normal: np.ndarray,
    axis_u: np.ndarray,
    axis_v: np.ndarray,
    half_size: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap, unit normal (towards the ball) and contact point for each (sphere, plane) pair, with the
    planes' frames given by their centre, normal, axes and half extents.

    ``side`` (±1) is the side of the plane each ball started the step on. A ball whose centre has
    crossed the face (which continuous detection prevents, but an edited scene can cause) is pushed back
    to the side it came from instead of through.
    """
    p = x.take(sphere, axis=0)  # rows by index: several times faster than x[sphere]
    point = closest_point_on_planes(p, plane, center, axis_u, axis_v, half_size)
    delta = p - point
    dist = np.sqrt(np.einsum("ij,ij->i", delta, delta))
    plane_normal = normal[plane]
    signed = np.einsum("ij,ij->i", delta, plane_normal)
    in_plane = dist - np.abs(signed)  # zero when the closest point is on the face, not an edge or corner
    on_face = in_plane <= TINY * np.maximum(dist, 1.0)
    crossed = on_face & (signed * side <= 0.0)
    safe = np.where(dist > TINY, dist, 1.0)
    normal = np.where(on_face[:, None], side[:, None] * plane_normal, delta / safe[:, None])
    gap = np.where(crossed, -np.abs(signed), dist) - radius[sphere]
    return gap, normal, point


def sphere_sphere(
    x: np.ndarray, radius: np.ndarray, i: np.ndarray, j: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap, unit normal (from j towards i) and contact point (middle of the gap) for each pair."""
    xj = x.take(j, axis=0)  # rows by index: several times faster than x[j]
    delta = x.take(i, axis=0) - xj
    dist = np.sqrt(np.einsum("ij,ij->i", delta, delta))
    coincident = dist <= TINY
    normal = delta / np.maximum(dist, TINY)[:, None]
    if np.count_nonzero(
        coincident
    ):  # coincident centres have no normal: +y, so the pair separates vertically
        normal[coincident] = (0.0, 1.0, 0.0)
    rj = radius[j]
    gap = dist - radius[i] - rj
    point = xj + normal * (rj + 0.5 * gap)[:, None]
    return gap, normal, point
