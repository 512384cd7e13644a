"""Picking: rays from the camera through the pointer, and what they hit (balls, planes).

Pure NumPy, no GL: every test is vectorised over all balls or all planes at once. Window coordinates
are pyglet's: x to the right and y up from the window's bottom-left corner, in window pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .camera import WORLD_UP, Camera

# m: an infinite plane is picked only this near the eye. Beyond it the fog (renderer.FOG_DENSITY,
# 0.02/m) leaves under a tenth of it visible, exp(-(0.02 * 76)^2) = 0.1, so a click on what looks like
# the sky just above the horizon does not select the ground hundreds of metres away (and tint it all).
INFINITE_PICK_DISTANCE = 76.0


@dataclass(frozen=True)
class Ray:
    """A half-line ``origin + t·direction``, t ≥ 0, with a unit direction."""

    origin: np.ndarray
    direction: np.ndarray

    def at(self, t: float) -> np.ndarray:
        return self.origin + t * self.direction


@dataclass(frozen=True)
class Hit:
    """The nearest thing a ray hits: ``kind`` is "sphere" or "plane", ``index`` its index in the world."""

    kind: str
    index: int
    distance: float
    point: np.ndarray


def camera_basis(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The camera's unit (right, up, forward) vectors, as its view matrix uses them."""
    forward = camera.forward
    right = np.cross(forward, WORLD_UP)
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def pointer_ray(camera: Camera, x: float, y: float, width: int, height: int) -> Ray:
    """The ray from the eye through window point (x, y) of a ``width`` × ``height`` window."""
    right, up, forward = camera_basis(camera)
    tan_half = math.tan(math.radians(camera.fov_y_degrees) / 2.0)
    keep = 1.0 - camera.inset  # the view fills the part of the window right of the panel
    ndc_x = (2.0 * x / width - 1.0 - camera.inset) / keep
    ndc_y = (2.0 * y / height - 1.0) / keep
    direction = forward + (ndc_x * tan_half * width / height) * right + (ndc_y * tan_half) * up
    return Ray(np.asarray(camera.position, dtype=float).copy(), direction / np.linalg.norm(direction))


def ray_spheres(ray: Ray, centers: np.ndarray, radii: np.ndarray) -> tuple[int, float]:
    """The first ball the ray enters (index, distance along the ray), or (-1, inf).

    A ray starting inside a ball hits that ball at distance 0.
    """
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    if len(centers) == 0:
        return -1, math.inf
    oc = ray.origin - centers
    b = oc @ ray.direction
    c = np.einsum("ij,ij->i", oc, oc) - np.asarray(radii, dtype=float) ** 2
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
    near = -b - root
    far = -b + root
    t = np.where(near >= 0.0, near, np.where(far >= 0.0, 0.0, np.inf))  # inside a ball: distance 0
    t = np.where(disc >= 0.0, t, np.inf)
    k = int(np.argmin(t))
    return (k, float(t[k])) if np.isfinite(t[k]) else (-1, math.inf)


def ray_planes(
    ray: Ray,
    centers: np.ndarray,
    normals: np.ndarray,
    axis_u: np.ndarray,
    axis_v: np.ndarray,
    half_sizes: np.ndarray,
) -> tuple[int, float]:
    """The first plane (finite rectangle or infinite plane) the ray crosses, from either side:
    (index, distance along the ray), or (-1, inf). An infinite plane counts only within
    ``INFINITE_PICK_DISTANCE``."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    if len(centers) == 0:
        return -1, math.inf
    normals = np.asarray(normals, dtype=float).reshape(-1, 3)
    facing = normals @ ray.direction
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.einsum("ij,ij->i", centers - ray.origin, normals) / facing
    t = np.where((np.abs(facing) > 1e-12) & (t >= 0.0), t, np.inf)
    finite_t = np.where(np.isfinite(t), t, 0.0)
    local = ray.origin + finite_t[:, None] * ray.direction - centers
    u = np.einsum("ij,ij->i", local, np.asarray(axis_u, dtype=float).reshape(-1, 3))
    v = np.einsum("ij,ij->i", local, np.asarray(axis_v, dtype=float).reshape(-1, 3))
    half = np.asarray(half_sizes, dtype=float).reshape(-1, 2)
    inside = (np.abs(u) <= half[:, 0]) & (np.abs(v) <= half[:, 1])
    inside &= np.isfinite(half).all(axis=1) | (t <= INFINITE_PICK_DISTANCE)
    t = np.where(inside, t, np.inf)
    k = int(np.argmin(t))
    return (k, float(t[k])) if np.isfinite(t[k]) else (-1, math.inf)


def pick(ray: Ray, world: object) -> Hit | None:
    """The nearest ball or plane of ``world`` along the ray (a ball wins a tie), or None."""
    spheres, planes = world.spheres, world.planes  # type: ignore[attr-defined]
    ball, t_ball = ray_spheres(ray, spheres.positions, spheres.radii)
    axes = [p.axes for p in planes]
    plane, t_plane = ray_planes(
        ray,
        planes.centers,
        planes.normals,
        np.array([a[0] for a in axes]).reshape(-1, 3),
        np.array([a[1] for a in axes]).reshape(-1, 3),
        planes.half_sizes,
    )
    if ball < 0 and plane < 0:
        return None
    if ball >= 0 and t_ball <= t_plane:
        return Hit("sphere", ball, t_ball, ray.at(t_ball))
    return Hit("plane", plane, t_plane, ray.at(t_plane))


def ray_plane_point(ray: Ray, point: np.ndarray, normal: np.ndarray) -> np.ndarray | None:
    """Where the ray (as a full line, either direction) meets the plane through ``point`` with
    ``normal``, or None when it runs parallel to it."""
    facing = float(np.dot(normal, ray.direction))
    if abs(facing) < 1e-9:
        return None
    t = float(np.dot(np.asarray(point, dtype=float) - ray.origin, normal)) / facing
    return ray.at(t)
