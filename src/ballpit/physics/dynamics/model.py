"""The model: what a step reads but never changes.

Ball properties (radius, mass, inertia, material), plane shapes and materials, and the world's
parameters (gravity, drag, integrator, solver settings). The state a step advances is in ``state.py``;
together they are everything a World is (NVIDIA warp.sim's Model/State split).
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.settings import (
    CONTACT_SLOP,
    CROWD_LIMIT,
    SLOP_PER_RADIUS,
    SLOWEST_TURN,
    SOLVER_ITERATIONS,
    EnergyGuards,
)
from ..core.state import Columns
from .forces import AngularDrag, ForceTerm, Gravity, LinearDrag
from .integrators import DEFAULT_INTEGRATOR, INTEGRATORS, Integrator

# Moments of inertia of a sphere about a diameter, as a fraction of m·r².
SOLID_INERTIA = 2.0 / 5.0
HOLLOW_INERTIA = 2.0 / 3.0

# Defaults of World.add_sphere/add_spheres/add_plane (the README's Python API); the scene schema
# reads them from those signatures, so this is their one home.
BALL_RADIUS = 0.5  # m
BALL_MASS = 1.0  # kg
BALL_RESTITUTION = 1.0  # so a default ball bouncing off a plane shows exactly the plane's bounciness
PLANE_RESTITUTION = 0.8
FRICTION = 0.5  # balls and planes alike
ROLLING_FRICTION = 0.0


def sphere_columns() -> Columns:
    """Per-ball properties: shape, mass properties and material."""
    f = float
    return Columns(
        {
            "radius": ((), f),
            "mass": ((), f),
            "inv_mass": ((), f),
            "inv_inertia": ((), f),  # spheres are isotropic: I⁻¹ is a scalar times the identity
            "restitution": ((), f),
            "friction": ((), f),
            "rolling_friction": ((), f),
            "hollow": ((), bool),
        }
    )


def plane_columns() -> Columns:
    """Per-plane shape, motion and material: half extents (inf for unbounded), the velocity and angular
    velocity it is moved with (world frame, about its centre), and its material. Its pose is state."""
    f = float
    return Columns(
        {
            "half_size": ((2,), f),
            "velocity": ((3,), f),
            "angular_velocity": ((3,), f),
            "restitution": ((), f),
            "friction": ((), f),
            "rolling_friction": ((), f),
        },
        capacity=4,
    )


class Model:
    """Ball properties, planes and parameters. The World's setters validate what is written here."""

    def __init__(self) -> None:
        self.spheres = sphere_columns()
        self.planes = plane_columns()
        self.gravity = np.array([0.0, -9.81, 0.0])
        self.integrator: Integrator = INTEGRATORS[DEFAULT_INTEGRATOR]
        self.linear_drag = 0.0
        self.angular_drag = 0.0
        self.restitution_threshold: float | None = None
        self.solver_iterations = SOLVER_ITERATIONS
        self.crowd_limit: float = CROWD_LIMIT
        self.sleep = False  # whether still islands fall asleep (sleeping.py)
        self.substeps = 1  # soft substeps of a crowded step (softstep.py)
        self.guards = EnergyGuards()  # which energy guards are on (energy_guard.py): all, but in tests

    def append_spheres(
        self, n: int, *, radius, mass, restitution, friction, rolling_friction, hollow
    ) -> slice:
        """Room for ``n`` more balls with these (validated, broadcastable) properties; their rows."""
        cols = self.spheres
        rows = cols.reserve(n)
        cols.full("radius")[rows] = radius
        cols.full("mass")[rows] = mass
        cols.full("inv_mass")[rows] = 1.0 / np.asarray(mass)
        shape_factor = np.where(hollow, HOLLOW_INERTIA, SOLID_INERTIA)
        cols.full("inv_inertia")[rows] = 1.0 / (shape_factor * np.asarray(mass) * np.asarray(radius) ** 2)
        cols.full("hollow")[rows] = hollow
        cols.full("restitution")[rows] = restitution
        cols.full("friction")[rows] = friction
        cols.full("rolling_friction")[rows] = rolling_friction
        return rows

    def append_plane(self, half_size: tuple[float, float], properties: dict[str, object]) -> int:
        """Room for one more plane with these (validated) half extents, materials and motion; its row."""
        cols = self.planes
        i = cols.reserve(1).start
        cols.full("half_size")[i] = half_size
        for key, value in properties.items():
            cols.full(key)[i] = value
        return i

    def moving_planes(self) -> bool:
        """True when some plane has a velocity or turns (``plane_spin``)."""
        return self._plane_motion()[2]

    def moving_plane_mask(self) -> np.ndarray:
        """Which planes have a velocity or turn (``plane_spin``), one flag per plane (read only)."""
        return self._plane_motion()[3]

    def plane_spin(self) -> np.ndarray:
        """Each plane's angular velocity as the step turns it (P, 3; read only): as written, but zero
        for a plane turning slower than SLOWEST_TURN, whose rate cannot be formed from its squares.
        Every stage of the step reads a plane's spin from here, so such a plane is still in all of them
        alike (one turning in one stage and still in another could be missed by the time of impact)."""
        spin, _, _, _, turned = self._plane_motion()
        return spin if turned is None else turned

    def _plane_motion(self) -> tuple:
        """(angular velocity as written, its bytes with the velocities', moving?, which move, the spin
        with the too-slow planes zeroed or None when none is): read a dozen times a step, so worked
        out again only when a plane's velocity or angular velocity changed (they are compared by
        their bytes, which is cheaper than working them out)."""
        velocity, spin = self.planes.velocity, self.planes.angular_velocity
        key = velocity.tobytes() + spin.tobytes()
        memo = self.__dict__.get("_motion")
        if memo is not None and memo[1] == key:
            return (spin, *memo[1:])
        turned = None
        if np.count_nonzero(spin):
            x, y, z = spin[:, 0], spin[:, 1], spin[:, 2]  # exact.dot_rows' sums, without its call
            still = (x * x + y * y) + z * z < SLOWEST_TURN * SLOWEST_TURN
            if np.count_nonzero(still):
                turned = np.where(still[:, None], 0.0, spin)
                turned.flags.writeable = False
        turning = spin if turned is None else turned
        moving = bool(np.count_nonzero(velocity) or np.count_nonzero(turning))
        mask = velocity.any(axis=1) | turning.any(axis=1) if moving else np.zeros(len(spin), bool)
        mask.flags.writeable = False
        self._motion = (spin, key, moving, mask, turned)
        return self._motion

    def contact_slop(self) -> float:
        """The gap (m) under which a pair is touching in this world, for every stage of the step:
        CONTACT_SLOP, or SLOP_PER_RADIUS of the smallest ball's radius if that is less."""
        radius = self.spheres.radius  # (the smallest by the ufunc's reduce, without ndarray.min's wrapper)
        return (
            min(CONTACT_SLOP, SLOP_PER_RADIUS * float(np.minimum.reduce(radius)))
            if len(radius)
            else CONTACT_SLOP
        )

    def forces(self) -> list[ForceTerm]:
        """The force terms acting on every ball: gravity, then the drags that are switched on."""
        terms: list[ForceTerm] = [Gravity(self.gravity)]
        if self.linear_drag:
            terms.append(LinearDrag(self.linear_drag))
        if self.angular_drag:
            terms.append(AngularDrag(self.angular_drag))
        return terms

    def restitution_threshold_for(self, dt: float) -> float:
        """The restitution threshold for a step of ``dt``: the approach speed (m/s) below which contacts
        do not bounce, ``restitution_threshold`` when it is set.

        Default: the integrator's ``threshold_steps``·|g|·dt (2 for RK2 and RK4: a ball bouncing slower
        than 2·|g|·dt would land again within a step or two; 8 for explicit Euler, see integrators.py).
        """
        if self.restitution_threshold is not None:
            return self.restitution_threshold
        # |g| in Python floats: the same squares summed in the same order, correctly rounded alike
        return self.integrator.threshold_steps * exact.norm_floats(*self.gravity.tolist()) * dt
