"""What a scene holds besides the physics, and the defaults for a World built in code.

``Appearance`` is how the scene looks (camera start, ball and plane colours, its file); ``Scene`` is a
World together with its appearance, timestep and suggested duration. A scene file gives them through
``read_scene``; a World built in code gets them from ``scene_of``, with the camera framing the scene
and the palette colours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..physics import DEFAULT_TIMESTEP, World
from .colours import palette_colors, plane_colors


@dataclass(eq=False)
class Appearance:
    """The camera start and the colours, one row per ball and per plane in world order.

    Arrays are read-only; replace one to recolour.
    """

    path: Path | None  # the scene file, or None for a World built in code
    camera_position: np.ndarray  # (3,) m
    camera_look_at: np.ndarray  # (3,) m
    sphere_colors: np.ndarray  # (N, 3) sRGB 0..1
    plane_colors: np.ndarray  # (P, 3) sRGB 0..1

    @property
    def name(self) -> str:
        """The label the viewer shows: the file's name, or "untitled"."""
        return self.path.name if self.path is not None else "untitled"


@dataclass(frozen=True, eq=False)
class Scene:
    """A World with its appearance, the timestep to run it at and a suggested run length."""

    world: World
    appearance: Appearance
    timestep: float = DEFAULT_TIMESTEP  # s per physics step
    duration: float | None = None  # s, or None

    @property
    def path(self) -> Path | None:
        return self.appearance.path

    @property
    def name(self) -> str:
        """The scene's name: its file's stem (``slopes``), or "untitled"."""
        return self.path.stem if self.path is not None else "untitled"


def frozen(values: object) -> np.ndarray:
    """A read-only float copy."""
    a = np.array(values, dtype=float)
    a.setflags(write=False)
    return a


def frame_camera(world: World) -> tuple[np.ndarray, np.ndarray]:
    """A camera that sees every ball and finite plane: from the front, a little above (50° tall view)."""
    points = [world.spheres.positions]
    for plane in world.planes:
        if plane.size is not None:
            u, v = plane.axes
            w, d = plane.size
            corners = [
                plane.position + su * 0.5 * w * u + sv * 0.5 * d * v for su in (-1, 1) for sv in (-1, 1)
            ]
            points.append(np.array(corners))
    pts = np.concatenate([p.reshape(-1, 3) for p in points])
    if len(pts) == 0:
        return np.array([0.0, 4.0, 12.0]), np.array([0.0, 2.0, 0.0])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    look_at = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1.0)
    direction = np.array([0.0, 0.35, 1.0])
    direction /= np.linalg.norm(direction)
    distance = 1.15 * radius / math.sin(math.radians(25.0))
    return look_at + distance * direction, look_at


def default_plane_colors(world: World) -> np.ndarray:
    """Each plane's default colour: by restitution, or ground grey for an infinite plane."""
    planes = world.planes
    return plane_colors(planes.restitutions, np.isinf(np.asarray(planes.half_sizes)).all(axis=1))


def default_appearance(world: World, path: Path | str | None = None) -> Appearance:
    """The appearance of a World without a scene file: camera framing it, palette and plane colours."""
    position, look_at = frame_camera(world)
    return Appearance(
        path=Path(path) if path is not None else None,
        camera_position=frozen(position),
        camera_look_at=frozen(look_at),
        sphere_colors=frozen(palette_colors(len(world.spheres))),
        plane_colors=frozen(default_plane_colors(world)),
    )


def scene_of(world: World | Scene, path: Path | str | None = None) -> Scene:
    """A Scene as it is, or a World built in code as a Scene with the default appearance and timestep."""
    if isinstance(world, Scene):
        return world
    return Scene(world, default_appearance(world, path))
