"""Argument checks shared by the public API: every message names the argument and the bad value."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from . import exact
from . import quaternion as rotations
from .state import Q

# What the engine can step: far enough inside float64 that squares, products and sums of these never
# overflow or underflow (a speed of 1e154 m/s once overflowed v² in the time of impact and hung a step).
MAX_COORDINATE = 1e9  # m, any coordinate of a ball or plane centre
MAX_SPEED = 1e9  # m/s
MAX_SPIN = 1e9  # rad/s
RADIUS_RANGE = (1e-9, 1e9)  # m
MASS_RANGE = (1e-12, 1e12)  # kg
# Any component of gravity (m/s²): the same bound as every other number (and as scene files' largest),
# 1e8 g. Squares and products of it with the other bounded values stay far from overflow, and a ball
# falling under it reaches MAX_SPEED within a second, after which a step refuses it by name.
MAX_GRAVITY = 1e9
# A Python int too large for a float (10**400) is named so, not shown: its repr may be thousands of digits.
TOO_LARGE = "an integer too large for a float"
UNIT_TOLERANCE = 1e-6  # how far a plane's normal, axes or orientation may be from unit length
# The longest step (s): the same bound as every other number. Positions, speeds and accelerations within
# theirs then stay far from overflow through a step's squares and products (a step of 1e100 s overflowed
# a·h² and printed warnings before the step was undone); a step this long is a mistake, not a run.
MAX_TIMESTEP = 1e9
# Soft substeps per crowded step: as many as a split step may have intervals (settings.MAX_INTERVALS). A
# frame tried again takes up to four times as many; a step divided finer than this is a smaller
# timestep's job, and 10⁹ substeps (which a scene once asked for) would take days a step.
MAX_SUBSTEPS = 1_000
# A coefficient of restitution, a ball's or a plane's: from 0 (dead) to 1 (elastic). More would be a ball
# that leaves faster than it came, and the step keeps no impact from adding energy (impacts.py): it would
# be held to 1 without a word, so it is refused instead.
RESTITUTION_RANGE = (0.0, 1.0)


def vector(name: str, value: object, length: int = 3, limit: float = math.inf) -> np.ndarray:
    """A finite float vector of the given length, each component at most ``limit`` in size, or
    TypeError/ValueError naming ``name``."""
    if isinstance(value, str | bytes) or value is None:
        raise TypeError(f"{name} must be a sequence of {length} numbers, got {value!r}")
    try:
        arr = np.array(value, dtype=float)
    except OverflowError:  # a Python int beyond float range, 10**400
        raise ValueError(f"{name} must be finite, got {TOO_LARGE}") from None
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a sequence of {length} numbers, got {value!r}") from None
    if arr.shape != (length,):
        raise ValueError(f"{name} must have {length} components, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if np.any(np.abs(arr) > limit):
        raise ValueError(f"{name} must have components of at most {limit:g} in size, got {value!r}")
    return arr


def number(
    name: str,
    value: object,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    infinite: bool = False,
    within: tuple[float, float] | None = None,
) -> float:
    """A finite float (or ±inf if ``infinite``; never NaN), optionally > 0, ≥ 0 or ``within`` a range."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise TypeError(f"{name} must be a number, got {value!r}")
    try:
        x = float(value)
    except OverflowError:  # a Python int beyond float range, 10**400
        raise ValueError(f"{name} must be finite, got {TOO_LARGE}") from None
    if math.isnan(x) or (math.isinf(x) and not infinite):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if positive and x <= 0.0:
        raise ValueError(f"{name} must be positive, got {value!r}")
    if nonnegative and x < 0.0:
        raise ValueError(f"{name} must not be negative, got {value!r}")
    if within is not None and not within[0] <= x <= within[1]:
        raise ValueError(f"{name} must be from {within[0]:g} to {within[1]:g}, got {value!r}")
    return x


def whole_number(name: str, value: object, low: int, high: int | None = None) -> int:
    """An int (a NumPy integer too, never a bool) from ``low`` to ``high``, or ValueError naming ``name``."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | np.integer)
        or value < low
        or (high is not None and value > high)
    ):
        bound = f"of at least {low}" if high is None else f"from {low} to {high:,}"
        raise ValueError(f"{name} must be a whole number {bound}, got {value!r}")
    return int(value)


def timestep(dt: object) -> float:
    """A step's length (s): positive and at most ``MAX_TIMESTEP``."""
    x = number("dt", dt, positive=True)
    if x > MAX_TIMESTEP:
        raise ValueError(f"dt must be at most {MAX_TIMESTEP:g} s, got {dt!r}")
    return x


def unit_vector(name: str, value: object) -> np.ndarray:
    """A finite non-zero 3-vector, normalised (scaled first, so huge components keep their direction)."""
    v = vector(name, value)
    biggest = float(np.abs(v).max())
    if biggest > 1.0:
        v = v / biggest
    norm = float(exact.norm(v))
    if norm < 1e-12:
        raise ValueError(f"{name} must not be a zero vector, got {value!r}")
    return v / norm


def quaternion(name: str, value: object) -> np.ndarray:
    """A finite non-zero (x, y, z, w) quaternion, normalised (scaled first, like ``unit_vector``)."""
    q = vector(name, value, 4)
    biggest = float(np.abs(q).max())
    if biggest > 1.0:
        q = q / biggest
    norm = float(exact.norm(q))
    if norm < 1e-12:
        raise ValueError(f"{name} must not be a zero quaternion, got {value!r}")
    return q / norm


def plane_size(name: str, value: object) -> tuple[float, float]:
    """A plane's size: a number (square side) or (width, depth), each positive; inf means unbounded."""
    if isinstance(value, Sequence) and not isinstance(value, str):
        if len(value) != 2:
            raise ValueError(f"{name} must be a number or [width, depth], got {value!r}")
        w, d = (_extent(name, v, value) for v in value)
        return w, d
    s = _extent(name, value, value)
    return s, s


def _extent(name: str, v: object, whole: object) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
        raise TypeError(f"{name} must be a number or [width, depth], got {whole!r}")
    try:
        x = float(v)
    except OverflowError:  # a Python int beyond float range, 10**400
        raise ValueError(f"{name} must be finite or inf, got {TOO_LARGE}") from None
    if math.isnan(x) or x <= 0.0:
        raise ValueError(f"{name} must be positive, got {whole!r}")
    return x


def array_of(name: str, value: object, count: int, width: int | None,
             within: tuple[float, float] = (-math.inf, math.inf)) -> np.ndarray:  # fmt: skip
    """Broadcast a batch argument to (count,) or (count, width) floats, all finite and ``within``."""
    try:
        arr = np.asarray(value, dtype=float)
    except OverflowError:  # a Python int beyond float range, 10**400
        raise ValueError(f"{name} must be finite, got {TOO_LARGE}") from None
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be numeric, got {value!r}") from None
    shape = (count,) if width is None else (count, width)
    try:
        arr = np.broadcast_to(arr, shape)
    except ValueError:
        raise ValueError(f"{name} must broadcast to shape {shape}, got shape {arr.shape}") from None
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)].ravel()[0]
        raise ValueError(f"{name} must be finite, got {bad!r}")
    outside = (arr < within[0]) | (arr > within[1])
    if outside.any():
        bad = arr[outside].ravel()[0]
        raise ValueError(f"{name} must be from {within[0]:g} to {within[1]:g}, got {bad!r}")
    return arr


# Column ranges of a ball's state row [x v q ω] and what each may hold, for naming what went wrong.
_STATE_FIELDS = (
    ("position", 0, 3, MAX_COORDINATE),
    ("velocity", 3, 6, MAX_SPEED),
    ("orientation", 6, 10, math.inf),
    ("angular_velocity", 10, 13, MAX_SPIN),
)
_STATE_LIMITS = np.concatenate([np.full(stop - start, lim) for _, start, stop, lim in _STATE_FIELDS])
_SMALLEST_LIMIT = float(_STATE_LIMITS.min())


# A ball's orientation may have any length a step can normalise (every step does): not one whose squared
# length underflows to nothing (a zero quaternion) or overflows.
_SHORTEST_TURN2 = 1e-24


class LastGoodBalls:
    """Each field of the balls' state (position, velocity, orientation, spin) as the last step left it,
    copied when a view first hands that field out after a step: what a bad value written through a
    view is put back to.

    A copy every step would cost a pass over every ball (2 % of a 100,000-ball free fall); copied only
    when handed out, a field costs a step nothing unless someone looks at it. While orientations are
    out, the next step also checks that each can be normalised (a zero quaternion cannot), which it
    otherwise leaves to its own normalising. A value written through a view kept from before the last
    step is refused by name but cannot be put back: no copy was taken for it.
    """

    def __init__(self) -> None:
        self._copies: dict[int, np.ndarray] = {}  # by a field's first column: its copy, rows to spare
        self._out: dict[int, slice] = {}  # the fields handed out since the last step
        self.count = 0  # the balls each copy holds

    @property
    def exposed(self) -> bool:
        return bool(self._out)

    def expose(self, body: np.ndarray, field: slice) -> None:
        """``body[:, field]`` is being handed out: copy it first, once between two steps."""
        if not self._out:
            self.count = len(body)
        if field.start not in self._out:
            self._out[field.start] = field
            self._copy(body, field, 0)
        self.grow(body)

    def grow(self, body: np.ndarray) -> None:
        """Copy the rows of balls added since the copies were taken (checked as they were added)."""
        if not self._out or len(body) <= self.count:
            return
        for field in self._out.values():
            self._copy(body, field, self.count)
        self.count = len(body)

    def _copy(self, body: np.ndarray, field: slice, start: int) -> None:
        """Copy rows ``start``.. of ``body[:, field]``, growing its copy (doubling) to hold them."""
        copy = self._copies.get(field.start)
        if copy is None or len(copy) < len(body):
            grown = np.empty(
                (max(len(body), 2 * (0 if copy is None else len(copy))), field.stop - field.start)
            )
            if copy is not None:
                grown[:start] = copy[:start]
            self._copies[field.start] = copy = grown
        copy[start : len(body)] = body[start:, field]

    def forget(self) -> None:
        """The state changes from here without a view (a step, a restore): the copies are out of date."""
        self._out.clear()

    @property
    def orientations_out(self) -> bool:
        return Q.start in self._out

    def put_back(self, body: np.ndarray) -> bool:
        """Put every value a step cannot use back as the copies have it; True when none is left."""
        n = min(len(body), self.count)
        bad = _unusable(body[:n])
        for field in self._out.values():
            part, good, wrong = body[:n, field], self._copies[field.start][:n], bad[:, field]
            part[wrong] = good[wrong]
        return _unsteppable(body) is None and _unturnable(body) is None


def _unusable(body: np.ndarray) -> np.ndarray:
    """A mask of the entries a step cannot use: beyond their limits, non-finite, or in an orientation
    that cannot be normalised."""
    bad = ~(np.abs(body) <= _STATE_LIMITS)
    bad[:, Q] |= ~_turnable(body)[:, None]
    return bad


def _turnable(body: np.ndarray) -> np.ndarray:
    """Which balls' orientations a step can normalise."""
    q = body[:, Q]
    with np.errstate(over="ignore"):  # a square that overflows is what this looks for
        q2 = q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2] + q[:, 3] * q[:, 3]
    return (q2 >= _SHORTEST_TURN2) & (q2 < math.inf)


def _unturnable(body: np.ndarray) -> str | None:
    """The first ball whose orientation cannot be normalised, with what is wrong, or None."""
    bad = np.flatnonzero(~_turnable(body))
    if len(bad) == 0:
        return None
    row = int(bad[0])
    q = body[row, Q]
    what = "a zero" if np.abs(q).max() < 1.0 else "a too large"  # NaN is named by _unsteppable first
    return f"{row} has {what} orientation quaternion {q.tolist()}, which cannot be normalised"


def reject_unsteppable_state(body: np.ndarray, last_good: LastGoodBalls | None = None) -> None:
    """Refuse to step from a NaN/inf, or a value beyond what the engine can step, written straight
    into the arrays (the setters check theirs); while ``last_good`` has the orientations handed out,
    from one that cannot be normalised too. Every bad value is put back as ``last_good`` copied it,
    so the world keeps its last good state, as with planes (``reject_bad_planes``)."""
    exposed = last_good is not None and last_good.exposed
    turned = last_good is not None and last_good.orientations_out
    bad = _unsteppable(body) or (_unturnable(body) if turned else None)
    if bad is None:
        if last_good is not None:
            last_good.forget()  # the step changes the state from here
        return
    kept = exposed and last_good.put_back(body)  # type: ignore[union-attr]
    raise ValueError(f"sphere #{bad}; the world was not stepped" + (" and keeps its last good state" * kept))


def _unsteppable(body: np.ndarray) -> str | None:
    """The first ball whose state the engine cannot step, with what is wrong ("3 has a non-finite
    velocity (nan)"), or None."""
    # Every value within the smallest limit passes: two passes over the block, no temporaries (a NaN
    # makes max and min NaN, which fails too). Only then is it looked at field by field.
    if len(body) == 0 or (body.max() <= _SMALLEST_LIMIT and body.min() >= -_SMALLEST_LIMIT):
        return None
    bad = ~(np.abs(body) <= _STATE_LIMITS)  # NaN compares false
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    field, _, _, limit = next(f for f in _STATE_FIELDS if f[1] <= col < f[2])
    what = "a non-finite" if not np.isfinite(body[row, col]) else f"beyond {limit:g} in its"
    return f"{row} has {what} {field} ({body[row, col]})"


def undo_non_finite_step(body: np.ndarray, before: np.ndarray) -> None:
    """Keep the world free of NaN/inf, and of values the next step would refuse: restore the state and
    raise if a step produced any (``step(1e6)`` let balls fall 5e12 m, and the next step then refused
    the world's own state)."""
    if not np.isfinite(body).all():
        bad = int(np.flatnonzero(~np.isfinite(body).all(axis=1))[0])
        body[:] = before
        raise FloatingPointError(f"step made sphere #{bad}'s state non-finite; the step was undone")
    beyond = _unsteppable(body)
    if beyond is not None:
        body[:] = before
        raise ValueError(f"after the step sphere #{beyond}; the step was undone (take shorter steps)")


def _symmetric(limit: float) -> tuple[float, float]:
    return (-limit, limit)


def ball(position, radius, mass, velocity, angular_velocity, orientation, restitution, friction,
         rolling_friction, hollow) -> dict:  # fmt: skip
    """``World.add_sphere``'s arguments, checked: the ball's state and properties by column name."""
    if not isinstance(hollow, bool | np.bool_):
        raise TypeError(f"hollow must be True or False, got {hollow!r}")
    return dict(
        position=vector("position", position, limit=MAX_COORDINATE),
        velocity=vector("velocity", velocity, limit=MAX_SPEED),
        angular_velocity=vector("angular_velocity", angular_velocity, limit=MAX_SPIN),
        orientation=quaternion("orientation", orientation),
        radius=number("radius", radius, within=RADIUS_RANGE),
        mass=number("mass", mass, within=MASS_RANGE),
        restitution=number("restitution", restitution, within=RESTITUTION_RANGE),
        friction=number("friction", friction, nonnegative=True),
        rolling_friction=number("rolling_friction", rolling_friction, nonnegative=True),
        hollow=bool(hollow),
    )


def balls(positions, radius, mass, velocity, angular_velocity, orientation, restitution, friction,
          rolling_friction, hollow) -> dict:  # fmt: skip
    """``World.add_spheres``' arguments, checked and broadcast against ``positions`` (N, 3)."""
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"positions must have shape (N, 3), got shape {pos.shape}")
    n = len(pos)
    rows = dict(
        position=array_of("positions", pos, n, 3, _symmetric(MAX_COORDINATE)),
        velocity=array_of("velocity", velocity, n, 3, _symmetric(MAX_SPEED)),
        angular_velocity=array_of("angular_velocity", angular_velocity, n, 3, _symmetric(MAX_SPIN)),
        orientation=array_of("orientation", orientation, n, 4),
        radius=array_of("radius", radius, n, None, RADIUS_RANGE),
        mass=array_of("mass", mass, n, None, MASS_RANGE),
        restitution=array_of("restitution", restitution, n, None, RESTITUTION_RANGE),
        friction=array_of("friction", friction, n, None, (0.0, math.inf)),
        rolling_friction=array_of("rolling_friction", rolling_friction, n, None, (0.0, math.inf)),
    )
    q = rows["orientation"]
    q = q / np.maximum(np.abs(q).max(axis=1, keepdims=True), 1.0)  # huge components keep their turn
    qnorm = np.linalg.norm(q, axis=1)
    if np.any(qnorm < 1e-12):
        raise ValueError("orientation must not be a zero quaternion")
    rows["orientation"] = q / qnorm[:, None]
    hollow_in = np.asarray(hollow)
    if hollow_in.dtype != np.bool_:
        raise TypeError(f"hollow must be True or False (or an array of them), got {hollow!r}")
    rows["hollow"] = np.broadcast_to(hollow_in, (n,))
    return rows


def plane(position, normal, rotation, size, restitution, friction, rolling_friction, velocity,
          angular_velocity) -> tuple:  # fmt: skip
    """``World.add_plane``'s arguments, checked: centre, orientation (turning +y to the normal),
    (width, depth), materials and motion."""
    center = vector("position", position, limit=MAX_COORDINATE)
    if normal is not None and rotation is not None:
        raise ValueError(
            f"give a plane's normal or its rotation, not both (normal={normal!r}, rotation={rotation!r})"
        )
    if rotation is not None:
        q = rotations.from_euler_xyz(vector("rotation", rotation))
    elif normal is not None:
        q = rotations.from_up_to(unit_vector("normal", normal))
    else:
        q = rotations.IDENTITY.copy()
    extent = (math.inf, math.inf) if size is None else plane_size("size", size)
    materials = {
        "restitution": number("restitution", restitution, within=RESTITUTION_RANGE),
        "friction": number("friction", friction, nonnegative=True),
        "rolling_friction": number("rolling_friction", rolling_friction, nonnegative=True),
    }
    motion = {
        "velocity": vector("velocity", velocity, limit=MAX_SPEED),
        "angular_velocity": vector("angular_velocity", angular_velocity, limit=MAX_SPIN),
    }
    return center, q, extent, materials, motion


# The plane columns a user can write through ``world.planes`` (its columns, or a plane's vectors), what
# each must hold, and where it lives ("pose": state.planes, moved by a step; "shape": model.planes).
# Kinds: "bounded" |x| <= limit, "unit" rows of length 1, "extent" positive (inf: unbounded),
# "material" finite and not negative, "fraction" from 0 to 1.
_PLANE_FIELDS = (
    ("center", "pose", "bounded", MAX_COORDINATE),
    ("orientation", "pose", "unit", None),
    ("normal", "pose", "unit", None),
    ("axis_u", "pose", "unit", None),
    ("axis_v", "pose", "unit", None),
    ("velocity", "shape", "bounded", MAX_SPEED),
    ("angular_velocity", "shape", "bounded", MAX_SPIN),
    ("half_size", "shape", "extent", None),
    ("restitution", "shape", "fraction", None),
    ("friction", "shape", "material", None),
    ("rolling_friction", "shape", "material", None),
)
_PLANE_RULES = {
    "bounded": "must be finite and at most {limit:g} in size",
    "unit": "must be a unit vector",
    "extent": "must be positive (inf: unbounded)",
    "material": "must be finite and not negative",
    "fraction": "must be from 0 to 1",
}


def _bad_plane_values(kind: str, arr: np.ndarray, limit: float | None) -> np.ndarray:
    """A mask of the entries of ``arr`` that a step cannot use (NaN fails every comparison)."""
    if kind == "bounded":
        return ~(np.abs(arr) <= limit)
    if kind == "unit":
        length = np.sqrt(np.sum(arr * arr, axis=1, keepdims=True))
        return np.broadcast_to(~(np.abs(length - 1.0) <= UNIT_TOLERANCE), arr.shape)
    if kind == "extent":
        return ~(arr > 0.0)
    if kind == "fraction":
        return ~((arr >= 0.0) & (arr <= 1.0))
    return ~((arr >= 0.0) & (arr < math.inf))


def plane_columns(shape, pose) -> list[np.ndarray]:
    """The live plane columns ``reject_bad_planes`` checks (``shape``/``pose``: the model's and the
    state's plane Columns), in its order."""
    n = shape.count  # every step looks: full(name)[:n] costs a third of Columns.__getattr__
    return [(pose if where == "pose" else shape).full(name)[:n] for name, where, _, _ in _PLANE_FIELDS]


class PlanesAsStepped:
    """Every checked plane column as the last step left it, flattened into one copy, and each plane added
    since (checked as it was added): what ``reject_bad_planes`` compares with and puts bad values back to.

    Adding a plane appends its row, merged into the copy when a step next looks, so adding P planes costs
    O(P), not a copy of every plane each time (40,000 planes once took 18 s to load)."""

    def __init__(self, flat: np.ndarray, count: int) -> None:
        self._flat = flat
        self._count = count
        self._added: list[np.ndarray] = []
        self._widths: tuple[int, ...] = ()  # how many numbers each column has per plane

    def add(self, shape, pose) -> None:
        """Remember the plane just added (the last of ``shape``'s and ``pose``'s rows)."""
        i = shape.count - 1
        row = [c[i].ravel() for c in plane_columns(shape, pose)]
        self._widths = tuple(len(r) for r in row)
        self._added.append(np.concatenate(row))

    def flat(self) -> np.ndarray:
        """The copy, with the planes added since merged in, column by column."""
        if self._added:
            added = np.stack(self._added)
            count = self._count + len(added)
            parts, at, column = [], 0, 0
            for width in self._widths:
                parts.append(self._flat[at : at + self._count * width])
                parts.append(added[:, column : column + width].ravel())
                at += self._count * width
                column += width
            self._flat, self._count, self._added = np.concatenate(parts), count, []
        return self._flat


def planes_as_stepped(shape, pose) -> PlanesAsStepped:
    """Every checked plane column, flattened into one copy: what ``reject_bad_planes`` compares with."""
    columns = plane_columns(shape, pose)
    return PlanesAsStepped(np.concatenate([c.ravel() for c in columns]), shape.count)


def reject_bad_planes(shape, pose, good: PlanesAsStepped | None) -> PlanesAsStepped:
    """Refuse to step with a NaN, inf or out-of-range value written into a plane (a ``world.planes``
    column or a plane's vector): ValueError naming the plane, the field and the value. ``good`` is
    ``planes_as_stepped`` after the last step: when nothing differs from it there is nothing to check
    (the common case costs one copy and one comparison); every bad entry is put back as it was there,
    so the world keeps its last good state. Returns the columns checked."""
    columns = plane_columns(shape, pose)
    now = np.concatenate([c.ravel() for c in columns])
    checked = PlanesAsStepped(now, shape.count)
    good_flat = None if good is None else good.flat()
    if good_flat is not None and good_flat.shape == now.shape and (now == good_flat).all():
        return checked
    restorable = good_flat is not None and good_flat.shape == now.shape
    first, at = None, 0
    for arr, (name, _, kind, limit) in zip(columns, _PLANE_FIELDS, strict=True):
        before = good_flat[at : at + arr.size].reshape(arr.shape) if restorable else None  # type: ignore[index]
        at += arr.size
        bad = _bad_plane_values(kind, arr, limit)
        if not bad.any():
            continue
        if first is None:
            row = int(np.argwhere(bad)[0][0])
            rule = _PLANE_RULES[kind].format(limit=limit)
            first = f"plane #{row} has a bad {name} {arr[row].tolist()}: it {rule}"
        if before is not None:
            arr[bad] = before[bad]
    if first is not None:
        raise ValueError(f"{first}; the world was not stepped and keeps its last good state")
    return checked
