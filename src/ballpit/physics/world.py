"""The World: ball and plane arrays plus the step pipeline that advances them."""

from __future__ import annotations

import numpy as np

from . import quaternion, validation
from .bodies import Plane, PlaneList, Sphere, SphereList
from .contacts import Contacts
from .forces import AngularDrag, ForceTerm, Gravity, LinearDrag
from .integrators import INTEGRATORS, Integrator, Workspace, integrate
from .state import Q, V, W, X, plane_columns, sphere_columns

# Moments of inertia of a sphere about a diameter, as a fraction of m·r².
SOLID_INERTIA = 2.0 / 5.0
HOLLOW_INERTIA = 2.0 / 3.0


class World:
    """Balls and planes under gravity and drag, advanced by ``step``.

    State is kept as structure-of-arrays; ``spheres`` and ``planes`` are sequences of live views.
    """

    def __init__(
        self,
        gravity: object = (0.0, -9.81, 0.0),
        integrator: str = "rk4",
        linear_drag: float = 0.0,
        angular_drag: float = 0.0,
        restitution_threshold: float | None = None,
    ) -> None:
        self.gravity = gravity
        self.integrator = integrator
        self.linear_drag = linear_drag
        self.angular_drag = angular_drag
        self.restitution_threshold = restitution_threshold
        self.time = 0.0
        self._spheres = sphere_columns()
        self._planes = plane_columns()
        self._workspace = Workspace()

    # ------------------------------------------------------------------ parameters
    @property
    def gravity(self) -> np.ndarray:
        return self._gravity

    @gravity.setter
    def gravity(self, value: object) -> None:
        self._gravity = validation.vector("gravity", value)

    @property
    def integrator(self) -> str:
        """ "euler", "rk2" or "rk4"; may be changed between steps."""
        return self._integrator.name

    @integrator.setter
    def integrator(self, value: str) -> None:
        if not isinstance(value, str) or value.lower() not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {value!r}")
        self._integrator: Integrator = INTEGRATORS[value.lower()]

    @property
    def linear_drag(self) -> float:
        return self._linear_drag

    @linear_drag.setter
    def linear_drag(self, value: float) -> None:
        self._linear_drag = validation.number("linear_drag", value, nonnegative=True)

    @property
    def angular_drag(self) -> float:
        return self._angular_drag

    @angular_drag.setter
    def angular_drag(self, value: float) -> None:
        self._angular_drag = validation.number("angular_drag", value, nonnegative=True)

    @property
    def restitution_threshold(self) -> float | None:
        """Approach speed (m/s) below which contacts do not bounce; None picks one from g and dt."""
        return self._restitution_threshold

    @restitution_threshold.setter
    def restitution_threshold(self, value: float | None) -> None:
        if value is not None:
            value = validation.number("restitution_threshold", value, nonnegative=True)
        self._restitution_threshold = value

    # ------------------------------------------------------------------ bodies
    @property
    def spheres(self) -> SphereList:
        return SphereList(self)

    @property
    def planes(self) -> PlaneList:
        return PlaneList(self)

    def add_sphere(
        self,
        position: object = (0.0, 0.0, 0.0),
        radius: float = 0.5,
        mass: float = 1.0,
        velocity: object = (0.0, 0.0, 0.0),
        angular_velocity: object = (0.0, 0.0, 0.0),
        orientation: object = (0.0, 0.0, 0.0, 1.0),
        restitution: float = 1.0,
        friction: float = 0.5,
        rolling_friction: float = 0.0,
        hollow: bool = False,
    ) -> Sphere:
        """Add one ball and return its live view."""
        row = dict(
            position=validation.vector("position", position),
            velocity=validation.vector("velocity", velocity),
            angular_velocity=validation.vector("angular_velocity", angular_velocity),
            orientation=validation.quaternion("orientation", orientation),
            radius=validation.number("radius", radius, positive=True),
            mass=validation.number("mass", mass, positive=True),
            restitution=validation.number("restitution", restitution, nonnegative=True),
            friction=validation.number("friction", friction, nonnegative=True),
            rolling_friction=validation.number("rolling_friction", rolling_friction, nonnegative=True),
        )
        if not isinstance(hollow, bool | np.bool_):
            raise TypeError(f"hollow must be True or False, got {hollow!r}")
        first = self._append_spheres(1, hollow=bool(hollow), **row)
        return Sphere(self, first)

    def add_spheres(
        self,
        positions: object,
        radius: object = 0.5,
        mass: object = 1.0,
        velocity: object = (0.0, 0.0, 0.0),
        angular_velocity: object = (0.0, 0.0, 0.0),
        orientation: object = (0.0, 0.0, 0.0, 1.0),
        restitution: object = 1.0,
        friction: object = 0.5,
        rolling_friction: object = 0.0,
        hollow: object = False,
    ) -> np.ndarray:
        """Add many balls at once; every argument broadcasts against ``positions`` (N, 3).

        Returns the new balls' indices.
        """
        pos = np.asarray(positions, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 3:
            raise ValueError(f"positions must have shape (N, 3), got shape {pos.shape}")
        n = len(pos)
        rows = dict(
            position=validation.array_of("positions", pos, n, 3),
            velocity=validation.array_of("velocity", velocity, n, 3),
            angular_velocity=validation.array_of("angular_velocity", angular_velocity, n, 3),
            orientation=validation.array_of("orientation", orientation, n, 4),
            radius=validation.array_of("radius", radius, n, None),
            mass=validation.array_of("mass", mass, n, None),
            restitution=validation.array_of("restitution", restitution, n, None),
            friction=validation.array_of("friction", friction, n, None),
            rolling_friction=validation.array_of("rolling_friction", rolling_friction, n, None),
        )
        for key in ("radius", "mass"):
            if np.any(rows[key] <= 0):
                raise ValueError(f"{key} must be positive, got {rows[key][rows[key] <= 0][0]!r}")
        for key in ("restitution", "friction", "rolling_friction"):
            if np.any(rows[key] < 0):
                raise ValueError(f"{key} must not be negative, got {rows[key][rows[key] < 0][0]!r}")
        qnorm = np.linalg.norm(rows["orientation"], axis=1)
        if np.any(qnorm < 1e-12):
            raise ValueError("orientation must not be a zero quaternion")
        rows["orientation"] = rows["orientation"] / qnorm[:, None]
        hollow_arr = np.broadcast_to(np.asarray(hollow, dtype=bool), (n,))
        first = self._append_spheres(n, hollow=hollow_arr, **rows)
        return np.arange(first, first + n)

    def _append_spheres(self, n: int, *, position, velocity, angular_velocity, orientation, radius, mass,
                        restitution, friction, rolling_friction, hollow) -> int:  # fmt: skip
        cols = self._spheres
        rows = cols.reserve(n)
        state = cols.full("state")[rows]
        state[:, X] = position
        state[:, V] = velocity
        state[:, Q] = orientation
        state[:, W] = angular_velocity
        cols.full("radius")[rows] = radius
        cols.full("mass")[rows] = mass
        cols.full("inv_mass")[rows] = 1.0 / np.asarray(mass)
        shape_factor = np.where(hollow, HOLLOW_INERTIA, SOLID_INERTIA)
        cols.full("inv_inertia")[rows] = 1.0 / (shape_factor * np.asarray(mass) * np.asarray(radius) ** 2)
        cols.full("hollow")[rows] = hollow
        cols.full("restitution")[rows] = restitution
        cols.full("friction")[rows] = friction
        cols.full("rolling_friction")[rows] = rolling_friction
        return rows.start

    def add_plane(
        self,
        position: object = (0.0, 0.0, 0.0),
        normal: object = None,
        rotation: object = None,
        size: object = None,
        restitution: float = 0.8,
        friction: float = 0.5,
        rolling_friction: float = 0.0,
    ) -> Plane:
        """Add a static plane: infinite (``size=None``), square (a side) or rectangular ((width, depth)).

        Orient it with ``rotation`` (extrinsic x, y, z Euler angles in degrees, turning the +y plane) or
        with ``normal`` (the shortest turn from +y), not both; with neither its normal is +y.
        """
        center = validation.vector("position", position)
        if normal is not None and rotation is not None:
            raise ValueError(
                f"give a plane's normal or its rotation, not both (normal={normal!r}, rotation={rotation!r})"
            )
        if rotation is not None:
            q = quaternion.from_euler_xyz(validation.vector("rotation", rotation))
        elif normal is not None:
            q = quaternion.from_up_to(validation.unit_vector("normal", normal))
        else:
            q = quaternion.IDENTITY.copy()
        width, depth = (np.inf, np.inf) if size is None else validation.size("size", size)
        mat = {
            "restitution": validation.number("restitution", restitution, nonnegative=True),
            "friction": validation.number("friction", friction, nonnegative=True),
            "rolling_friction": validation.number("rolling_friction", rolling_friction, nonnegative=True),
        }
        cols = self._planes
        i = cols.reserve(1).start
        axes = quaternion.rotate(q, np.eye(3))  # rows: the plane's x, y (normal) and z axes
        cols.full("center")[i] = center
        cols.full("orientation")[i] = q
        cols.full("axis_u")[i] = axes[0]
        cols.full("normal")[i] = axes[1] / np.linalg.norm(axes[1])
        cols.full("axis_v")[i] = axes[2]
        cols.full("half_size")[i] = (0.5 * width, 0.5 * depth)
        for key, value in mat.items():
            cols.full(key)[i] = value
        return Plane(self, i)

    # ------------------------------------------------------------------ stepping
    def forces(self) -> list[ForceTerm]:
        """The force terms acting on every ball: gravity, then the drags that are switched on."""
        terms: list[ForceTerm] = [Gravity(self._gravity)]
        if self._linear_drag:
            terms.append(LinearDrag(self._linear_drag))
        if self._angular_drag:
            terms.append(AngularDrag(self._angular_drag))
        return terms

    def step(self, dt: float) -> Contacts:
        """Advance the world by ``dt`` seconds; returns the contacts resolved in the step."""
        dt = validation.number("dt", dt, positive=True)
        state = self._spheres.state
        before = state.copy()
        integrate(self._integrator, state, self.forces(), dt, self._workspace)
        contacts = Contacts.empty()
        self._reject_non_finite(before)
        self.time += dt
        return contacts

    def _reject_non_finite(self, before: np.ndarray) -> None:
        """Keep the world free of NaN/inf: restore the state and raise if a step produced any."""
        state = self._spheres.state
        if not np.isfinite(state).all():
            bad = int(np.flatnonzero(~np.isfinite(state).all(axis=1))[0])
            state[:] = before
            raise FloatingPointError(f"step made sphere #{bad}'s state non-finite; the step was undone")
