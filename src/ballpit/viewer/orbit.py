"""The orbit camera beside the free-fly one (as MuJoCo's and PyBullet's viewers): dragging turns the
camera about a target, scrolling zooms towards it, the middle button pans both, and a followed ball
carries the target with it. It moves the same ``Camera`` (position, yaw, pitch) the free-fly keys do,
so switching back to flying starts from where the orbit left the camera. No GL here.
"""

from __future__ import annotations

import math

import numpy as np

from .camera import PITCH_LIMIT, Camera

ZOOM_FACTOR = 0.85  # distance factor per scroll notch towards the target
DISTANCE_RANGE = (0.05, 2000.0)
ORBIT_SENSITIVITY = 0.006  # radians per pixel dragged


class Orbit:
    """Orbit state: the target (None: the camera flies free) and the ball followed, if any."""

    def __init__(self) -> None:
        self.target: np.ndarray | None = None
        self.follow: int | None = None  # the ball whose centre the target stays on
        self.follow_wanted = False  # the View section's "follow the ball" box

    @property
    def active(self) -> bool:
        return self.target is not None

    def start(self, camera: Camera, target: object, ball: int | None = None) -> None:
        """Orbit ``target`` from where the camera is, looking at it (and follow ``ball`` if asked)."""
        self.target = np.asarray(target, dtype=float).copy()
        self.follow = ball if self.follow_wanted else None
        self._aim(camera, self.distance(camera))

    def stop(self) -> None:
        self.target = None
        self.follow = None

    def distance(self, camera: Camera) -> float:
        if self.target is None:
            return 0.0
        d = np.asarray(camera.position, dtype=float) - self.target
        return float(np.clip(math.sqrt(float((d * d).sum())), *DISTANCE_RANGE))

    def _aim(self, camera: Camera, distance: float) -> None:
        """Place the camera ``distance`` from the target along its own view direction, looking at it."""
        look = Camera.looking_at(camera.position, self.target)
        camera.yaw, camera.pitch = look.yaw, look.pitch
        camera.position = self.target - camera.forward * distance

    def turn(self, camera: Camera, dx: float, dy: float) -> None:
        """Drag by (dx, dy) pixels: the scene turns with the pointer (the camera the other way)."""
        distance = self.distance(camera)
        camera.yaw = (camera.yaw - dx * ORBIT_SENSITIVITY + math.pi) % (2 * math.pi) - math.pi
        camera.pitch = float(np.clip(camera.pitch - dy * ORBIT_SENSITIVITY, -PITCH_LIMIT, PITCH_LIMIT))
        camera.position = self.target - camera.forward * distance

    def zoom(self, camera: Camera, notches: float) -> None:
        """Scroll: up moves towards the target by ``ZOOM_FACTOR`` per notch, down away."""
        distance = float(np.clip(self.distance(camera) * ZOOM_FACTOR**notches, *DISTANCE_RANGE))
        camera.position = self.target - camera.forward * distance

    def pan(self, camera: Camera, dx: float, dy: float, height: int) -> None:
        """Middle-drag by (dx, dy) pixels: target and camera slide with the pointer, in the view plane."""
        from .picking import camera_basis

        right, up, _ = camera_basis(camera)
        per_pixel = 2.0 * self.distance(camera) * math.tan(math.radians(camera.fov_y_degrees) / 2) / height
        shift = -(dx * right + dy * up) * per_pixel
        self.target = self.target + shift
        camera.position = np.asarray(camera.position, dtype=float) + shift

    def carry(self, camera: Camera, point: object) -> None:
        """The followed ball is at ``point`` now: move target and camera by as much as it moved."""
        shift = np.asarray(point, dtype=float) - self.target
        self.target = self.target + shift
        camera.position = np.asarray(camera.position, dtype=float) + shift
