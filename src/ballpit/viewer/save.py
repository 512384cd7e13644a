"""Ctrl+S: the scene as it stands now (moved planes, added balls, every ball's state, the view) as a new
TOML scene file beside the original, which loads back into the same World.

The original file is edited with tomlkit, so its comments and layout stay wherever its values still
hold: tables of planes that did not move and balls that did not change are left as written; a ball's
``[[sphere]]`` table gets its new position, velocity, spin and orientation in place; ``[[grid]]`` blocks
(which describe balls only at the start) become one ``[[sphere]]`` per ball once their balls have moved.
Only the public World API is read. Numbers are written with Python's shortest round-trip repr, so they
load back to the same doubles.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import tomlkit
from tomlkit.items import AoT, Table

from .camera import Camera
from .simulation import Simulation

SAVED_SUFFIX = re.compile(r"-saved-\d+$")


# ---------------------------------------------------------------------- numbers and values
def euler_xyz_degrees(q: object) -> list[float]:
    """The scene file's plane ``rotation`` for a unit quaternion (x, y, z, w): extrinsic x, y, z
    Euler angles in degrees (R = Rz·Ry·Rx), as ``Rotation.from_euler("xyz", ...)`` reads them."""
    x, y, z, w = (float(c) for c in np.asarray(q, dtype=float) / np.linalg.norm(q))
    r00 = 1 - 2 * (y * y + z * z)
    r10 = 2 * (x * y + z * w)
    r20 = 2 * (x * z - y * w)
    r21 = 2 * (y * z + x * w)
    r22 = 1 - 2 * (x * x + y * y)
    cos_b = math.hypot(r00, r10)
    b = math.atan2(-r20, cos_b)
    if cos_b > 1e-9:
        a = math.atan2(r21, r22)
        c = math.atan2(r10, r00)
    else:  # gimbal lock: only a ± c is defined; put it all in c
        r01 = 2 * (x * y - z * w)
        r11 = 1 - 2 * (x * x + z * z)
        a, c = 0.0, math.atan2(-r01, r11)
    return [math.degrees(a), math.degrees(b), math.degrees(c)]


def _array(values: object) -> tomlkit.items.Array:
    """An inline TOML array of floats (exact: repr round-trips)."""
    out = tomlkit.array()
    out.extend(float(v) for v in np.asarray(values, dtype=float).reshape(-1))
    return out


def _color(rgb: object) -> object:
    """ "#rrggbb" when that is exact, else [r, g, b]."""
    rgb = np.asarray(rgb, dtype=float).reshape(3)
    codes = np.round(rgb * 255.0)
    if np.array_equal(codes / 255.0, rgb):
        return "#" + "".join(f"{int(c):02x}" for c in codes)
    return _array(rgb)


def _set(table: Table, key: str, value: object) -> None:
    """Set ``key``; tomlkit keeps the line's place and comment when it is there already."""
    table[key] = value


# ---------------------------------------------------------------------- tables
def _world_table(world: object, timestep: float) -> Table:
    table = tomlkit.table()
    table["gravity"] = _array(world.gravity)  # type: ignore[attr-defined]
    table["integrator"] = world.integrator  # type: ignore[attr-defined]
    table["timestep"] = float(timestep)
    table["linear_drag"] = float(world.linear_drag)  # type: ignore[attr-defined]
    table["angular_drag"] = float(world.angular_drag)  # type: ignore[attr-defined]
    if world.restitution_threshold is not None:  # type: ignore[attr-defined]
        table["restitution_threshold"] = float(world.restitution_threshold)  # type: ignore[attr-defined]
    if world.sleep:  # type: ignore[attr-defined]
        table["sleep"] = True
    if world.substeps != 1:  # type: ignore[attr-defined]
        table["substeps"] = int(world.substeps)  # type: ignore[attr-defined]
    return table


def _plane_table(plane: object, color: object) -> Table:
    table = tomlkit.table()
    _place_plane(table, plane)
    if plane.size is not None:  # type: ignore[attr-defined]
        table["size"] = _array(plane.size)  # type: ignore[attr-defined]
    for key in ("restitution", "friction", "rolling_friction"):
        table[key] = float(getattr(plane, key))
    table["color"] = _color(color)
    return table


def _place_plane(table: Table, plane: object) -> None:
    """Where the plane is now: its position and rotation (a given ``normal`` no longer holds)."""
    if "normal" in table:
        del table["normal"]
    _set(table, "position", _array(plane.position))  # type: ignore[attr-defined]
    _set(table, "rotation", _array(euler_xyz_degrees(plane.orientation)))  # type: ignore[attr-defined]


def _plane_motion(table: Table, velocity: np.ndarray, spin: np.ndarray) -> None:
    """A plane's own motion, written only when it has one (scene files without it stay loadable)."""
    for key, value in (("velocity", velocity), ("angular_velocity", spin)):
        if np.any(value != 0.0):
            _set(table, key, _array(value))
        elif key in table:
            del table[key]


def _ball_state(table: Table, ball: object) -> None:
    for key in ("position", "velocity", "angular_velocity", "orientation"):
        _set(table, key, _array(getattr(ball, key)))


def _sphere_table(ball: object, color: object) -> Table:
    table = tomlkit.table()
    _ball_state(table, ball)
    table["radius"] = float(ball.radius)  # type: ignore[attr-defined]
    table["mass"] = float(ball.mass)  # type: ignore[attr-defined]
    for key in ("restitution", "friction", "rolling_friction"):
        table[key] = float(getattr(ball, key))
    if ball.hollow:  # type: ignore[attr-defined]
        table["hollow"] = True
    table["color"] = _color(color)
    return table


def _aot(doc: tomlkit.TOMLDocument, name: str) -> AoT:
    if name not in doc:
        doc.append(name, tomlkit.aot())
    return doc[name]


def _same_state(a: object, b: object, n: int) -> bool:
    """Whether the first ``n`` balls of worlds a and b are in exactly the same state."""
    columns = ("positions", "velocities", "angular_velocities", "orientations")
    return all(
        np.array_equal(np.asarray(getattr(a.spheres, c))[:n], np.asarray(getattr(b.spheres, c))[:n])  # type: ignore[attr-defined]
        for c in columns
    )


def scene_document(
    sim: Simulation, camera: Camera, plane_motion: dict[int, tuple[np.ndarray, np.ndarray]] | None = None
) -> tomlkit.TOMLDocument:
    """The scene as it stands, as a TOML document built on the original file's text when there is one.

    ``plane_motion`` gives planes' own (velocity, angular velocity) where the live ones are not theirs
    (a selected plane is moved by held keys, which are not saved).
    """
    world, initial, look = sim.world, sim.initial, sim.appearance
    path = sim.path
    text = path.read_text(encoding="utf-8") if path is not None and path.is_file() else ""
    doc = tomlkit.parse(text)

    if "world" not in doc:
        doc.append("world", _world_table(world, sim.timestep))
    else:
        if doc["world"].get("integrator", "rk4") != world.integrator:
            _set(doc["world"], "integrator", world.integrator)
        if doc["world"].get("substeps", 1) != world.substeps:
            _set(doc["world"], "substeps", int(world.substeps))

    look_distance = float(np.linalg.norm(look.camera_look_at - look.camera_position)) or 10.0
    view = doc["camera"] if "camera" in doc else tomlkit.table()
    _set(view, "position", _array(camera.position))
    _set(view, "look_at", _array(camera.position + camera.forward * look_distance))
    if "camera" not in doc:
        doc.append("camera", view)

    planes = _aot(doc, "plane") if len(world.planes) else None
    for i, plane in enumerate(world.planes):
        if i >= len(planes):
            planes.append(_plane_table(plane, look.plane_colors[i]))
        else:
            before = initial.planes[i] if i < len(initial.planes) else None
            moved = before is None or not (
                np.array_equal(plane.position, before.position)
                and np.array_equal(plane.orientation, before.orientation)
            )
            if moved:
                _place_plane(planes[i], plane)
        velocity, spin = (plane_motion or {}).get(i, (plane.velocity, plane.angular_velocity))
        _plane_motion(planes[i], np.asarray(velocity, dtype=float), np.asarray(spin, dtype=float))

    _write_balls(doc, sim)
    return doc


def _write_balls(doc: tomlkit.TOMLDocument, sim: Simulation) -> None:
    """Balls the document describes keep their tables (in place, with new state, if they moved); the
    rest (added in the viewer, a moved grid's, or all of a world built in code) get new tables."""
    world, initial, colors = sim.world, sim.initial, sim.appearance.sphere_colors
    spheres = world.spheres
    first = len(initial.spheres)  # the scene's own balls; later ones were added in the viewer
    tables = min(len(doc["sphere"]) if "sphere" in doc else 0, first)  # [[sphere]] i is ball i
    same = _same_state(world, initial, first)
    if "sphere" not in doc and "grid" not in doc:
        start = 0  # nothing describes the balls yet
    elif same and ("grid" not in doc or len(spheres) == first):
        start = first
    else:
        if not same:
            for i in range(tables):
                _ball_state(doc["sphere"][i], spheres[i])
        if "grid" in doc:  # a grid says where its balls start, and its balls load after every
            del doc["grid"]  # [[sphere]]: they get [[sphere]] tables of their own, in order
        start = tables
    for i in range(start, len(spheres)):
        _aot(doc, "sphere").append(_sphere_table(spheres[i], colors[i]))


# ---------------------------------------------------------------------- the file
def saved_path(original: Path | None, directory: Path | None = None) -> Path:
    """The first ``<name>-saved-<n>.toml`` that does not exist yet, beside the original (or in
    ``directory``)."""
    stem = SAVED_SUFFIX.sub("", original.stem) if original is not None else "untitled"
    folder = directory if directory is not None else (original.parent if original is not None else Path.cwd())
    n = 1
    while (folder / f"{stem}-saved-{n}.toml").exists():
        n += 1
    return folder / f"{stem}-saved-{n}.toml"


def _folder_for(original: Path | None) -> Path:
    """Beside the original, unless that is the bundled scenes (or not writable): then the current
    directory."""
    import os

    from ballpit.scene import bundled_scenes_dir

    if original is None:
        return Path.cwd()
    folder = original.resolve().parent
    if folder == bundled_scenes_dir().resolve() or not os.access(folder, os.W_OK):
        return Path.cwd()
    return folder


def save_scene(
    sim: Simulation, camera: Camera, plane_motion: dict[int, tuple[np.ndarray, np.ndarray]] | None = None
) -> Path:
    """Write the scene as it stands to a new file (never overwriting one); returns its path."""
    text = tomlkit.dumps(scene_document(sim, camera, plane_motion))
    folder = _folder_for(sim.path)
    while True:
        path = saved_path(sim.path, folder)
        try:
            with open(path, "x", encoding="utf-8") as f:
                f.write(text)
            return path.resolve()
        except FileExistsError:  # someone took the name since we looked
            continue
