"""The builder: validated scene tables -> a World and its appearance.

Every table is checked before anything is built, so a bad file never gives a half-built world. Balls
from ``[[sphere]]`` and ``[[grid]]`` tables are gathered in file order (spheres first, then grids) and
added in one batch; entries are numbered from 1 in file order, per kind.

A file may hold half a million spheres, so each is read and dropped in turn (its parsed table let go
once its numbers are in the batch), and where a table or key is in the file is looked up only when an
error names it: loading stays within a few hundred MB for any file under the size cap.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..physics import World
from ..physics.core import exact
from . import layout, schema
from .appearance import Appearance, Scene, default_plane_colors, frame_camera, frozen
from .balls import Balls
from .fields import LARGEST, Entry, did_you_mean, show
from .lines import LineIndex, find_array_item
from .reading import SceneError, quote_key


class Builder:
    """Validates the parsed TOML tables one by one, then builds the Scene."""

    def __init__(self, path: Path, text: str, data: dict) -> None:
        self.path = path
        self.data = data
        self.text = text
        self._lines: LineIndex | None = None

    @property
    def lines(self) -> LineIndex:
        """Where every table and key is in the file (made on first use: only errors need it)."""
        if self._lines is None:
            self._lines = LineIndex(self.text)
        return self._lines

    def build(self) -> Scene:
        """Check every table in file order, then build the World and its appearance."""
        self.check_top_level()
        params, timestep, duration = self.world_settings()
        camera = self.table("camera")
        camera.check_keys(schema.CAMERA_KEYS)
        given = camera.vector("position", None), camera.vector("look_at", None)
        planes = [self.plane(e) for e in self.array("plane", schema.MAX_PLANES)]
        spheres = self.data.get("sphere")
        balls = Balls(lambda k: self.entry("sphere", k, {}), len(spheres) if isinstance(spheres, list) else 0)
        for entry in self.array("sphere", schema.MAX_BALLS, drop=True):
            self.sphere(entry, balls)
        for entry in self.array("grid"):
            self.grid(entry, balls)

        world = World(**params)
        plane_colors = self.add_planes(world, planes)
        if balls.count:
            positions = balls.positions()
            columns = {k: balls.column(k) for k in schema.BALL_COLUMNS}
            radii = np.broadcast_to(columns["radius"], (balls.count,))
            balls.check_overlaps(positions, radii, world, self.overlap_tolerance)
            columns["hollow"] = columns["hollow"].astype(bool)
            world.add_spheres(positions, **columns)
            del positions, columns, radii
        position, look_at = self.camera(camera, *given, world)
        appearance = Appearance(
            path=self.path,
            camera_position=frozen(position),
            camera_look_at=frozen(look_at),
            sphere_colors=frozen(balls.sphere_colors().reshape(-1, 3)),
            plane_colors=frozen(plane_colors.reshape(-1, 3)),
        )
        return Scene(world, appearance, float(timestep), duration)

    def world_settings(self) -> tuple[dict[str, object], float, float | None]:
        """[world]: the World's arguments, the timestep and the suggested duration."""
        e = self.table("world")
        e.check_keys(schema.WORLD_KEYS)
        d = schema.WORLD_DEFAULTS
        params = dict(
            gravity=e.vector("gravity", d["gravity"]),
            integrator=e.choice("integrator", d["integrator"], schema.INTEGRATORS),
        )
        timestep = e.number("timestep", schema.TIMESTEP_DEFAULT, positive=True)
        params.update(
            linear_drag=e.number("linear_drag", d["linear_drag"], nonnegative=True),
            angular_drag=e.number("angular_drag", d["angular_drag"], nonnegative=True),
            restitution_threshold=e.number(
                "restitution_threshold", d["restitution_threshold"], nonnegative=True
            ),
            sleep=e.boolean("sleep", bool(d["sleep"])),
            substeps=e.integer(
                "substeps",
                int(d["substeps"]),
                minimum=schema.SUBSTEPS_RANGE[0],
                maximum=schema.SUBSTEPS_RANGE[1],
            ),
        )
        self.overlap_tolerance = e.number("overlap_tolerance", schema.OVERLAP_TOLERANCE, nonnegative=True)
        return params, timestep, e.number("duration", None, positive=True)

    @staticmethod
    def add_planes(world: World, planes: list[tuple[Entry, dict, np.ndarray | None]]) -> np.ndarray:
        """Add the checked planes to ``world``; returns their colours, defaults where none was given."""
        for entry, kwargs, _ in planes:
            try:
                world.add_plane(**kwargs)
            except (TypeError, ValueError) as e:  # the checks above should have caught it
                raise entry.error(None, str(e)) from None
        colors = default_plane_colors(world)
        for p, (_, _, color) in enumerate(planes):
            if color is not None:
                colors[p] = color
        return colors

    @staticmethod
    def camera(
        e: Entry, position: np.ndarray | None, look_at: np.ndarray | None, world: World
    ) -> tuple[np.ndarray, np.ndarray]:
        """[camera]: where it starts; what the file leaves out comes from framing the built world."""
        if look_at is None or position is None:
            auto_position, auto_look_at = frame_camera(world)
            look_at = auto_look_at if look_at is None else look_at
            position = auto_position if position is None else position
        if float(np.linalg.norm(position - look_at)) < 1e-9:
            raise e.error("look_at", "must differ from the camera position", [float(x) for x in look_at])
        return position, look_at

    # ------------------------------------------------------------------ tables
    def check_top_level(self) -> None:
        """Refuse any top-level name that is not one of the scene's tables."""
        for key in self.data:
            if key in schema.TABLES:
                continue
            line = self.lines.root.key_lines.get(key) or self.lines.first_header.get(key)
            hint = did_you_mean(key, schema.TABLES)
            owners = [schema.header(n) for n in schema.TABLES if key in schema.KEYS[n]]
            if hint == "" and owners:
                hint = f" (it belongs inside a table: {' or '.join(owners)})"
            raise SceneError(self.path, f"unknown table or key {quote_key(key)}{hint}", line=line)

    def table(self, name: str) -> Entry:
        """The ``[name]`` table (empty when the file has none)."""
        value = self.data.get(name, {})
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            first = self.lines.array_item(name, 0)
            line = first.header_line if first else None
            raise SceneError(self.path, f"write [{name}] once, as a table, not [[{name}]]", line=line)
        if not isinstance(value, dict):
            problem = f"'{name}' must be a table written [{name}], got {show(value)}"
            raise SceneError(self.path, problem, line=self.lines.root.key_lines.get(name))
        return Entry(self.path, f"[{name}]", value, lambda: self.lines.table(name))

    def entry(self, name: str, index: int, data: dict) -> Entry:
        """The ``index``-th (from 0) ``[[name]]`` table as an Entry; where it is in the file is found
        only if an error asks."""
        return Entry(self.path, f"{name} #{index + 1}", data, lambda: find_array_item(self.text, name, index))

    def array(self, name: str, most: int | None = None, drop: bool = False) -> Iterator[Entry]:
        """The ``[[name]]`` tables, in file order, one at a time (refused beyond ``most`` of them). With
        ``drop``, each parsed table is let go once the next is asked for."""
        value = self.data.get(name, [])
        if not isinstance(value, dict | list):
            problem = f"'{name}' must be tables written [[{name}]], got {show(value)}"
            raise SceneError(self.path, problem, line=self.lines.root.key_lines.get(name))
        if isinstance(value, dict):
            where = self.lines.table(name)
            raise SceneError(
                self.path,
                f"each {name} is a table written [[{name}]] (double brackets), not [{name}]",
                line=where.header_line if where else None,
            )
        if most is not None and len(value) > most:
            raise self.entry(name, most, {}).error(
                None, f"{len(value):,} of them are more than the {most:,} a scene may have"
            )
        return self._entries(name, value, drop)

    def _entries(self, name: str, value: list, drop: bool) -> Iterator[Entry]:
        for i, item in enumerate(value):
            if not isinstance(item, dict):
                line = self.lines.root.key_lines.get(name)
                raise SceneError(
                    self.path, f"must be a table, got {show(item)}", line=line, entry=f"{name} #{i + 1}"
                )
            yield self.entry(name, i, item)
            if drop:
                value[i] = None

    # ------------------------------------------------------------------ entries
    def plane(self, e: Entry) -> tuple[Entry, dict, np.ndarray | None]:
        """A [[plane]] as add_plane arguments and its colour (None: the default)."""
        e.check_keys(schema.PLANE_KEYS)
        d = schema.PLANE_DEFAULTS
        position = e.vector("position", d["position"])
        rotation = e.vector("rotation", d["rotation"])
        normal = e.nonzero_vector("normal")
        if rotation is not None and normal is not None:
            second = max(("rotation", "normal"), key=lambda k: e.line(k) or 0)
            raise e.error(second, "give either 'normal' or 'rotation', not both")
        size = e.extents("size", 2)
        kwargs = dict(
            position=position,
            rotation=rotation,
            normal=normal,
            size=None if size is None else (float(size[0]), float(size[1])),
            restitution=e.number("restitution", d["restitution"], within=schema.RESTITUTION_RANGE),
            friction=e.number("friction", d["friction"], nonnegative=True),
            rolling_friction=e.number("rolling_friction", d["rolling_friction"], nonnegative=True),
            velocity=e.vector("velocity", d["velocity"]),
            angular_velocity=e.vector("angular_velocity", d["angular_velocity"]),
        )
        return e, kwargs, e.color("color")

    def ball_properties(self, e: Entry, given_only: bool = False) -> dict[str, object]:
        """The add_sphere arguments (but position) shared by a [[sphere]] or by a [[grid]]'s balls; with
        ``given_only``, only those the entry gives."""
        props = {}
        for key in schema.BALL_COLUMNS:
            if key in e.data:
                props[key] = _ball_property(e, key)
            elif not given_only:
                props[key] = _BALL_DEFAULTS[key]
        return props

    def sphere(self, e: Entry, balls: Balls) -> None:
        e.check_keys(schema.SPHERE_KEYS)
        e.require("position")
        position = e.vector("position", None)
        balls.add_sphere(position, self.ball_properties(e, given_only=True), e.color("color"))

    def grid(self, e: Entry, balls: Balls) -> None:
        e.check_keys(schema.GRID_KEYS)
        e.require("count")
        count = e.data["count"]
        if (
            not isinstance(count, list)
            or len(count) != 3
            or not all(isinstance(c, int) and not isinstance(c, bool) for c in count)
        ):
            raise e.error("count", "must be a list of 3 whole numbers [nx, ny, nz]", count)
        if min(count) < 1:
            raise e.error("count", "every count must be at least 1", count)
        n = count[0] * count[1] * count[2]
        cap = schema.MAX_BALLS
        if n > cap - balls.count:
            before = f"; with the {balls.count:,} before it that is" if balls.count else ","
            raise e.error("count", f"asks for {n:,} balls{before} more than the {cap:,} a scene may have")
        count = tuple(count)
        corner = e.vector("corner", None)
        center = e.vector("center", None)
        if corner is None and center is None:
            raise e.error(None, "give the block's 'corner' (first ball's centre) or its 'center'")
        if corner is not None and center is not None:
            second = max(("corner", "center"), key=lambda k: e.line(k) or 0)
            raise e.error(second, "give either 'corner' or 'center', not both")
        props = self.ball_properties(e)
        radius = float(props["radius"])
        spacing = e.extents("spacing", 3)
        spacing = np.full(3, schema.GRID_SPACING * radius) if spacing is None else spacing
        jitter = e.number("jitter", schema.GRID_JITTER, nonnegative=True)
        velocity_jitter = e.number("velocity_jitter", schema.GRID_VELOCITY_JITTER, nonnegative=True)
        seed = e.integer("seed", schema.GRID_SEED)
        need = 2 * radius + 2 * jitter
        axis = layout.crowded_axis(count, spacing, need)
        if axis is not None:
            key = "spacing" if "spacing" in e.data or jitter == 0 else "jitter"
            why = "2·radius" if jitter == 0 else "2·radius + 2·jitter"
            raise e.error(
                key,
                f"neighbouring balls would overlap: spacing {spacing[axis]:g} along {'xyz'[axis]} "
                f"is less than {why} = {need:g}",
            )
        far = layout.reach(count, spacing, corner, center) + jitter
        if far > LARGEST:
            key = "spacing" if "spacing" in e.data else "count"
            raise e.error(key, f"the block reaches {far:.4g} m from the origin, beyond 1e9 m")
        fastest = float(np.abs(props["velocity"]).max()) + velocity_jitter
        if fastest > LARGEST:
            key = "velocity_jitter" if velocity_jitter > 0 else "velocity"
            raise e.error(
                key, f"a ball's velocity could reach {fastest:.4g} m/s along an axis, beyond 1e9 m/s"
            )
        positions = layout.grid_positions(count, spacing, corner, center)
        positions, props["velocity"] = layout.jitter(
            positions, props["velocity"], jitter, velocity_jitter, seed
        )
        key = "center" if center is not None else "corner"
        balls.add_grid(e, key, positions, props, self.grid_colors(e, n), lambda k: layout.ball_name(count, k))

    def grid_colors(self, e: Entry, n: int) -> np.ndarray | None:
        """(n, 3) colours a [[grid]] gives (one, or a list cycled), or None for the palette."""
        value = e.data.get("color")
        if value is None:
            return None
        if isinstance(value, list) and value and all(isinstance(v, str | list) for v in value):
            cycle = np.array([e.parse_color("color", v, value) for v in value])
            return cycle[np.arange(n) % len(cycle)]
        return np.broadcast_to(e.parse_color("color", value), (n, 3)).copy()


def _ball_property(e: Entry, key: str) -> object:
    """Ball property ``key``, which entry ``e`` gives, checked."""
    if key in ("radius", "mass"):
        return e.number(key, None, positive=True)
    if key in ("velocity", "angular_velocity"):
        return e.vector(key, None)
    if key == "orientation":
        q = e.nonzero_vector(key, 4)
        return q / exact.norm_rows(q)
    if key == "restitution":
        return e.number(key, None, within=schema.RESTITUTION_RANGE)
    if key == "hollow":
        return float(e.boolean(key, False))
    return e.number(key, None, nonnegative=True)  # friction, rolling friction


def _default(value: object) -> object:
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, tuple):
        return frozen(value)
    return value


_BALL_DEFAULTS = {key: _default(value) for key, value in schema.BALL_DEFAULTS.items()}
