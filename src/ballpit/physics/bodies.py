"""Sphere and Plane: live views onto one row of the world's arrays.

A view holds only the world and an index, so it never goes stale when the arrays grow. Reading a
vector gives a view of the row; assigning validates the value and writes it into the world.
``SphereList``/``PlaneList`` are the sequences behind ``world.spheres``/``world.planes``; they also
hand out whole columns (``world.spheres.positions``) for code that works on every ball at once.
"""

from __future__ import annotations

import operator
from collections.abc import Iterator, Sequence
from typing import Protocol, overload

import numpy as np

from .collision import geometry
from .core import exact, steppable, validation
from .core.state import Columns, Q, State, V, W, X
from .dynamics.model import Model


class Viewed(Protocol):
    """What a view reads and writes: a world's model and state (``world.World`` has both). A
    protocol, so this module need not import the facade that imports it."""

    model: Model
    state: State
    _good_balls: steppable.LastGoodBalls


_LIMITS = {
    "position": validation.MAX_COORDINATE,
    "velocity": validation.MAX_SPEED,
    "angular_velocity": validation.MAX_SPIN,
}


def _handed_out(world: Viewed, field: slice) -> np.ndarray:
    """The ball state block, whose ``field`` columns are about to be handed out as a view: a bad value
    written through it is put back as the last step left it (``steppable.LastGoodBalls``)."""
    body = world.state.body
    world._good_balls.expose(body, field)
    return body


def _state_vector(cols: slice, name: str, length: int):
    def get(self: Sphere) -> np.ndarray:
        row = self.row
        return _handed_out(self._world, cols)[row, cols]

    def set(self: Sphere, value: object) -> None:
        if name == "orientation":
            vec = validation.quaternion(name, value)
        else:
            vec = validation.vector(name, value, length, limit=_LIMITS[name])
        self._world.state.body[self.row, cols] = vec

    return property(get, set, doc=f"The ball's {name.replace('_', ' ')} (world frame).")


def _material(name: str, owner: str):
    def get(self) -> float:
        return float(getattr(self._columns, name)[self.row])

    def set(self, value: object) -> None:
        if name == "restitution":
            checked = validation.number(name, value, within=validation.RESTITUTION_RANGE)
        else:
            checked = validation.number(name, value, nonnegative=True)
        getattr(self._columns, name)[self.row] = checked

    return property(get, set, doc=f"The {owner}'s {name.replace('_', ' ')} coefficient.")


def _state_column(cols: slice, doc: str) -> property:
    return property(lambda self: _handed_out(self._world, cols)[:, cols], doc=doc)


def _plane_column(name: str, doc: str, pose: bool = False) -> property:
    def get(self: PlaneList) -> np.ndarray:
        return getattr(self._world.state.planes if pose else self._world.model.planes, name)

    return property(get, doc=doc)


def _plane_motion(name: str, doc: str) -> property:
    def get(self: Plane) -> np.ndarray:
        return getattr(self._columns, name)[self.row]

    def set(self: Plane, value: object) -> None:
        limit = validation.MAX_SPEED if name == "velocity" else validation.MAX_SPIN
        getattr(self._columns, name)[self.row] = validation.vector(name, value, limit=limit)

    return property(get, set, doc=doc)


class _Body:
    """A live view: the world and a row index, nothing else, so it never goes stale."""

    __slots__ = ("_world", "index")
    _kind = _noun = "body"

    def __init__(self, world: Viewed, index: int) -> None:
        self._world = world
        self.index = index

    def _count(self) -> int:
        raise NotImplementedError

    @property
    def row(self) -> int:
        """``index``, once it is checked that the world still has this body: one removed, or a world
        restored to a snapshot taken before the body was added, has not (IndexError, saying so)."""
        n = self._count()
        if self.index >= n:
            noun = self._noun if n == 1 else f"{self._noun}s"
            raise IndexError(
                f"{self._kind} #{self.index} is no longer in the world, which holds {n} {noun}: it was "
                f"removed, or the world restored to a snapshot taken before this {self._noun} was added"
            )
        return self.index


class Sphere(_Body):
    """A ball: a live view of row ``index`` of the world's sphere arrays."""

    __slots__ = ()
    _kind, _noun = "sphere", "ball"

    def _count(self) -> int:
        return self._world.state.count

    @property
    def _columns(self) -> Columns:
        return self._world.model.spheres

    position = _state_vector(X, "position", 3)
    velocity = _state_vector(V, "velocity", 3)
    orientation = _state_vector(Q, "orientation", 4)
    angular_velocity = _state_vector(W, "angular_velocity", 3)
    restitution = _material("restitution", "ball")
    friction = _material("friction", "ball")
    rolling_friction = _material("rolling_friction", "ball")

    @property
    def radius(self) -> float:
        return float(self._columns.radius[self.row])

    @property
    def mass(self) -> float:
        return float(self._columns.mass[self.row])

    @property
    def hollow(self) -> bool:
        return bool(self._columns.hollow[self.row])

    @property
    def inertia(self) -> float:
        """Moment of inertia about any axis through the centre: 2/5·m·r² solid, 2/3·m·r² hollow."""
        return 1.0 / float(self._columns.inv_inertia[self.row])

    def __repr__(self) -> str:
        x, y, z = self.position
        return f"Sphere(index={self.index}, position=({x:.4g}, {y:.4g}, {z:.4g}), radius={self.radius:g})"


class Plane(_Body):
    """A plane or finite rectangle: a live view of row ``index`` of the world's plane arrays."""

    __slots__ = ()
    _kind = _noun = "plane"

    def _count(self) -> int:
        return self._world.model.planes.count

    @property
    def _columns(self) -> Columns:
        return self._world.model.planes

    restitution = _material("restitution", "plane")
    friction = _material("friction", "plane")
    rolling_friction = _material("rolling_friction", "plane")

    @property
    def _pose(self) -> Columns:
        return self._world.state.planes

    velocity = _plane_motion("velocity", "The velocity (m/s, world frame) the plane moves with.")
    angular_velocity = _plane_motion(
        "angular_velocity",
        "The angular velocity (rad/s, world frame) the plane turns with, about its centre.",
    )

    @property
    def position(self) -> np.ndarray:
        """Where the plane's centre is now (a step moves it by its velocity)."""
        return self._pose.center[self.row]

    @property
    def normal(self) -> np.ndarray:
        return self._pose.normal[self.row]

    @property
    def orientation(self) -> np.ndarray:
        """The rotation taking the +y plane to this one, (x, y, z, w)."""
        return self._pose.orientation[self.row]

    @property
    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """The in-plane width (+x turned) and depth (+z turned) directions."""
        i = self.row
        return self._pose.axis_u[i], self._pose.axis_v[i]

    @property
    def size(self) -> tuple[float, float] | None:
        """(width, depth) in metres, or None for an infinite plane."""
        half = self._columns.half_size[self.row]
        if np.isinf(half).all():
            return None
        return float(2 * half[0]), float(2 * half[1])

    @property
    def infinite(self) -> bool:
        return bool(np.isinf(self._columns.half_size[self.row]).all())

    def _frame(self) -> tuple[np.ndarray, ...]:
        pose = self._pose
        i = slice(self.row, self.row + 1)
        return pose.center[i], pose.normal[i], pose.axis_u[i], pose.axis_v[i], self._columns.half_size[i]

    def signed_distance(self, points: object) -> np.ndarray | float:
        """Signed distance of points from the plane's infinite extension, positive on the normal's side."""
        p = np.asarray(points, float)
        d = exact.dot_rows(p - self.position, self.normal)
        return float(d) if p.ndim == 1 else d

    def closest_point(self, points: object) -> np.ndarray:
        """The closest point on the (possibly finite) rectangle to each point."""
        p = np.asarray(points, float)
        flat = p.reshape(-1, 3)
        center, _normal, u, v, half = self._frame()
        zeros = np.zeros(len(flat), dtype=np.intp)
        closest = geometry.closest_point_on_planes(flat, zeros, center, u, v, half)
        return closest.reshape(p.shape)

    def distance(self, points: object) -> np.ndarray | float:
        """Unsigned distance from each point to the rectangle (face, edge or corner)."""
        p = np.asarray(points, float)
        d = np.linalg.norm(p - self.closest_point(p), axis=-1)
        return float(d) if p.ndim == 1 else d

    def __repr__(self) -> str:
        n = self.normal
        return f"Plane(index={self.index}, normal=({n[0]:.3g}, {n[1]:.3g}, {n[2]:.3g}), size={self.size})"


def _read_only(column: np.ndarray) -> np.ndarray:
    """A view of ``column`` that refuses writes: a column others are derived from."""
    view = column.view()
    view.flags.writeable = False
    return view


class _Views(Sequence):
    _view: type

    def __init__(self, world: Viewed) -> None:
        self._world = world

    def _count(self) -> int:
        raise NotImplementedError

    def __len__(self) -> int:
        return self._count()

    @overload
    def __getitem__(self, i: int) -> Sphere | Plane: ...
    @overload
    def __getitem__(self, i: slice) -> list: ...
    def __getitem__(self, i):
        n = self._count()
        if isinstance(i, slice):
            return [self._view(self._world, k) for k in range(n)[i]]
        try:
            k = operator.index(i)  # ints and NumPy integers; 1.5, "0" and True-like floats are refused
        except TypeError:
            raise TypeError(f"indices must be integers or slices, not {type(i).__name__} ({i!r})") from None
        if k < 0:
            k += n
        if not 0 <= k < n:
            raise IndexError(f"index {i} out of range for {n} bodies")
        return self._view(self._world, k)

    def __iter__(self) -> Iterator:
        return (self._view(self._world, k) for k in range(self._count()))


class SphereList(_Views):
    """``world.spheres``: every ball as a view, plus whole columns for vectorised use."""

    _view = Sphere

    def _count(self) -> int:
        return self._world.state.count

    positions = _state_column(X, "Every ball's position (m).")
    velocities = _state_column(V, "Every ball's velocity (m/s).")
    orientations = _state_column(Q, "Every ball's orientation quaternion (x, y, z, w).")
    angular_velocities = _state_column(W, "Every ball's angular velocity (rad/s, world frame).")

    @property
    def radii(self) -> np.ndarray:
        """Every ball's radius, read-only (the inertia and the broad phase derive from it)."""
        return _read_only(self._world.model.spheres.radius)

    @property
    def masses(self) -> np.ndarray:
        """Every ball's mass, read-only (the inverse mass and inertia derive from it)."""
        return _read_only(self._world.model.spheres.mass)


class PlaneList(_Views):
    """``world.planes``: every plane as a view, plus whole columns for vectorised use."""

    _view = Plane

    def _count(self) -> int:
        return self._world.model.planes.count

    centers = _plane_column("center", "Every plane's centre (m), where it is now.", pose=True)
    normals = _plane_column("normal", "Every plane's unit normal.", pose=True)
    orientations = _plane_column(
        "orientation", "Every plane's orientation quaternion (x, y, z, w).", pose=True
    )
    velocities = _plane_column("velocity", "Every plane's velocity (m/s).")
    angular_velocities = _plane_column("angular_velocity", "Every plane's angular velocity (rad/s).")
    half_sizes = _plane_column("half_size", "Every plane's half width and depth (inf: unbounded).")
    restitutions = _plane_column("restitution", "Every plane's restitution.")
