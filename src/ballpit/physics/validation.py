"""Argument checks shared by the public API: every message names the argument and the bad value."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def vector(name: str, value: object, length: int = 3) -> np.ndarray:
    """A finite float vector of the given length, or TypeError/ValueError naming ``name``."""
    if isinstance(value, str | bytes) or value is None:
        raise TypeError(f"{name} must be a sequence of {length} numbers, got {value!r}")
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a sequence of {length} numbers, got {value!r}") from None
    if arr.shape != (length,):
        raise ValueError(f"{name} must have {length} components, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return arr


def number(
    name: str, value: object, *, positive: bool = False, nonnegative: bool = False, infinite: bool = False
) -> float:
    """A finite float (or ±inf if ``infinite``; never NaN), optionally > 0 or ≥ 0."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise TypeError(f"{name} must be a number, got {value!r}")
    x = float(value)
    if math.isnan(x) or (math.isinf(x) and not infinite):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if positive and x <= 0.0:
        raise ValueError(f"{name} must be positive, got {value!r}")
    if nonnegative and x < 0.0:
        raise ValueError(f"{name} must not be negative, got {value!r}")
    return x


def unit_vector(name: str, value: object) -> np.ndarray:
    """A finite non-zero 3-vector, normalised."""
    v = vector(name, value)
    norm = float(np.linalg.norm(v))
    if norm < 1e-12:
        raise ValueError(f"{name} must not be a zero vector, got {value!r}")
    return v / norm


def quaternion(name: str, value: object) -> np.ndarray:
    """A finite non-zero (x, y, z, w) quaternion, normalised."""
    q = vector(name, value, 4)
    norm = float(np.linalg.norm(q))
    if norm < 1e-12:
        raise ValueError(f"{name} must not be a zero quaternion, got {value!r}")
    return q / norm


def size(name: str, value: object) -> tuple[float, float]:
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
    x = float(v)
    if math.isnan(x) or x <= 0.0:
        raise ValueError(f"{name} must be positive, got {whole!r}")
    return x


def array_of(name: str, value: object, count: int, width: int | None) -> np.ndarray:
    """Broadcast a batch argument to (count,) or (count, width) floats, all finite."""
    try:
        arr = np.asarray(value, dtype=float)
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
    return arr


# Column ranges of a ball's state row [x v q ω], for naming what went non-finite.
_STATE_FIELDS = (("position", 0, 3), ("velocity", 3, 6), ("orientation", 6, 10), ("angular_velocity", 10, 13))


def reject_non_finite_state(body: np.ndarray) -> None:
    """Refuse to step from a NaN/inf written straight into the arrays (the setters check theirs)."""
    if np.isfinite(body).all():
        return
    row, col = np.argwhere(~np.isfinite(body))[0]
    field = next(name for name, start, stop in _STATE_FIELDS if start <= col < stop)
    raise ValueError(f"sphere #{row} has a non-finite {field} ({body[row, col]}); the world was not stepped")


def undo_non_finite_step(body: np.ndarray, before: np.ndarray) -> None:
    """Keep the world free of NaN/inf: restore the state and raise if a step produced any."""
    if not np.isfinite(body).all():
        bad = int(np.flatnonzero(~np.isfinite(body).all(axis=1))[0])
        body[:] = before
        raise FloatingPointError(f"step made sphere #{bad}'s state non-finite; the step was undone")
