"""A free-fly camera: position, yaw and pitch, with pyrr view and projection matrices.

Matrices follow pyrr's row-vector layout (a point transforms as ``[x, y, z, 1] @ view @ projection``),
which is exactly what ``glUniformMatrix4fv(..., GL_FALSE, ...)`` expects in memory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pyrr import matrix44

WORLD_UP = np.array([0.0, 1.0, 0.0])
PITCH_LIMIT = math.radians(89.0)


@dataclass
class Camera:
    """Where the viewer looks from. ``yaw`` 0 looks along −z, positive yaw turns right (towards +x);
    ``pitch`` is up from the horizon. Angles in radians, distances in metres."""

    position: np.ndarray = field(default_factory=lambda: np.array([0.0, 4.0, 12.0]))
    yaw: float = 0.0
    pitch: float = 0.0
    fov_y_degrees: float = 50.0
    near: float = 0.05
    far: float = 1500.0
    speed: float = 4.0  # fly speed, m/s
    look_sensitivity: float = 0.004  # radians per mouse pixel
    # the share of the window's width a panel covers at its left: the whole view is drawn in the rest,
    # centred there and as wide as it (so it shows a little more above and below)
    inset: float = 0.0

    def __post_init__(self) -> None:
        self.position = np.asarray(self.position, dtype=float).copy()

    @classmethod
    def looking_at(cls, position: object, target: object, **kwargs: float) -> Camera:
        """A camera at ``position`` looking at ``target``."""
        position = np.asarray(position, dtype=float)
        d = np.asarray(target, dtype=float) - position
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            d, length = np.array([0.0, 0.0, -1.0]), 1.0
        yaw = math.atan2(d[0], -d[2])
        pitch = float(np.clip(math.asin(np.clip(d[1] / length, -1.0, 1.0)), -PITCH_LIMIT, PITCH_LIMIT))
        return cls(position=position, yaw=yaw, pitch=pitch, **kwargs)

    def look_from(self, position: object, target: object) -> None:
        """Move to ``position`` and look at ``target`` (Home: back to the scene's view); speed is kept."""
        other = Camera.looking_at(position, target)
        self.position, self.yaw, self.pitch = other.position, other.yaw, other.pitch

    # ------------------------------------------------------------------ directions
    @property
    def forward(self) -> np.ndarray:
        """Unit look direction."""
        cp = math.cos(self.pitch)
        return np.array([cp * math.sin(self.yaw), math.sin(self.pitch), -cp * math.cos(self.yaw)])

    @property
    def right(self) -> np.ndarray:
        """Unit horizontal direction to the right of the view."""
        return np.array([math.cos(self.yaw), 0.0, math.sin(self.yaw)])

    # ------------------------------------------------------------------ motion
    def fly(self, direction: np.ndarray, dt: float, multiplier: float = 1.0) -> None:
        """Move by ``direction`` = (right, up, forward) at ``speed × multiplier`` for ``dt`` seconds.
        Forward follows the look direction; up is the world's up."""
        right, up, forward = np.asarray(direction, dtype=float)
        step = right * self.right + up * WORLD_UP + forward * self.forward
        self.position = self.position + step * (self.speed * multiplier * dt)

    def look(self, dx: float, dy: float) -> None:
        """Turn by a mouse motion of (dx, dy) pixels; +dx turns right, +dy (mouse up) looks up."""
        self.yaw = (self.yaw + dx * self.look_sensitivity + math.pi) % (2 * math.pi) - math.pi
        self.pitch = float(np.clip(self.pitch + dy * self.look_sensitivity, -PITCH_LIMIT, PITCH_LIMIT))

    # ------------------------------------------------------------------ matrices
    def view_matrix(self) -> np.ndarray:
        """World → eye, float32, pyrr layout."""
        return matrix44.create_look_at(
            self.position, self.position + self.forward, WORLD_UP, dtype=np.float32
        )

    def projection_matrix(self, aspect: float) -> np.ndarray:
        """Eye → clip for a viewport of width/height ``aspect``, float32, pyrr layout."""
        projection = matrix44.create_perspective_projection(
            self.fov_y_degrees, aspect, self.near, self.far, dtype=np.float32
        )
        if self.inset:  # NDC x → (1 − inset)·x + inset, y → (1 − inset)·y
            projection[0, 0] *= 1.0 - self.inset
            projection[1, 1] *= 1.0 - self.inset
            projection[2, 0] -= self.inset  # clip x gains inset·w (w = −z_eye)
        return projection

    def view_projection(self, aspect: float) -> np.ndarray:
        """World → clip."""
        return (self.view_matrix().astype(float) @ self.projection_matrix(aspect).astype(float)).astype(
            np.float32
        )

    def project(self, points: object, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (x right, y down from the top row) and view depth of world points.

        Returns ``(pixels (..., 2), depth (...))``; depth is the distance in front of the camera
        (negative behind it).
        """
        p = np.asarray(points, dtype=float)
        homo = np.concatenate([p, np.ones((*p.shape[:-1], 1))], axis=-1)
        clip = homo @ self.view_projection(width / height).astype(float)
        ndc = clip[..., :2] / clip[..., 3:4]
        pixels = np.stack([(ndc[..., 0] + 1.0) * 0.5 * width, (1.0 - ndc[..., 1]) * 0.5 * height], axis=-1)
        return pixels, clip[..., 3]
