"""Scene files: TOML text -> a ready World, its appearance, timestep and duration.

A scene has ``[world]`` and ``[camera]`` tables and any number of ``[[plane]]``, ``[[sphere]]`` and
``[[grid]]`` (a block of nx×ny×nz balls) tables. Every key is checked before anything is built, and
every error is one ``SceneError`` line:

    scenes/x.toml:12: sphere #3: key 'radius': must be positive, got -1.0

One module per job: ``reading`` (file, TOML, SceneError), ``lines`` (the line index), ``fields``
(typed readers), ``schema`` (keys and defaults), ``builder``, ``balls`` (the batch of balls),
``layout`` (grids), ``overlap`` (the start-overlap check), ``colours`` and ``appearance`` (what a
scene holds besides the physics), ``loading`` (entry points, bundled scenes).
"""

from .appearance import Appearance, Scene, default_appearance, frame_camera, scene_of
from .colours import PALETTE
from .loading import (
    bundled_scenes,
    bundled_scenes_dir,
    default_scene_path,
    load_scene,
    read_scene,
    resolve_scene_path,
)
from .overlap import first_overlap
from .reading import SceneError

__all__ = [
    "PALETTE",
    "Appearance",
    "Scene",
    "SceneError",
    "bundled_scenes",
    "bundled_scenes_dir",
    "default_appearance",
    "default_scene_path",
    "first_overlap",
    "frame_camera",
    "load_scene",
    "read_scene",
    "resolve_scene_path",
    "scene_of",
]
