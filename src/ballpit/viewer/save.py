"""Ctrl+S: the scene as it stands now (moved planes, added balls, every ball's state, the view) as a new
TOML scene file beside the original, which loads back into the same World. A bundled scene lives inside
the installed package (read-only, or lost on reinstall, or in a checkout's scenes/ where it would pass
for a bundled scene): it is saved in the current directory, as is a scene in a folder that cannot be
written to (``_folder_for``).

The original file is edited with tomlkit, so its comments and layout stay wherever its values still
hold: tables of planes that did not move and balls that did not change are left as written; a ball's
``[[sphere]]`` table gets its new position, velocity, spin and orientation in place; ``[[grid]]`` blocks
(which describe balls only at the start) become one ``[[sphere]]`` per ball once their balls have moved.
Only the public World API is read. Numbers are written with Python's shortest round-trip repr, so they
load back to the same doubles, except round-off: a value below ``ROUND_OFF`` of its quantity's scale
in the scene (the largest position, speed, spin... there, at least 1 in SI units) is written as 0, not
as ``2e-323`` or ``-3.55e-15``.

The file starts with a comment saying it was saved from the original, when, and how far into the run:
the original's own comments, kept below it, describe its start and its run, not this state.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np
import tomlkit
from tomlkit.items import AoT, Table

from ..scene.overlap import deepest_overlap
from ..scene.reading import read_text
from ..scene.schema import OVERLAP_TOLERANCE
from .camera import Camera
from .simulation import Simulation

SAVED_SUFFIX = re.compile(r"-saved-\d+$")
ROUND_OFF = 1e-12  # of a quantity's scale: smaller values are round-off and are written as 0
SAVED_MARK = "# Saved from "  # the first line of the comment ``header`` writes


@dataclass(frozen=True)
class Scales:
    """The size of each kind of quantity in the scene (SI units, at least 1): round-off is measured
    against them."""

    length: float = 1.0
    speed: float = 1.0
    spin: float = 1.0
    unit: float = 1.0  # quaternion components, normals, colours
    degrees: float = 180.0  # Euler angles

    @classmethod
    def of(cls, world: object, camera: Camera) -> Scales:
        """The scales of ``world`` as it stands, seen from ``camera``."""
        s, p = world.spheres, world.planes  # type: ignore[attr-defined]

        def largest(*arrays: object) -> float:
            sizes = [np.abs(np.asarray(a, dtype=float)) for a in arrays]
            finite = [a[np.isfinite(a)] for a in sizes]
            return max([1.0] + [float(a.max()) for a in finite if a.size])

        return cls(
            length=largest(s.positions, s.radii, p.centers, p.half_sizes, camera.position),
            speed=largest(s.velocities, p.velocities, world.gravity),  # type: ignore[attr-defined]
            spin=largest(s.angular_velocities, p.angular_velocities),
        )


def clean(values: object, scale: float) -> np.ndarray:
    """``values`` as floats with round-off (magnitude below ``ROUND_OFF * scale``, and -0.0) made 0."""
    v = np.asarray(values, dtype=float)
    return np.where(np.abs(v) < ROUND_OFF * scale, 0.0, v)


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


def _array(values: object, scale: float = 1.0) -> tomlkit.items.Array:
    """An inline TOML array of floats (exact: repr round-trips), round-off below ``ROUND_OFF * scale``
    written as 0."""
    out = tomlkit.array()
    out.extend(float(v) for v in clean(values, scale).reshape(-1))
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
def _world_table(world: object, timestep: float, sc: Scales) -> Table:
    table = tomlkit.table()
    table["gravity"] = _array(world.gravity, sc.speed)  # type: ignore[attr-defined]
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


def _plane_table(plane: object, color: object, sc: Scales) -> Table:
    table = tomlkit.table()
    _place_plane(table, plane, sc)
    if plane.size is not None:  # type: ignore[attr-defined]
        table["size"] = _array(plane.size, sc.length)  # type: ignore[attr-defined]
    for key in ("restitution", "friction", "rolling_friction"):
        table[key] = float(getattr(plane, key))
    table["color"] = _color(color)
    return table


def _place_plane(table: Table, plane: object, sc: Scales) -> None:
    """Where the plane is now: its position and rotation (a given ``normal`` no longer holds)."""
    if "normal" in table:
        del table["normal"]
    _set(table, "position", _array(plane.position, sc.length))  # type: ignore[attr-defined]
    angles = euler_xyz_degrees(plane.orientation)  # type: ignore[attr-defined]
    _set(table, "rotation", _array(angles, sc.degrees))


def _plane_motion(table: Table, velocity: np.ndarray, spin: np.ndarray, sc: Scales) -> None:
    """A plane's own motion, written only when it has one (scene files without it stay loadable)."""
    for key, value in (("velocity", clean(velocity, sc.speed)), ("angular_velocity", clean(spin, sc.spin))):
        if np.any(value != 0.0):
            _set(table, key, _array(value))
        elif key in table:
            del table[key]


def _ball_state(table: Table, ball: object, sc: Scales) -> None:
    for key, scale in (("position", sc.length), ("velocity", sc.speed), ("angular_velocity", sc.spin),
                       ("orientation", sc.unit)):  # fmt: skip
        _set(table, key, _array(getattr(ball, key), scale))


def _sphere_table(ball: object, color: object, sc: Scales) -> Table:
    table = tomlkit.table()
    _ball_state(table, ball, sc)
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
    text = read_text(path) if path is not None and path.is_file() else ""
    doc = tomlkit.parse(_without_header(text))

    sc = Scales.of(world, camera)
    if "world" not in doc:
        doc.append("world", _world_table(world, sim.timestep, sc))
    else:
        if doc["world"].get("integrator", "rk4") != world.integrator:
            _set(doc["world"], "integrator", world.integrator)
        if doc["world"].get("substeps", 1) != world.substeps:
            _set(doc["world"], "substeps", int(world.substeps))

    look_distance = float(np.linalg.norm(look.camera_look_at - look.camera_position)) or 10.0
    view = doc["camera"] if "camera" in doc else tomlkit.table()
    _set(view, "position", _array(camera.position, sc.length))
    _set(view, "look_at", _array(camera.position + camera.forward * look_distance, sc.length))
    if "camera" not in doc:
        doc.append("camera", view)

    planes = _aot(doc, "plane") if len(world.planes) else None
    for i, plane in enumerate(world.planes):
        if i >= len(planes):
            planes.append(_plane_table(plane, look.plane_colors[i], sc))
        else:
            before = initial.planes[i] if i < len(initial.planes) else None
            moved = before is None or not (
                np.array_equal(plane.position, before.position)
                and np.array_equal(plane.orientation, before.orientation)
            )
            if moved:
                _place_plane(planes[i], plane, sc)
        velocity, spin = (plane_motion or {}).get(i, (plane.velocity, plane.angular_velocity))
        _plane_motion(planes[i], np.asarray(velocity, dtype=float), np.asarray(spin, dtype=float), sc)

    _write_balls(doc, sim, sc)
    _allow_resting_overlap(doc, world)
    return doc


def _allow_resting_overlap(doc: tomlkit.TOMLDocument, world: object) -> None:
    """Let the saved state load: balls at rest press a little into each other and into the floor,
    more than a scene's start allows by default, so [world] allows twice the deepest overlap now."""
    spheres = world.spheres  # type: ignore[attr-defined]
    deepest = deepest_overlap(spheres.positions, spheres.radii, world.planes)  # type: ignore[attr-defined]
    if deepest > OVERLAP_TOLERANCE:
        _set(doc["world"], "overlap_tolerance", float(f"{2 * deepest:.2g}"))


def _write_balls(doc: tomlkit.TOMLDocument, sim: Simulation, sc: Scales) -> None:
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
                _ball_state(doc["sphere"][i], spheres[i], sc)
        if "grid" in doc:  # a grid says where its balls start, and its balls load after every
            del doc["grid"]  # [[sphere]]: they get [[sphere]] tables of their own, in order
        start = tables
    for i in range(start, len(spheres)):
        _aot(doc, "sphere").append(_sphere_table(spheres[i], colors[i], sc))


# ---------------------------------------------------------------------- the file
def header(sim: Simulation, now: datetime) -> str:
    """The comment a saved file starts with: what it was saved from, when, and how far into the run."""
    source = sim.path.name if sim.path is not None else "a world built in code"
    when = now.astimezone().strftime("%Y-%m-%d %H:%M:%S %Z")
    lines = [
        f"{SAVED_MARK}{source} in the viewer (Ctrl+S) on {when},",
        f"# {sim.world.time:.3f} s into its run, integrator {sim.world.integrator.upper()}.",
    ]
    if sim.path is not None:
        lines.append("# The comments below are the original's: they describe its start, not this state.")
    return "\n".join(lines) + "\n\n"


def _without_header(text: str) -> str:
    """The original's text without the ``header`` it got if it was saved itself (up to a blank line)."""
    if not text.startswith(SAVED_MARK):
        return text
    _, blank, rest = text.partition("\n\n")
    return rest if blank else ""


def scene_text(
    sim: Simulation,
    camera: Camera,
    plane_motion: dict[int, tuple[np.ndarray, np.ndarray]] | None = None,
    now: datetime | None = None,
) -> str:
    """The saved file's text: ``header`` (saved ``now``, the current time by default), then
    ``scene_document``."""
    return header(sim, now or datetime.now()) + tomlkit.dumps(scene_document(sim, camera, plane_motion))


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
    text = scene_text(sim, camera, plane_motion)
    folder = _folder_for(sim.path)
    while True:
        path = saved_path(sim.path, folder)
        try:
            with open(path, "x", encoding="utf-8") as f:
                f.write(text)
            return path.resolve()
        except FileExistsError:  # someone took the name since we looked
            continue


def save_scene_as(
    sim: Simulation,
    camera: Camera,
    path: Path,
    plane_motion: dict[int, tuple[np.ndarray, np.ndarray]] | None = None,
) -> Path:
    """Write the scene as it stands to ``path`` (the panel's Save as; ``.toml`` is added if missing),
    replacing that file whole or not at all; returns its path."""
    path = Path(path)
    if path.suffix != ".toml":
        path = path.with_name(path.name + ".toml")
    text = scene_text(sim, camera, plane_motion)
    partial = path.with_name(f"{path.name}.{os.getpid()}.partial")
    partial.write_text(text, encoding="utf-8")
    os.replace(partial, path)
    return path.resolve()
