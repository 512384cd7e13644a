"""What a step can step, checked at its start and its end: the balls' states and the planes' values
written straight into the arrays (the setters check theirs), and the state a step leaves. Every
message names the ball or plane, the field and the value."""

from __future__ import annotations

import math

import numpy as np

from .state import Q
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
    if len(body) == 0 or _within_smallest_limit(body):
        return None
    bad = ~(np.abs(body) <= _STATE_LIMITS)  # NaN compares false
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    field, _, _, limit = next(f for f in _STATE_FIELDS if f[1] <= col < f[2])
    what = "a non-finite" if not np.isfinite(body[row, col]) else f"beyond {limit:g} in its"
    return f"{row} has {what} {field} ({body[row, col]})"


def _within_smallest_limit(body: np.ndarray) -> bool:
    """Every value of ``body`` within the smallest limit (a NaN makes the max and min NaN, which fail):
    two reductions without ``ndarray.max``'s Python wrapper."""
    return bool(
        np.maximum.reduce(body, axis=None) <= _SMALLEST_LIMIT
        and np.minimum.reduce(body, axis=None) >= -_SMALLEST_LIMIT
    )


def step_fault(body: np.ndarray) -> FloatingPointError | ValueError | None:
    """What is wrong with the state ``body`` a step left, as the error to raise once the step is undone,
    or None: a NaN/inf, or a value the next step would refuse (``step(1e6)`` let balls fall 5e12 m, and
    the next step then refused the world's own state)."""
    if len(body) == 0 or _within_smallest_limit(body):  # the common case: finite and within every limit
        return None
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
    # every step looks: each column's live rows are a plain attribute (``Columns._publish``)
    return [getattr(pose if where == "pose" else shape, name) for name, where, _, _ in _PLANE_FIELDS]


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
