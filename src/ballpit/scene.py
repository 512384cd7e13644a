"""Scene files: TOML text -> a ready ``World``, with validation a user can act on.

A scene has ``[world]`` and ``[camera]`` tables and any number of ``[[plane]]``, ``[[sphere]]`` and
``[[grid]]`` (a block of nx×ny×nz balls) tables. ``load_scene`` checks every key before building
anything, so a bad file never gives a half-built world, and every error is one ``SceneError`` line:

    scenes/x.toml:12: sphere #3: key 'radius': must be positive, got -1.0

``tomllib`` reports line numbers only for syntax errors, so ``_LineIndex`` scans the raw text for the
table headers and keys itself; entries are numbered from 1 in file order, per kind.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from .physics import World
from .physics.collision import closest_point_on_planes

DEFAULT_TIMESTEP = 1.0 / 240.0
INTEGRATORS = ("euler", "rk2", "rk4")
# Balls or a ball and a plane may touch at the start (a cradle, a ball resting on the floor), but not
# interpenetrate by more than this.
OVERLAP_TOLERANCE = 1e-6  # m

# Default ball colours, cycled by ball index: saturated but not garish against a grey floor.
PALETTE = (
    "#e0482f",
    "#f4a259",
    "#3fa7d6",
    "#5bc06f",
    "#9b5de5",
    "#f15bb5",
    "#fee440",
    "#00bbf9",
    "#00c9a7",
    "#ff8c42",
)
# Default plane colours: unbounded planes are a neutral floor; finite ones show their bounciness,
# slate blue at restitution 0, green at 0.5, orange at 1 (the viewer's legend uses the same stops).
GROUND_COLOR = (0.55, 0.57, 0.60)
RESTITUTION_STOPS = np.array([0.0, 0.5, 1.0])
RESTITUTION_COLORS = np.array([[0.29, 0.36, 0.50], [0.30, 0.56, 0.42], [0.93, 0.55, 0.20]])


class SceneError(ValueError):
    """A problem with a scene file, as one line naming the file, line, entry, key and value."""

    def __init__(
        self,
        path: Path | str,
        problem: str,
        *,
        line: int | None = None,
        entry: str | None = None,
        key: str | None = None,
    ) -> None:
        self.path = Path(path)
        self.line = line
        self.entry = entry
        self.key = key
        self.problem = problem
        where = f"{path}:{line}" if line is not None else f"{path}"
        parts = [where]
        if entry:
            parts.append(entry)
        if key:
            parts.append(f"key '{key}'")
        parts.append(problem)
        super().__init__(": ".join(parts))


@dataclass(frozen=True, eq=False)
class SceneInfo:
    """The parts of a scene file the physics does not use: camera, colours, timestep, duration.

    Travels with the world as ``world.scene``. Arrays are read-only.
    """

    path: Path
    name: str
    camera_position: np.ndarray  # (3,) m
    camera_look_at: np.ndarray  # (3,) m
    sphere_colors: np.ndarray  # (N, 3) sRGB 0..1 floats, one row per ball in world order
    plane_colors: np.ndarray  # (P, 3) sRGB 0..1 floats, one row per plane in world order
    timestep: float  # s per physics step
    duration: float | None  # suggested run length in s, or None


def load_scene(path: str | Path) -> World:
    """Read and validate a scene file; return its World with ``world.scene`` set to a ``SceneInfo``.

    Raises ``SceneError`` (a ``ValueError``) for a missing file, bad TOML or any bad value.
    """
    path = Path(path)
    text = _read_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise _syntax_error(path, text, e) from None
    return _Builder(path, text, data).build()


def bundled_scenes_dir() -> Path:
    """The directory of the scenes shipped with ballpit (``ballpit.scenes`` when installed)."""
    try:
        found = Path(str(resources.files("ballpit.scenes")))
        if found.is_dir():
            return found
    except (ModuleNotFoundError, TypeError):
        pass
    return Path(__file__).resolve().parents[2] / "scenes"  # a source checkout


def bundled_scenes() -> list[Path]:
    """Every bundled scene file, sorted by name."""
    return sorted(bundled_scenes_dir().glob("*.toml"))


def default_scene_path() -> Path:
    """The default demo, ``slopes.toml``."""
    return bundled_scenes_dir() / "slopes.toml"


def resolve_scene_path(name: str | Path) -> Path:
    """A scene argument as a path: an existing file, else a bundled scene's name (``slopes``).

    An unknown name comes back unchanged, so loading it reports the missing file.
    """
    path = Path(name)
    if path.exists():
        return path
    stem = path.name.removesuffix(".toml")
    if path.parent == Path(".") and stem:
        bundled = bundled_scenes_dir() / f"{stem}.toml"
        if bundled.is_file():
            return bundled
    return path


# ---------------------------------------------------------------------------------------- reading


def _read_text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise SceneError(path, "no such file") from None
    except IsADirectoryError:
        raise SceneError(path, "is a directory, not a scene file") from None
    except PermissionError:
        raise SceneError(path, "permission denied") from None
    except OSError as e:
        raise SceneError(path, f"cannot read: {e.strerror or e}") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise SceneError(path, "not UTF-8 text; is this a scene file?", line=line) from None


_AT_LINE = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")
_AT_END = re.compile(r"\s*\(at end of document\)\s*$")


def _syntax_error(path: Path, text: str, e: tomllib.TOMLDecodeError) -> SceneError:
    msg = str(e)
    m = _AT_LINE.search(msg)
    if m:
        problem = f"TOML syntax error: {msg[: m.start()]} (column {m.group(2)})"
        return SceneError(path, problem, line=int(m.group(1)))
    m = _AT_END.search(msg)
    if m:
        # Something left open (an array, a string): point at the last line that has anything on it.
        lines = text.splitlines()
        last = max((i + 1 for i, ln in enumerate(lines) if ln.strip()), default=None)
        return SceneError(path, f"TOML syntax error: {msg[: m.start()]} at the end of the file", line=last)
    return SceneError(path, f"TOML syntax error: {msg}")


# ---------------------------------------------------------------------------------------- line index


@dataclass
class _Table:
    """Where one table of the file is: its header line and the line of each of its keys."""

    header_line: int | None
    key_lines: dict[str, int]


_HEADER = re.compile(r"^\s*(\[\[|\[)\s*([^\[\]#]+?)\s*(\]\]|\])\s*(?:#.*)?$")
_KEY = re.compile(r"""^\s*("(?:[^"\\]|\\.)*"|'[^']*'|[A-Za-z0-9_-]+)\s*[.=]""")


def _unquote(name: str) -> str:
    parts = [p.strip() for p in re.split(r"\.(?=(?:[^\"']|\"[^\"]*\"|'[^']*')*$)", name)]
    return ".".join(p[1:-1] if len(p) >= 2 and p[0] == p[-1] and p[0] in "\"'" else p for p in parts)


class _LineIndex:
    """Header and key line numbers, found by scanning the raw TOML text.

    Lines inside multi-line strings and multi-line arrays are skipped, so a value that happens to look
    like ``[x]`` or ``key =`` is not mistaken for a header or a key.
    """

    def __init__(self, text: str) -> None:
        self.root = _Table(None, {})
        self.tables: dict[str, _Table] = {}
        self.arrays: dict[str, list[_Table]] = {}
        current = self.root
        depth = 0  # open brackets/braces of a value continuing onto later lines
        multiline: str | None = None  # the closing delimiter of an open multi-line string
        for number, line in enumerate(text.splitlines(), start=1):
            if multiline is None and depth == 0:
                header = _HEADER.match(line)
                if header:
                    name = _unquote(header.group(2))
                    current = _Table(number, {})
                    if header.group(1) == "[[":
                        self.arrays.setdefault(name, []).append(current)
                    else:
                        self.tables.setdefault(name, current)
                    continue
                key = _KEY.match(line)
                if key:
                    current.key_lines.setdefault(_unquote(key.group(1)), number)
            depth, multiline = _scan_line(line, depth, multiline)

    def table(self, name: str) -> _Table | None:
        return self.tables.get(name)

    def array_item(self, name: str, index: int) -> _Table | None:
        items = self.arrays.get(name, [])
        return items[index] if index < len(items) else None


def _scan_line(line: str, depth: int, multiline: str | None) -> tuple[int, str | None]:
    """Bracket depth and open multi-line string after one line of TOML."""
    i, n = 0, len(line)
    while i < n:
        if multiline is not None:
            end = _find_closing(line, i, multiline)
            if end < 0:
                return depth, multiline
            i, multiline = end + 3, None
            continue
        c = line[i]
        if c == "#":
            break
        if c in "\"'":
            if line.startswith(c * 3, i):
                multiline = c * 3
                i += 3
                continue
            i = _skip_string(line, i + 1, c)
            continue
        if c in "[{":
            depth += 1
        elif c in "]}":
            depth = max(0, depth - 1)
        i += 1
    return depth, multiline


def _find_closing(line: str, start: int, delim: str) -> int:
    i = start
    while True:
        j = line.find(delim, i)
        if j < 0:
            return -1
        if delim == '"""':
            backslashes = len(line[:j]) - len(line[:j].rstrip("\\"))
            if backslashes % 2:
                i = j + 1
                continue
        return j


def _skip_string(line: str, i: int, quote: str) -> int:
    while i < len(line):
        if quote == '"' and line[i] == "\\":
            i += 2
            continue
        if line[i] == quote:
            return i + 1
        i += 1
    return i


# ---------------------------------------------------------------------------------------- values


def _show(value: object) -> str:
    """A value as it would be written in TOML, for error messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    return str(value)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _did_you_mean(word: str, options: Iterable[str]) -> str:
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


class _Entry:
    """One table of the file under validation: typed getters that raise ``SceneError`` with context."""

    def __init__(self, path: Path, label: str, data: dict, where: _Table | None) -> None:
        self.path = path
        self.label = label
        self.data = data
        self.where = where

    def line(self, key: str | None = None) -> int | None:
        if self.where is None:
            return None
        if key is not None and key in self.where.key_lines:
            return self.where.key_lines[key]
        return self.where.header_line

    def error(self, key: str | None, problem: str, value: object = ...) -> SceneError:
        if value is not ...:
            problem = f"{problem}, got {_show(value)}"
        return SceneError(self.path, problem, line=self.line(key), entry=self.label, key=key)

    def check_keys(self, allowed: Iterable[str]) -> None:
        allowed = list(allowed)
        for key in self.data:
            if key not in allowed:
                hint = _did_you_mean(key, allowed)
                raise SceneError(
                    self.path,
                    f"unknown key '{key}'{hint}",
                    line=self.line(key),
                    entry=self.label,
                )

    def require(self, key: str) -> None:
        if key not in self.data:
            raise self.error(None, f"missing required key '{key}'")

    def number(self, key: str, default: float | None, *, positive: bool = False, nonnegative: bool = False):
        if key not in self.data:
            return default
        value = self.data[key]
        if not _is_number(value):
            raise self.error(key, "must be a number", value)
        x = float(value)
        if not math.isfinite(x):
            raise self.error(key, "must be finite", value)
        if positive and x <= 0:
            raise self.error(key, "must be positive", value)
        if nonnegative and x < 0:
            raise self.error(key, "must not be negative", value)
        return x

    def integer(self, key: str, default: int, *, minimum: int = 0) -> int:
        if key not in self.data:
            return default
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, "must be a whole number", value)
        if value < minimum:
            raise self.error(key, f"must be at least {minimum}", value)
        return value

    def boolean(self, key: str, default: bool) -> bool:
        if key not in self.data:
            return default
        value = self.data[key]
        if not isinstance(value, bool):
            raise self.error(key, "must be true or false", value)
        return value

    def vector(self, key: str, default: object, length: int = 3) -> np.ndarray | None:
        if key not in self.data:
            return None if default is None else np.array(default, dtype=float)
        value = self.data[key]
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise self.error(key, f"must be a list of {length} numbers", value)
        if len(value) != length:
            raise self.error(key, f"must have {length} components, not {len(value)}", value)
        arr = np.array(value, dtype=float)
        if not np.isfinite(arr).all():
            raise self.error(key, "must be finite", value)
        return arr

    def nonzero_vector(self, key: str, length: int = 3) -> np.ndarray | None:
        arr = self.vector(key, None, length)
        if arr is not None and float(np.linalg.norm(arr)) < 1e-12:
            raise self.error(key, "must not be the zero vector", self.data[key])
        return arr

    def extents(self, key: str, count: int) -> np.ndarray | None:
        """A positive finite number, or a list of ``count`` of them."""
        if key not in self.data:
            return None
        value = self.data[key]
        items = value if isinstance(value, list) else [value]
        shape = "a number" if count == 1 else f"a number or a list of {count} numbers"
        if not all(_is_number(v) for v in items) or (isinstance(value, list) and len(value) != count):
            raise self.error(key, f"must be {shape}", value)
        arr = np.array(items, dtype=float)
        if not np.isfinite(arr).all():
            raise self.error(key, "must be finite", value)
        if (arr <= 0).any():
            raise self.error(key, "must be positive", value)
        return np.broadcast_to(arr, (count,)).copy()

    def choice(self, key: str, default: str, options: tuple[str, ...]) -> str:
        if key not in self.data:
            return default
        value = self.data[key]
        if not isinstance(value, str):
            raise self.error(key, f"must be one of {', '.join(options)}", value)
        if value.lower() not in options:
            hint = _did_you_mean(value.lower(), options)
            raise self.error(key, f"must be one of {', '.join(options)}{hint}", value)
        return value.lower()

    def color(self, key: str) -> np.ndarray | None:
        if key not in self.data:
            return None
        return self.parse_color(key, self.data[key])

    def parse_color(self, key: str, value: object, whole: object = ...) -> np.ndarray:
        whole = value if whole is ... else whole
        if isinstance(value, str):
            m = re.fullmatch(r"#?([0-9a-fA-F]{6})", value.strip())
            if not m:
                raise self.error(key, 'must be "#rrggbb" or [r, g, b] with components 0..1', whole)
            h = m.group(1)
            return np.array([int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4)])
        if isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value):
            rgb = np.array(value, dtype=float)
            if not np.isfinite(rgb).all() or (rgb < 0).any() or (rgb > 1).any():
                raise self.error(key, "components must be between 0 and 1", whole)
            return rgb
        raise self.error(key, 'must be "#rrggbb" or [r, g, b] with components 0..1', whole)


# ---------------------------------------------------------------------------------------- building

WORLD_KEYS = (
    "gravity",
    "integrator",
    "timestep",
    "linear_drag",
    "angular_drag",
    "restitution_threshold",
    "duration",
)
CAMERA_KEYS = ("position", "look_at")
PLANE_KEYS = (
    "position",
    "rotation",
    "normal",
    "size",
    "restitution",
    "friction",
    "rolling_friction",
    "velocity",
    "angular_velocity",
    "color",
)
BALL_KEYS = (
    "radius",
    "mass",
    "velocity",
    "angular_velocity",
    "orientation",
    "restitution",
    "friction",
    "rolling_friction",
    "hollow",
    "color",
)
SPHERE_KEYS = ("position", *BALL_KEYS)
GRID_KEYS = ("corner", "center", "count", "spacing", "jitter", "velocity_jitter", "seed", *BALL_KEYS)
TABLES = {"world": "table", "camera": "table", "plane": "array", "sphere": "array", "grid": "array"}


@dataclass
class _Balls:
    """Balls gathered from [[sphere]] and [[grid]] entries, added to the world in one batch."""

    positions: list[np.ndarray]
    columns: dict[str, list[np.ndarray]]
    colors: list[np.ndarray]
    # For error messages: for each block of balls, a function naming ball k of the block.
    owners: list[tuple[int, _Entry, str | None, Callable[[int], str | None]]]

    @property
    def count(self) -> int:
        return sum(len(p) for p in self.positions)


class _Builder:
    """Validates the parsed TOML table by table, then builds the World."""

    def __init__(self, path: Path, text: str, data: dict) -> None:
        self.path = path
        self.data = data
        self.lines = _LineIndex(text)

    def table(self, name: str) -> _Entry:
        value = self.data.get(name, {})
        where = self.lines.table(name)
        if not isinstance(value, dict):
            line = (self.lines.array_item(name, 0) or _Table(None, {})).header_line
            raise SceneError(self.path, f"write [{name}] once, as a table, not [[{name}]]", line=line)
        return _Entry(self.path, f"[{name}]", value, where)

    def array(self, name: str) -> list[_Entry]:
        value = self.data.get(name, [])
        if isinstance(value, dict):
            line = (self.lines.table(name) or _Table(None, {})).header_line
            raise SceneError(
                self.path,
                f"each {name} is a table written [[{name}]] (double brackets), not [{name}]",
                line=line,
            )
        entries = []
        for i, item in enumerate(value):
            label = f"{name} #{i + 1}"
            where = self.lines.array_item(name, i)
            if not isinstance(item, dict):
                raise SceneError(
                    self.path,
                    f"must be a table, got {_show(item)}",
                    line=self.lines.root.key_lines.get(name),
                    entry=label,
                )
            entries.append(_Entry(self.path, label, item, where))
        return entries

    def build(self) -> World:
        for key in self.data:
            if key not in TABLES:
                line = self.lines.root.key_lines.get(key)
                if line is None:
                    where = self.lines.table(key) or (self.lines.arrays.get(key) or [None])[0]
                    line = where.header_line if where else None
                hint = _did_you_mean(key, TABLES)
                if hint == "":
                    every = {k for name in TABLES for k in self._keys_of(name)}
                    if key in every:
                        owners = [
                            f"[{n}]" if TABLES[n] == "table" else f"[[{n}]]"
                            for n in TABLES
                            if key in self._keys_of(n)
                        ]
                        hint = f" (it belongs inside a table: {' or '.join(owners)})"
                raise SceneError(self.path, f"unknown table or key '{key}'{hint}", line=line)

        world_entry = self.table("world")
        world_entry.check_keys(WORLD_KEYS)
        gravity = world_entry.vector("gravity", (0.0, -9.81, 0.0))
        integrator = world_entry.choice("integrator", "rk4", INTEGRATORS)
        timestep = world_entry.number("timestep", DEFAULT_TIMESTEP, positive=True)
        linear_drag = world_entry.number("linear_drag", 0.0, nonnegative=True)
        angular_drag = world_entry.number("angular_drag", 0.0, nonnegative=True)
        threshold = world_entry.number("restitution_threshold", None, nonnegative=True)
        duration = world_entry.number("duration", None, positive=True)

        camera = self.table("camera")
        camera.check_keys(CAMERA_KEYS)
        cam_pos = camera.vector("position", None)
        cam_at = camera.vector("look_at", None)

        planes = [self.plane(e) for e in self.array("plane")]
        balls = _Balls([], {k: [] for k in BALL_COLUMNS}, [], [])
        for entry in self.array("sphere"):
            self.sphere(entry, balls)
        for entry in self.array("grid"):
            self.grid(entry, balls)

        world = World(
            gravity=gravity,
            integrator=integrator,
            linear_drag=linear_drag,
            angular_drag=angular_drag,
            restitution_threshold=threshold,
        )
        plane_colors = []
        for entry, kwargs, color in planes:
            try:
                world.add_plane(**kwargs)
            except (TypeError, ValueError) as e:  # the checks above should have caught it
                raise entry.error(None, str(e)) from None
            plane_colors.append(color)
        if balls.count:
            positions = np.concatenate(balls.positions)
            radii = np.concatenate(balls.columns["radius"])
            self.check_overlaps(balls, positions, radii, world)
            columns = {k: np.concatenate(v) for k, v in balls.columns.items()}
            columns["hollow"] = columns["hollow"].astype(bool)
            world.add_spheres(positions, **columns)
        sphere_colors = np.concatenate(balls.colors) if balls.count else np.zeros((0, 3))

        if cam_at is None or cam_pos is None:
            auto_pos, auto_at = _frame_scene(world)
            cam_at = auto_at if cam_at is None else cam_at
            cam_pos = auto_pos if cam_pos is None else cam_pos
        if float(np.linalg.norm(cam_pos - cam_at)) < 1e-9:
            raise camera.error("look_at", "must differ from the camera position", _list(cam_at))

        world.scene = SceneInfo(
            path=self.path,
            name=self.path.stem,
            camera_position=_frozen(cam_pos),
            camera_look_at=_frozen(cam_at),
            sphere_colors=_frozen(sphere_colors.reshape(-1, 3)),
            plane_colors=_frozen(np.array(plane_colors, dtype=float).reshape(-1, 3)),
            timestep=float(timestep),
            duration=duration,
        )
        return world

    @staticmethod
    def _keys_of(name: str) -> tuple[str, ...]:
        return {"world": WORLD_KEYS, "camera": CAMERA_KEYS, "plane": PLANE_KEYS, "sphere": SPHERE_KEYS}.get(
            name, GRID_KEYS
        )

    # ------------------------------------------------------------------ entries
    def plane(self, e: _Entry) -> tuple[_Entry, dict, np.ndarray]:
        e.check_keys(PLANE_KEYS)
        position = e.vector("position", (0.0, 0.0, 0.0))
        rotation = e.vector("rotation", None)
        normal = e.nonzero_vector("normal")
        if rotation is not None and normal is not None:
            second = max(("rotation", "normal"), key=lambda k: e.line(k) or 0)
            raise e.error(second, "give either 'normal' or 'rotation', not both")
        size = e.extents("size", 2)
        restitution = e.number("restitution", 0.8, nonnegative=True)
        kwargs = dict(
            position=position,
            rotation=rotation,
            normal=normal,
            size=None if size is None else (float(size[0]), float(size[1])),
            restitution=restitution,
            friction=e.number("friction", 0.5, nonnegative=True),
            rolling_friction=e.number("rolling_friction", 0.0, nonnegative=True),
            velocity=e.vector("velocity", (0.0, 0.0, 0.0)),
            angular_velocity=e.vector("angular_velocity", (0.0, 0.0, 0.0)),
        )
        color = e.color("color")
        if color is None:
            if size is None:
                color = np.array(GROUND_COLOR)
            else:
                t = min(restitution, 1.0)
                color = np.array(
                    [np.interp(t, RESTITUTION_STOPS, RESTITUTION_COLORS[:, k]) for k in range(3)]
                )
        return e, kwargs, color

    def ball_properties(self, e: _Entry) -> dict[str, object]:
        orientation = e.nonzero_vector("orientation", 4)
        return dict(
            radius=e.number("radius", 0.5, positive=True),
            mass=e.number("mass", 1.0, positive=True),
            velocity=e.vector("velocity", (0.0, 0.0, 0.0)),
            angular_velocity=e.vector("angular_velocity", (0.0, 0.0, 0.0)),
            orientation=(
                np.array([0.0, 0.0, 0.0, 1.0])
                if orientation is None
                else orientation / np.linalg.norm(orientation)
            ),
            restitution=e.number("restitution", 1.0, nonnegative=True),
            friction=e.number("friction", 0.5, nonnegative=True),
            rolling_friction=e.number("rolling_friction", 0.0, nonnegative=True),
            hollow=float(e.boolean("hollow", False)),
        )

    def add_block(self, balls: _Balls, e: _Entry, key: str | None, positions, props, colors, name) -> None:
        n = len(positions)
        balls.owners.append((balls.count, e, key, name))
        balls.positions.append(positions)
        for k in BALL_COLUMNS:
            per_ball = {"velocity": (3,), "angular_velocity": (3,), "orientation": (4,)}.get(k, ())
            balls.columns[k].append(np.broadcast_to(np.asarray(props[k], dtype=float), (n, *per_ball)))
        balls.colors.append(colors)

    def sphere(self, e: _Entry, balls: _Balls) -> None:
        e.check_keys(SPHERE_KEYS)
        e.require("position")
        position = e.vector("position", None)
        props = self.ball_properties(e)
        color = e.color("color")
        if color is None:
            color = _palette_color(balls.count)
        self.add_block(balls, e, "position", position[None, :], props, color[None, :], lambda k: None)

    def grid(self, e: _Entry, balls: _Balls) -> None:
        e.check_keys(GRID_KEYS)
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
        if n > 2_000_000:
            raise e.error("count", "asks for more than 2,000,000 balls", count)
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
        spacing = np.full(3, 2.2 * radius) if spacing is None else spacing
        jitter = e.number("jitter", 0.0, nonnegative=True)
        velocity_jitter = e.number("velocity_jitter", 0.0, nonnegative=True)
        seed = e.integer("seed", 0)
        need = 2 * radius + 2 * jitter
        for axis in range(3):
            if count[axis] > 1 and spacing[axis] < need * (1 - 1e-12):
                key = "spacing" if "spacing" in e.data or jitter == 0 else "jitter"
                why = "2·radius" if jitter == 0 else "2·radius + 2·jitter"
                raise e.error(
                    key,
                    f"neighbouring balls would overlap: spacing {spacing[axis]:g} along {'xyz'[axis]} "
                    f"is less than {why} = {need:g}",
                )
        idx = np.indices(count).reshape(3, -1).T.astype(float)  # (n, 3) in x-major order
        offsets = idx * spacing
        if center is not None:
            corner = center - 0.5 * (np.array(count) - 1) * spacing
        positions = corner + offsets
        rng = np.random.default_rng(seed)  # seeded: the same file always gives the same balls
        if jitter > 0:
            positions = positions + rng.uniform(-jitter, jitter, size=positions.shape)
        if velocity_jitter > 0:
            props["velocity"] = props["velocity"] + rng.uniform(
                -velocity_jitter, velocity_jitter, size=(n, 3)
            )
        colors = self.grid_colors(e, balls.count, n)

        def name(k: int) -> str:
            i, j, m = np.unravel_index(k, count)
            return f"ball [{i}, {j}, {m}]"

        key = "center" if center is not None else "corner"
        self.add_block(balls, e, key, positions, props, colors, name)

    def grid_colors(self, e: _Entry, first: int, n: int) -> np.ndarray:
        value = e.data.get("color")
        if value is None:
            return np.array([_palette_color(first + k) for k in range(min(n, len(PALETTE)))])[
                np.arange(n) % min(n, len(PALETTE))
            ]
        if isinstance(value, list) and value and all(isinstance(v, str | list) for v in value):
            cycle = np.array([e.parse_color("color", v, value) for v in value])
            return cycle[np.arange(n) % len(cycle)]
        return np.broadcast_to(e.parse_color("color", value), (n, 3)).copy()

    # ------------------------------------------------------------------ whole-scene checks
    def check_overlaps(self, balls: _Balls, positions: np.ndarray, radii: np.ndarray, world: World) -> None:
        pair = first_overlap(positions, radii, OVERLAP_TOLERANCE)
        if pair is not None:
            i, j = pair
            dist = float(np.linalg.norm(positions[i] - positions[j]))
            e, key, name_j = self._owner(balls, j)
            e_i, _, name_i = self._owner(balls, i)
            other = e_i.label if name_i is None else f"{e_i.label} {name_i}"
            raise e.error(
                key,
                f"{'overlaps' if name_j is None else name_j + ' overlaps'} {other} at the start: "
                f"centres {dist:.6g} m apart, radii {radii[j]:g} + {radii[i]:g} m",
            )
        planes = world.planes
        if not len(planes):
            return
        cols = (planes.centers, planes.normals, np.array([p.axes[0] for p in planes]),
                np.array([p.axes[1] for p in planes]), planes.half_sizes)  # fmt: skip
        center, _, axis_u, axis_v, half = cols
        for p in range(len(planes)):
            which = np.full(len(positions), p, dtype=np.intp)
            closest = closest_point_on_planes(positions, which, center, axis_u, axis_v, half)
            dist = np.linalg.norm(positions - closest, axis=1)
            inside = np.flatnonzero(dist < radii - OVERLAP_TOLERANCE)
            if len(inside):
                k = int(inside[0])
                e, key, name = self._owner(balls, k)
                raise e.error(
                    key,
                    f"{'the ball' if name is None else name} cuts into plane #{p + 1} at the start: "
                    f"its centre is {dist[k]:.6g} m from the plane, less than its radius {radii[k]:g} m",
                )

    @staticmethod
    def _owner(balls: _Balls, k: int) -> tuple[_Entry, str | None, str | None]:
        for start, e, key, name in reversed(balls.owners):
            if k >= start:
                return e, key, name(k - start)
        raise IndexError(k)


BALL_COLUMNS = tuple(k for k in BALL_KEYS if k != "color")  # the keys that become World columns


def first_overlap(positions: np.ndarray, radii: np.ndarray, tolerance: float = 0.0) -> tuple[int, int] | None:
    """A pair (i, j), i < j, of balls that interpenetrate by more than ``tolerance``, or None.

    A uniform grid with cells one largest diameter wide, searched with sorted cell keys, so it is
    linear in the number of balls and needs no Python loop over them.
    """
    n = len(positions)
    if n < 2:
        return None
    cell = 2.0 * float(radii.max())
    ijk = np.floor((positions - positions.min(axis=0)) / cell).astype(np.int64) + 1
    dims = ijk.max(axis=0) + 2
    keys = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    found: list[tuple[int, int]] = []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                near = keys + (dx * dims[1] + dy) * dims[2] + dz
                lo = np.searchsorted(sorted_keys, near, side="left")
                hi = np.searchsorted(sorted_keys, near, side="right")
                found.extend(_overlaps_in_ranges(positions, radii, tolerance, order, lo, hi))
                if found:
                    return min(found, key=lambda p: (p[1], p[0]))
    return None


def _overlaps_in_ranges(positions, radii, tolerance, order, lo, hi, chunk_pairs: int = 2_000_000):
    counts = hi - lo
    ends = np.cumsum(counts)
    start = 0
    n = len(positions)
    while start < n:
        # Take balls [start, stop) so that at most ~chunk_pairs candidate pairs are expanded at once.
        base = ends[start - 1] if start else 0
        stop = max(start + 1, int(np.searchsorted(ends, base + chunk_pairs, side="right")))
        c = counts[start:stop]
        i = np.repeat(np.arange(start, stop), c)
        within = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
        j = order[np.repeat(lo[start:stop], c) + within]
        keep = i < j
        i, j = i[keep], j[keep]
        d = np.linalg.norm(positions[i] - positions[j], axis=1)
        bad = d < radii[i] + radii[j] - tolerance
        if bad.any():
            bi, bj = i[bad], j[bad]
            k = np.lexsort((bi, bj))[0]  # the earliest later ball, then the earliest partner
            return [(int(bi[k]), int(bj[k]))]
        start = stop
    return []


# ---------------------------------------------------------------------------------------- helpers


def _palette_color(k: int) -> np.ndarray:
    h = PALETTE[k % len(PALETTE)]
    return np.array([int(h[i : i + 2], 16) / 255.0 for i in (1, 3, 5)])


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


def _list(a: np.ndarray) -> list[float]:
    return [float(x) for x in a]


def _frame_scene(world: World) -> tuple[np.ndarray, np.ndarray]:
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
    pts = np.concatenate([p.reshape(-1, 3) for p in points]) if points else np.zeros((0, 3))
    if len(pts) == 0:
        return np.array([0.0, 4.0, 12.0]), np.array([0.0, 2.0, 0.0])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    look_at = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1.0)
    direction = np.array([0.0, 0.35, 1.0])
    direction /= np.linalg.norm(direction)
    distance = 1.15 * radius / math.sin(math.radians(25.0))
    return look_at + distance * direction, look_at


__all__ = [
    "PALETTE",
    "SceneError",
    "SceneInfo",
    "bundled_scenes",
    "bundled_scenes_dir",
    "default_scene_path",
    "first_overlap",
    "load_scene",
    "resolve_scene_path",
]
