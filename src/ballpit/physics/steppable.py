"""What a step can step, checked at its start and its end: the balls' states and the planes' values
written straight into the arrays (the setters check theirs), and the state a step leaves. Every
message names the ball or plane, the field and the value."""

from __future__ import annotations

import math

import numpy as np

from .validation import MAX_COORDINATE, MAX_SPEED, MAX_SPIN, UNIT_TOLERANCE

# Column ranges of a ball's state row [x v q ω] and what each may hold, for naming what went wrong.
_STATE_FIELDS = (
    ("position", 0, 3, MAX_COORDINATE),
    ("velocity", 3, 6, MAX_SPEED),
    ("orientation", 6, 10, math.inf),
    ("angular_velocity", 10, 13, MAX_SPIN),
)
_STATE_LIMITS = np.concatenate([np.full(stop - start, lim) for _, start, stop, lim in _STATE_FIELDS])
_SMALLEST_LIMIT = float(_STATE_LIMITS.min())


def reject_unsteppable_state(body: np.ndarray) -> None:
    """Refuse to step from a NaN/inf, or a value beyond what the engine can step, written straight
    into the arrays (the setters check theirs)."""
    bad = _unsteppable(body)
    if bad is not None:
        raise ValueError(f"sphere #{bad}; the world was not stepped")


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


def step_fault(body: np.ndarray) -> FloatingPointError | ValueError | None:
    """What is wrong with the state ``body`` a step left, as the error to raise once the step is undone,
    or None: a NaN/inf, or a value the next step would refuse (``step(1e6)`` let balls fall 5e12 m, and
    the next step then refused the world's own state)."""
    if not np.isfinite(body).all():
        bad = int(np.flatnonzero(~np.isfinite(body).all(axis=1))[0])
        return FloatingPointError(f"step made sphere #{bad}'s state non-finite; the step was undone")
    beyond = _unsteppable(body)
    if beyond is not None:
        return ValueError(f"after the step sphere #{beyond}; the step was undone (take shorter steps)")
    return None


# The plane columns a user can write through ``world.planes`` (its columns, or a plane's vectors), what
# each must hold, and where it lives ("pose": state.planes, moved by a step; "shape": model.planes).
# Kinds: "bounded" |x| <= limit, "unit" rows of length 1, "extent" positive (inf: unbounded),
# "material" finite and not negative.
_PLANE_FIELDS = (
    ("center", "pose", "bounded", MAX_COORDINATE),
    ("orientation", "pose", "unit", None),
    ("normal", "pose", "unit", None),
    ("axis_u", "pose", "unit", None),
    ("axis_v", "pose", "unit", None),
    ("velocity", "shape", "bounded", MAX_SPEED),
    ("angular_velocity", "shape", "bounded", MAX_SPIN),
    ("half_size", "shape", "extent", None),
    ("restitution", "shape", "material", None),
    ("friction", "shape", "material", None),
    ("rolling_friction", "shape", "material", None),
)
_PLANE_RULES = {
    "bounded": "must be finite and at most {limit:g} in size",
    "unit": "must be a unit vector",
    "extent": "must be positive (inf: unbounded)",
    "material": "must be finite and not negative",
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
    return ~((arr >= 0.0) & (arr < math.inf))


def plane_columns(shape, pose) -> list[np.ndarray]:
    """The live plane columns ``reject_bad_planes`` checks (``shape``/``pose``: the model's and the
    state's plane Columns), in its order."""
    n = shape.count  # every step looks: full(name)[:n] costs a third of Columns.__getattr__
    return [(pose if where == "pose" else shape).full(name)[:n] for name, where, _, _ in _PLANE_FIELDS]


def planes_as_stepped(shape, pose) -> np.ndarray:
    """Every checked plane column, flattened into one copy: what ``reject_bad_planes`` compares with."""
    return np.concatenate([c.ravel() for c in plane_columns(shape, pose)])


def reject_bad_planes(shape, pose, good: np.ndarray | None) -> np.ndarray:
    """Refuse to step with a NaN, inf or out-of-range value written into a plane (a ``world.planes``
    column or a plane's vector): ValueError naming the plane, the field and the value. ``good`` is
    ``planes_as_stepped`` after the last step: when nothing differs from it there is nothing to check
    (the common case costs one copy and one comparison); every bad entry is put back as it was there,
    so the world keeps its last good state. Returns the columns checked, flattened."""
    columns = plane_columns(shape, pose)
    now = np.concatenate([c.ravel() for c in columns])
    if good is not None and good.shape == now.shape and (now == good).all():
        return now
    restorable = good is not None and good.shape == now.shape
    first, at = None, 0
    for arr, (name, _, kind, limit) in zip(columns, _PLANE_FIELDS, strict=True):
        before = good[at : at + arr.size].reshape(arr.shape) if restorable else None
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
    return now
