"""Argument checks shared by the public API: every message names the argument and the bad value."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from . import exact
from . import quaternion as rotations
from .settings import TINY

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
    norm = float(exact.norm_rows(v))
    if norm < TINY:
        raise ValueError(f"{name} must not be a zero vector, got {value!r}")
    return v / norm


def quaternion(name: str, value: object) -> np.ndarray:
    """A finite non-zero (x, y, z, w) quaternion, normalised (scaled first, like ``unit_vector``)."""
    q = vector(name, value, 4)
    biggest = float(np.abs(q).max())
    if biggest > 1.0:
        q = q / biggest
    norm = float(exact.norm_rows(q))
    if norm < TINY:
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


def array_of(
    name: str,
    value: object,
    count: int,
    width: int | None,
    within: tuple[float, float] = (-math.inf, math.inf),
) -> np.ndarray:
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


def _symmetric(limit: float) -> tuple[float, float]:
    return (-limit, limit)


def ball(
    position,
    radius,
    mass,
    velocity,
    angular_velocity,
    orientation,
    restitution,
    friction,
    rolling_friction,
    hollow,
) -> dict:
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


def balls(
    positions,
    radius,
    mass,
    velocity,
    angular_velocity,
    orientation,
    restitution,
    friction,
    rolling_friction,
    hollow,
) -> dict:
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
    if np.any(qnorm < TINY):
        raise ValueError("orientation must not be a zero quaternion")
    rows["orientation"] = q / qnorm[:, None]
    hollow_in = np.asarray(hollow)
    if hollow_in.dtype != np.bool_:
        raise TypeError(f"hollow must be True or False (or an array of them), got {hollow!r}")
    rows["hollow"] = np.broadcast_to(hollow_in, (n,))
    return rows


def plane(
    position, normal, rotation, size, restitution, friction, rolling_friction, velocity, angular_velocity
) -> tuple:
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
