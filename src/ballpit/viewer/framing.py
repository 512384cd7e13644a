"""Framing a scene with no ground: its balls and squares fill the view.

A scene on an infinite plane is framed by its own ``[camera]``. One with no ground (a pile in a box,
the gas cube, Newton's cradle, the Galilean cannon) floats in empty space, and the distance its file
gives is right only for one window shape. ``fit`` keeps the file's view direction and look-at point
and moves the camera along that direction until the scene's bounding box just fills the part of the
window right of the panel (``FILL`` of it). No GL here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..physics.core import quaternion
from .camera import Camera

if TYPE_CHECKING:
    from .handover import Shown

FILL = 0.85  # the share of the visible width or height the scene's box fills


def scene_box(shown: Shown) -> np.ndarray | None:
    """The 8 corners of the box round every ball and finite plane of a hand-over, or None when some
    plane is infinite (a ground: the scene's own camera frames it)."""
    half = np.asarray(shown.plane_half_sizes, dtype=float).reshape(-1, 2)
    if len(half) and np.isinf(half).any():
        return None
    points = []
    if shown.ball_count:
        r = np.asarray(shown.radii, dtype=float)[:, None]
        points += [shown.positions - r, shown.positions + r]
    if len(half):
        q = np.asarray(shown.plane_orientations, dtype=float)
        u = quaternion.rotate(q, np.broadcast_to([1.0, 0.0, 0.0], (len(q), 3)))
        v = quaternion.rotate(q, np.broadcast_to([0.0, 0.0, 1.0], (len(q), 3)))
        for su in (-1.0, 1.0):
            for sv in (-1.0, 1.0):
                points.append(shown.plane_centers + su * half[:, :1] * u + sv * half[:, 1:] * v)
    if not points:
        return None
    everything = np.vstack(points)
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def fits(camera: Camera, corners: np.ndarray, width: int, height: int, fill: float = FILL) -> bool:
    """Whether every corner is in front of the camera and inside ``fill`` of the visible area."""
    pixels, depth = camera.project(corners, width, height)
    if (depth <= camera.near).any():
        return False
    left = camera.inset * width
    cx, cy = left + (width - left) / 2, height / 2
    half_w, half_h = fill * (width - left) / 2, fill * height / 2
    return bool((np.abs(pixels[:, 0] - cx) <= half_w).all() and (np.abs(pixels[:, 1] - cy) <= half_h).all())


def fit(camera: Camera, look_at: object, corners: np.ndarray, width: int, height: int) -> None:
    """Move ``camera`` along the line from ``look_at`` through it to the nearest distance at which the
    box ``corners`` fits (bisection over the distance; the view direction is kept)."""
    target = np.asarray(look_at, dtype=float)
    offset = np.asarray(camera.position, dtype=float) - target
    length = float(np.sqrt((offset * offset).sum()))
    if length < 1e-9:
        return
    direction = offset / length

    def placed(distance: float) -> bool:
        camera.position = target + direction * distance
        return fits(camera, corners, width, height)

    near, far = 1e-3, max(length, 1.0)
    while not placed(far) and far < 1e5:
        far *= 2.0
    for _ in range(40):
        middle = 0.5 * (near + far)
        near, far = (near, middle) if placed(middle) else (middle, far)
    camera.position = target + direction * far
