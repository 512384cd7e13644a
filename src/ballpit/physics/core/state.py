"""The state: what a step advances (each ball's position, velocity, orientation and spin, each
plane's pose, and the time), kept apart from the model (``model.py``), what a step only reads.

Storage is structure-of-arrays (``Columns``): arrays allocated with spare capacity that doubles when
full, so adding balls one at a time is amortised O(1). The live part of each array is its first
``count`` rows.

The ball's dynamic state is one (capacity, 13) block, ``[x(3) v(3) q(4) ω(3)]``, so an integrator
combines whole states with a handful of array operations; ``X``, ``V``, ``Q`` and ``W`` are its column
slices.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# Column slices of the dynamic state block.
X = slice(0, 3)
V = slice(3, 6)
Q = slice(6, 10)
W = slice(10, 13)
STATE_WIDTH = 13


class Columns:
    """Named arrays that share a leading capacity dimension and grow together."""

    def __init__(self, spec: dict[str, tuple[tuple[int, ...], type]], capacity: int = 16) -> None:
        self.count = 0
        self.capacity = capacity
        self._arrays = {k: np.zeros((capacity, *shape), dtype) for k, (shape, dtype) in spec.items()}
        self._publish()

    def _publish(self) -> None:
        """Keep each array's live part as an attribute, so reading one costs a plain attribute lookup
        (a step reads them some eighty times); done again whenever ``count`` or the arrays change."""
        for k, array in self._arrays.items():
            self.__dict__[k] = array[: self.count]

    def __getstate__(self) -> dict:
        """The columns without their live views (a copy makes its own from its own arrays)."""
        return {k: v for k, v in self.__dict__.items() if k not in self._arrays}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._publish()

    def reserve(self, extra: int) -> slice:
        """Make room for ``extra`` more rows; returns the slice of the new rows."""
        needed = self.count + extra
        if needed > self.capacity:
            capacity = max(needed, 2 * self.capacity)
            for k, old in self._arrays.items():
                new = np.zeros((capacity, *old.shape[1:]), old.dtype)
                new[: self.count] = old[: self.count]
                self._arrays[k] = new
            self.capacity = capacity
        rows = slice(self.count, needed)
        self.count = needed
        self._publish()
        return rows

    def full(self, name: str) -> np.ndarray:
        """The whole allocated array, spare rows included (for writing new rows)."""
        return self._arrays[name]

    def remove(self, row: int) -> None:
        """Drop row ``row``; the rows after it move up by one."""
        for array in self._arrays.values():
            array[row : self.count - 1] = array[row + 1 : self.count]
        self.count -= 1
        self._publish()

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = self.__dict__.get("_arrays")
        if arrays is None or name not in arrays:
            raise AttributeError(name)
        return arrays[name][: self.count]


# A plane's pose: what a step changes of a plane (moving_planes.py).
PLANE_POSE = ("center", "orientation", "normal", "axis_u", "axis_v")


def plane_pose_columns() -> Columns:
    """Per-plane pose: centre and frame. Planes are kinematic: a step moves them as told."""
    f = float
    return Columns(
        {
            "center": ((3,), f),
            "orientation": ((4,), f),  # the rotation taking +y to the normal
            "normal": ((3,), f),  # the plane's +y axis
            "axis_u": ((3,), f),  # width direction, the plane's +x axis
            "axis_v": ((3,), f),  # depth direction, the plane's +z axis
        },
        capacity=4,
    )


class Sleep:
    """Per-ball sleep bookkeeping (the rules are in ``sleeping.py``), kept with the state so snapshots
    carry it.

    Its arrays are never changed in place: every change makes new ones, so a checkpoint of the state
    holds them as they are (a copy of the object, not of its arrays)."""

    def __init__(self) -> None:
        self.rest = np.zeros(0)  # seconds each ball has been still
        self.asleep = np.zeros(0, bool)
        self.island = np.zeros(0, np.int64)  # which island a sleeping ball fell asleep with
        # x and q of each sleeping ball when it fell asleep: (N, 7) from the first fall, (0, 7) in a world
        # where nothing has slept
        self.pose = np.zeros((0, 7))
        self.islands = 0  # islands put to sleep so far (their ids)
        self.context: tuple | None = None  # what every sleeping ball's rest depends on

    def fit(self, n: int) -> None:
        """Room for ``n`` balls (balls are only ever added): those added since the last step are awake."""
        extra = n - len(self.rest)
        if extra == 0:
            return
        self.rest = np.concatenate((self.rest, np.zeros(extra)))
        self.asleep = np.concatenate((self.asleep, np.zeros(extra, bool)))
        self.island = np.concatenate((self.island, np.zeros(extra, np.int64)))
        if len(self.pose):
            self.pose = np.concatenate((self.pose, np.zeros((extra, 7))))

    @property
    def any(self) -> bool:
        return bool(np.count_nonzero(self.asleep))

    def wake(self, balls: np.ndarray) -> None:
        """Wake the islands of the sleeping balls ``balls`` (a mask or indices), whole."""
        ids = np.unique(self.island[balls][self.asleep[balls]])
        if ids.size == 0:
            return
        woken = self.asleep & np.isin(self.island, ids)
        self.asleep = self.asleep & ~woken
        self.rest = np.where(woken, 0.0, self.rest)

    def wake_all(self) -> None:
        self.asleep = np.zeros_like(self.asleep)
        self.rest = np.zeros_like(self.rest)

    def fall_asleep(self, idx: np.ndarray, group: np.ndarray, x: np.ndarray, q: np.ndarray) -> None:
        """Put the balls ``idx`` to sleep, each in the new island ``group`` numbers (0, 1, …), where they
        are (positions ``x``, orientations ``q``)."""
        island = self.island.copy()
        island[idx] = self.islands + group
        self.island = island
        self.islands += int(group.max()) + 1
        asleep = self.asleep.copy()
        asleep[idx] = True
        self.asleep = asleep
        pose = self.pose.copy() if len(self.pose) == len(self.rest) else np.zeros((len(self.rest), 7))
        pose[idx, :3] = x
        pose[idx, 3:] = q
        self.pose = pose


class State:
    """What a step advances: the (N, 13) block ``[x v q ω]`` of every ball, each plane's pose, the
    world time (s), and which balls are asleep (``sleeping.py``)."""

    def __init__(self) -> None:
        self._rows = Columns({"body": ((STATE_WIDTH,), float)})
        self.planes = plane_pose_columns()
        self.time = 0.0
        self.sleep = Sleep()

    @property
    def body(self) -> np.ndarray:
        """The live (N, 13) state block; its columns are ``X``, ``V``, ``Q`` and ``W``."""
        return self._rows.body

    @property
    def count(self) -> int:
        return self._rows.count

    @property
    def capacity(self) -> int:
        return self._rows.capacity

    def reserve(self, extra: int) -> np.ndarray:
        """Room for ``extra`` more balls; returns their rows of the block, to be filled in."""
        rows = self._rows.reserve(extra)
        return self._rows.full("body")[rows]

    def remove(self, row: int) -> None:
        """Drop ball ``row`` (the later balls move up by one); every ball wakes."""
        self._rows.remove(row)
        self.sleep = Sleep()
        self.sleep.fit(self.count)

    def checkpoint(self) -> SavedState:
        """What ``restore`` needs to put this state back: copies of the balls' block and of the planes'
        poses, the time, and the sleep bookkeeping (whose arrays are never changed in place)."""
        pose = self.planes  # its PLANE_POSE columns, in that order
        poses = (
            pose.center.copy(),
            pose.orientation.copy(),
            pose.normal.copy(),
            pose.axis_u.copy(),
            pose.axis_v.copy(),
        )
        return SavedState(self.body.copy(), poses, self.time, shallow_copy(self.sleep))

    def restore(self, saved: SavedState) -> None:
        """Put back the state ``saved`` (a ``checkpoint``; it stays usable)."""
        _put_back(self._rows, ("body",), (saved.body,))
        _put_back(self.planes, PLANE_POSE, saved.poses)
        self.time = saved.time
        self.sleep = shallow_copy(saved.sleep)


class SavedState(NamedTuple):
    """A state as it was (``State.checkpoint``)."""

    body: np.ndarray  # (N, 13)
    poses: tuple[np.ndarray, ...]  # the planes' pose columns, as PLANE_POSE names them
    time: float
    sleep: Sleep


def _put_back(columns: Columns, names: tuple[str, ...], saved: tuple[np.ndarray, ...]) -> None:
    """Write the saved live rows of the columns ``names`` back (in place when there are as many rows,
    else into columns of that many rows)."""
    count = len(saved[0])
    if count != columns.count:
        columns.count = 0
        columns.reserve(count)
    for name, rows in zip(names, saved, strict=True):
        columns.full(name)[:count] = rows


def shallow_copy(obj: object) -> object:
    """A new object of ``obj``'s class with the same attributes (the same arrays, not copies of them):
    a checkpoint of a part whose arrays are replaced, never changed in place. As ``copy.copy`` for
    these plain classes, at a fifth of its cost (a step takes one of each part)."""
    twin = object.__new__(type(obj))
    twin.__dict__.update(obj.__dict__)
    return twin


def with_static(rows: np.ndarray) -> np.ndarray:
    """Per-ball rows with the static world's zero row N appended (planes are body N in the solver)."""
    out = np.empty((len(rows) + 1, rows.shape[1]))  # as np.vstack with a zero row, at a third of its cost
    out[:-1] = rows
    out[-1] = 0.0
    return out
