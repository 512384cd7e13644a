"""What the viewer needs from a scene besides the physics: camera start, colours, timestep, name.

Scenes loaded by ``ballpit.load_scene`` carry this as ``world.scene`` (a SceneInfo); a World built in
code has none, so every field has a default here.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_TIMESTEP = 1.0 / 240.0
DEFAULT_CAMERA_POSITION = (0.0, 4.0, 12.0)
DEFAULT_CAMERA_LOOK_AT = (0.0, 2.0, 0.0)

# Ball colours (sRGB, 0..1) used when a scene gives none: saturated, easy to tell apart.
PALETTE = np.array(
    [
        [0.878, 0.282, 0.184],  # red
        [0.161, 0.502, 0.725],  # blue
        [0.153, 0.682, 0.376],  # green
        [0.953, 0.612, 0.071],  # orange
        [0.557, 0.267, 0.678],  # purple
        [0.086, 0.627, 0.522],  # teal
        [0.914, 0.302, 0.553],  # pink
        [0.945, 0.769, 0.059],  # yellow
    ]
)

# Plane colour by restitution: dead (0) slate blue → medium green → bouncy (≥1) orange.
_RESTITUTION_STOPS = np.array([0.0, 0.5, 1.0])
_RESTITUTION_COLORS = np.array([[0.29, 0.36, 0.50], [0.30, 0.56, 0.42], [0.93, 0.55, 0.20]])
GROUND_COLOR = (0.55, 0.57, 0.60)  # infinite planes: a neutral ground, as scene files default it


def restitution_colors(restitutions: object) -> np.ndarray:
    """(P, 3) plane colours showing bounciness: slate blue at 0, green at 0.5, orange at 1 and above."""
    e = np.clip(np.asarray(restitutions, dtype=float).reshape(-1), 0.0, 1.0)
    return np.stack([np.interp(e, _RESTITUTION_STOPS, _RESTITUTION_COLORS[:, k]) for k in range(3)], axis=-1)


def default_plane_colors(planes: object) -> np.ndarray:
    """Finite planes coloured by restitution, infinite ones (the ground) neutral grey."""
    colors = restitution_colors(planes.restitutions)  # type: ignore[attr-defined]
    infinite = np.isinf(np.asarray(planes.half_sizes)).all(axis=1)  # type: ignore[attr-defined]
    colors[infinite] = GROUND_COLOR
    return colors


@dataclass
class Appearance:
    """The scene's non-physical settings, with defaults filled in."""

    path: Path | None
    name: str
    camera_position: np.ndarray
    camera_look_at: np.ndarray
    sphere_colors: np.ndarray  # (N, 3) sRGB 0..1
    plane_colors: np.ndarray  # (P, 3) sRGB 0..1
    timestep: float


def _colors(value: object, count: int, fallback: np.ndarray) -> np.ndarray:
    """``value`` as (count, 3) colours when it fits, else ``fallback``."""
    if value is not None:
        arr = np.asarray(value, dtype=float)
        if arr.shape == (count, 3) and np.isfinite(arr).all():
            return np.clip(arr, 0.0, 1.0)
    return fallback


def appearance_of(world: object, path: Path | None = None) -> Appearance:
    """Read ``world.scene`` if the world has one, defaulting whatever is missing."""
    info = getattr(world, "scene", None)
    path = getattr(info, "path", None) or path
    path = Path(path) if path is not None else None
    n = len(world.spheres)  # type: ignore[attr-defined]
    planes = world.planes  # type: ignore[attr-defined]
    palette = PALETTE[np.arange(n) % len(PALETTE)]
    timestep = getattr(info, "timestep", None)
    if timestep is None or not np.isfinite(timestep) or timestep <= 0:
        timestep = DEFAULT_TIMESTEP
    camera_position = getattr(info, "camera_position", None)
    camera_look_at = getattr(info, "camera_look_at", None)
    return Appearance(
        path=path,
        name=path.name if path is not None else "untitled",
        camera_position=np.asarray(
            DEFAULT_CAMERA_POSITION if camera_position is None else camera_position, dtype=float
        ),
        camera_look_at=np.asarray(
            DEFAULT_CAMERA_LOOK_AT if camera_look_at is None else camera_look_at, dtype=float
        ),
        sphere_colors=_colors(getattr(info, "sphere_colors", None), n, palette),
        plane_colors=_colors(getattr(info, "plane_colors", None), len(planes), default_plane_colors(planes)),
        timestep=float(timestep),
    )
