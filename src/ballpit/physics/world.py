"""The World: the facade over the physics. Its parameters, ``add_*``, the live views, and ``step``.

What a World is lives in two objects: ``model`` (what a step reads: ball properties, planes and
parameters; model.py) and ``state`` (what a step advances; state.py). Between steps it also keeps two
caches that change results: the broad phase's kept pairs (pairs.py) and the warm-start forces
(resting.py). ``step`` is a short pipeline of named stages (see ``World.step`` and strategies.py).
"""

from __future__ import annotations

import copy
from time import perf_counter

import numpy as np

from . import (
    collision,
    energy,
    exact,
    moving_planes,
    narrowphase,
    quaternion,
    sleeping,
    strategies,
    validation,
)
from .bodies import Plane, PlaneList, Sphere, SphereList
from .contacts import ContactRecord, EventLog
from .forces import ForceTerm, free_acceleration
from .integrators import INTEGRATORS, Workspace
from .model import (
    BALL_MASS,
    BALL_RADIUS,
    BALL_RESTITUTION,
    FRICTION,
    HOLLOW_INERTIA,
    PLANE_RESTITUTION,
    ROLLING_FRICTION,
    SOLID_INERTIA,
    Model,
)
from .pairs import PairCache
from .profile import StepProfile
from .resting import WarmStart
from .snapshot import Snapshot
from .state import Q, State, V, W, X


def _index(kind: str, index: object, count: int) -> int:
    """``index`` checked as the index of one of ``count`` balls or planes (TypeError/ValueError naming it)."""
    if isinstance(index, bool) or not isinstance(index, int | np.integer):
        raise TypeError(f"index must be a {kind}'s index, got {index!r}")
    if not 0 <= index < count:
        raise ValueError(f"index must be a {kind}'s index from 0 to {count - 1}, got {index}")
    return int(index)


def _model_number(name: str, doc: str, **checks: bool) -> property:
    """A World parameter stored in the model, validated on the way in."""

    def get(self: World) -> float:
        return getattr(self.model, name)

    def set(self: World, value: float) -> None:
        setattr(self.model, name, validation.number(name, value, **checks))

    return property(get, set, doc=doc)


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
        sleep: bool = False,
        substeps: int = 1,
    ) -> None:
        self.model = Model()
        self.state = State()
        self.gravity = gravity
        self.integrator = integrator
        self.linear_drag = linear_drag
        self.angular_drag = angular_drag
        self.restitution_threshold = restitution_threshold
        self.sleep = sleep
        self.substeps = substeps
        self.crowded_steps = 0  # how many steps were taken as soft substeps (crowded)
        self.profile = StepProfile()  # the last step's time per stage (profile.py)
        self._pairs = PairCache()
        self._warm = WarmStart()
        self._workspace = Workspace()
        self._good_planes: validation.PlanesAsStepped | None = None  # the plane columns after the last step
        self._good_balls = validation.LastGoodBalls()  # the ball states, once views hand them out

    # ------------------------------------------------------------------ parameters
    @property
    def time(self) -> float:
        """Simulated time (s); ``step`` advances it."""
        return self.state.time

    @time.setter
    def time(self, value: float) -> None:
        self.state.time = validation.number("time", value)

    @property
    def gravity(self) -> np.ndarray:
        """Gravity (m/s²), read-only: assign a whole vector to change it (each component at most
        ``validation.MAX_GRAVITY``, 1e9 m/s², in size)."""
        view = self.model.gravity.view()
        view.flags.writeable = False
        return view

    @gravity.setter
    def gravity(self, value: object) -> None:
        self.model.gravity = validation.vector("gravity", value, limit=validation.MAX_GRAVITY)

    @property
    def integrator(self) -> str:
        """One of ``INTEGRATOR_NAMES`` ("euler", "rk2", "rk4", "symplectic"); may be changed between steps."""
        return self.model.integrator.name

    @integrator.setter
    def integrator(self, value: str) -> None:
        if not isinstance(value, str) or value.lower() not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {value!r}")
        self.model.integrator = INTEGRATORS[value.lower()]

    linear_drag = _model_number("linear_drag", "Linear drag c (1/s): acceleration −c·v.", nonnegative=True)
    angular_drag = _model_number(
        "angular_drag", "Angular drag c_ω (1/s): angular acceleration −c_ω·ω.", nonnegative=True
    )

    @property
    def solver_iterations(self) -> int:
        """Projected Gauss–Seidel sweeps per contact solve (at least 1)."""
        return self.model.solver_iterations

    @solver_iterations.setter
    def solver_iterations(self, value: int) -> None:
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
            raise ValueError(f"solver_iterations must be a whole number of at least 1, got {value!r}")
        self.model.solver_iterations = int(value)

    @property
    def substeps(self) -> int:
        """Soft substeps per crowded step (Box2D v3's soft step, softstep.py): a crowded step's contacts
        are solved this many times, each over dt / substeps. The split-at-impacts path ignores it."""
        return self.model.substeps

    @substeps.setter
    def substeps(self, value: int) -> None:
        self.model.substeps = validation.whole_number("substeps", value, 1, validation.MAX_SUBSTEPS)

    crowd_limit = _model_number(
        "crowd_limit",
        "A step in which more pairs than this may meet is taken whole, with speculative contacts "
        "(inf: always split the step at each impact; 0: take every step with an impact whole). "
        "Among 256 kept pairs or more (a pile) any meeting does, unless this is inf.",
        nonnegative=True,
        infinite=True,
    )

    @property
    def restitution_threshold(self) -> float | None:
        """Approach speed (m/s) below which contacts do not bounce; None picks one from g and dt."""
        return self.model.restitution_threshold

    @restitution_threshold.setter
    def restitution_threshold(self, value: float | None) -> None:
        if value is not None:
            value = validation.number("restitution_threshold", value, nonnegative=True)
        self.model.restitution_threshold = value

    @property
    def sleep(self) -> bool:
        """Whether balls that have stayed still together for half a second fall asleep (cost nothing,
        move not at all) until something reaches them (sleeping.py). Off by default."""
        return self.model.sleep

    @sleep.setter
    def sleep(self, value: bool) -> None:
        if not isinstance(value, bool | np.bool_):
            raise TypeError(f"sleep must be true or false, got {value!r}")
        self.model.sleep = bool(value)

    @property
    def asleep(self) -> np.ndarray:
        """Which balls are asleep now (a read-only copy, one flag per ball)."""
        sleep = self.state.sleep
        sleep.fit(self.model.spheres.count)
        flags = sleep.asleep.copy()
        flags.flags.writeable = False
        return flags

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
        radius: float = BALL_RADIUS,
        mass: float = BALL_MASS,
        velocity: object = (0.0, 0.0, 0.0),
        angular_velocity: object = (0.0, 0.0, 0.0),
        orientation: object = (0.0, 0.0, 0.0, 1.0),
        restitution: float = BALL_RESTITUTION,
        friction: float = FRICTION,
        rolling_friction: float = ROLLING_FRICTION,
        hollow: bool = False,
    ) -> Sphere:
        """Add one ball and return its live view."""
        row = validation.ball(position, radius, mass, velocity, angular_velocity, orientation, restitution,
                              friction, rolling_friction, hollow)  # fmt: skip
        return Sphere(self, self._append_spheres(1, **row))

    def add_spheres(
        self,
        positions: object,
        radius: object = BALL_RADIUS,
        mass: object = BALL_MASS,
        velocity: object = (0.0, 0.0, 0.0),
        angular_velocity: object = (0.0, 0.0, 0.0),
        orientation: object = (0.0, 0.0, 0.0, 1.0),
        restitution: object = BALL_RESTITUTION,
        friction: object = FRICTION,
        rolling_friction: object = ROLLING_FRICTION,
        hollow: object = False,
    ) -> np.ndarray:
        """Add many balls at once; every argument broadcasts against ``positions`` (N, 3).

        Returns the new balls' indices.
        """
        rows = validation.balls(positions, radius, mass, velocity, angular_velocity, orientation, restitution,
                                friction, rolling_friction, hollow)  # fmt: skip
        n = len(rows["position"])
        first = self._append_spheres(n, **rows)
        return np.arange(first, first + n)

    def _append_spheres(self, n: int, *, position, velocity, angular_velocity, orientation,
                        **properties) -> int:  # fmt: skip
        rows = self.model.append_spheres(n, **properties)
        body = self.state.reserve(n)
        body[:, X] = position
        body[:, V] = velocity
        body[:, Q] = orientation
        body[:, W] = angular_velocity
        self._good_balls.grow(self.state.body)
        return rows.start

    def add_plane(
        self,
        position: object = (0.0, 0.0, 0.0),
        normal: object = None,
        rotation: object = None,
        size: object = None,
        restitution: float = PLANE_RESTITUTION,
        friction: float = FRICTION,
        rolling_friction: float = ROLLING_FRICTION,
        velocity: object = (0.0, 0.0, 0.0),
        angular_velocity: object = (0.0, 0.0, 0.0),
    ) -> Plane:
        """Add a plane: infinite (``size=None``), square (a side) or rectangular ((width, depth)).

        Orient it with ``rotation`` (extrinsic x, y, z Euler angles in degrees, turning the +y plane) or
        with ``normal`` (the shortest turn from +y), not both; with neither its normal is +y.

        A plane is kinematic: ``velocity`` (m/s) and ``angular_velocity`` (rad/s, world frame, about
        its centre) move it during each step, and no ball pushes it.
        """
        center, q, (width, depth), mat, motion = validation.plane(
            position,
            normal,
            rotation,
            size,
            restitution,
            friction,
            rolling_friction,
            velocity,
            angular_velocity,
        )
        shape = self.model.planes
        i = shape.reserve(1).start
        shape.full("half_size")[i] = (0.5 * width, 0.5 * depth)
        for key, value in {**mat, **motion}.items():
            shape.full(key)[i] = value
        pose = self.state.planes
        pose.reserve(1)
        pose.full("center")[i] = center
        moving_planes.set_orientation(pose, i, q)
        if self._good_planes is None:
            self._remember_planes()
        else:
            self._good_planes.add(shape, pose)
        return Plane(self, i)

    # ------------------------------------------------------------------ edits between steps
    def set_sphere_size(self, index: int, radius: float | None = None, mass: float | None = None) -> None:
        """Give ball ``index`` a new ``radius`` and/or ``mass``; its inverse mass and inertia follow
        (2/5·m·r² solid, 2/3·m·r² hollow). Both are checked before either is written."""
        i = self._ball_index(index)
        cols = self.model.spheres
        r = cols.radius[i] if radius is None else validation.number("radius", radius, positive=True)
        m = cols.mass[i] if mass is None else validation.number("mass", mass, positive=True)
        cols.radius[i], cols.mass[i] = r, m
        cols.inv_mass[i] = 1.0 / m
        shape_factor = HOLLOW_INERTIA if cols.hollow[i] else SOLID_INERTIA
        cols.inv_inertia[i] = 1.0 / (shape_factor * m * r * r)
        self._edited()

    def remove_sphere(self, index: int) -> None:
        """Remove ball ``index``; the balls after it move down one index."""
        i = self._ball_index(index)
        self.model.spheres.remove(i)
        self.state.remove(i)
        self._edited()

    def move_plane(self, index: int, position: object = None, rotation: object = None) -> None:
        """Put plane ``index``'s centre at ``position`` and/or turn it to ``rotation`` (extrinsic x, y, z
        degrees from the +y plane, as ``add_plane``). Both are checked before either is written."""
        index = _index("plane", index, self.model.planes.count)
        pose = self.state.planes
        limit = validation.MAX_COORDINATE
        center = None if position is None else validation.vector("position", position, limit=limit)
        q = None if rotation is None else quaternion.from_euler_xyz(validation.vector("rotation", rotation))
        if center is not None:
            pose.center[index] = center
        if q is not None:
            moving_planes.set_orientation(pose, index, q)
        self._remember_planes()
        self._edited()

    def _ball_index(self, index: object) -> int:
        return _index("ball", index, self.state.count)

    def first_overlap(self, position: object, radius: float) -> str | None:
        """What a ball of ``radius`` at ``position`` would overlap ("ball 3", "plane 0"), or None: the
        check a ball added by hand should pass (``add_sphere`` itself allows overlaps, which the step
        pushes apart)."""
        p = validation.vector("position", position, limit=validation.MAX_COORDINATE)
        r = validation.number("radius", radius, positive=True)
        balls = self.state.body[:, X] - p
        reach = self.model.spheres.radius + r
        hit = np.flatnonzero(exact.dot(balls, balls) < reach * reach)
        if hit.size:
            return f"ball {hit[0]}"
        pose, shape = self.state.planes, self.model.planes
        k = np.arange(shape.count)
        points = np.broadcast_to(p, (shape.count, 3))
        near = collision.closest_point_on_planes(
            points, k, pose.center, pose.axis_u, pose.axis_v, shape.half_size
        )
        gap = near - points
        hit = np.flatnonzero(exact.dot(gap, gap) < r * r)
        return f"plane {hit[0]}" if hit.size else None

    def _edited(self) -> None:
        """Something a step reads was changed by hand: the kept pairs and warm start are found afresh,
        and sleeping balls wake; the copies a bad value in a ball view is put back from are dropped (a
        removed ball moves the rows after it)."""
        self._pairs = PairCache()
        self._warm = WarmStart()
        self.state.sleep.wake_all()
        self._good_balls.forget()

    def _remember_planes(self) -> None:
        """Copy the plane columns, to put back a bad value written into them before the next step."""
        self._good_planes = validation.planes_as_stepped(self.model.planes, self.state.planes)

    # ------------------------------------------------------------------ stepping
    def forces(self) -> list[ForceTerm]:
        """The force terms acting on every ball: gravity, then the drags that are switched on."""
        return self.model.forces()

    def step(self, dt: float) -> ContactRecord:
        """Advance the world by ``dt`` seconds; returns the contacts resolved in the step.

        Stages: waking what was changed by hand (sleeping.py), the kept pairs (found again only when
        a path leaves its box), the narrow phase, waking the islands awake balls reach, the crowd
        test, then one of the two strategies (strategies.py): split the step at every impact, or take
        a crowded step as soft substeps (softstep.py); last, still islands fall asleep. ``profile``
        then holds the step's time per stage.
        """
        dt = validation.timestep(dt)
        began = perf_counter()
        model, state = self.model, self.state
        validation.reject_unsteppable_state(state.body, self._good_balls)
        planes = validation.reject_bad_planes(model.planes, state.planes, self._good_planes)
        before = state.body.copy()
        step = strategies.Step(model, state, self._pairs, self._warm, self._workspace, model.forces(), dt,
                               model.restitution_threshold_for(dt), EventLog(), StepProfile(),
                               before=before)  # fmt: skip
        prof = step.profile
        with prof.stage("sleep"):
            sleep = state.sleep
            sleeping.before_step(model, state, sleep, model.sleep)
        free, ang, unheld = self._free_acceleration(step)
        with prof.stage("pairs"):
            pairs = self._pairs.for_step(model, state, free, dt)
        with prof.stage("narrow phase"):
            contacts = narrowphase.contact_points(model, state, pairs)
        # Pairs within reach (sleeping balls counted as falling, as they will once awake) join islands;
        # reaching a sleeping ball wakes its island. Needed only while some ball sleeps or may fall
        # asleep at the end of this step.
        reach = None
        if model.sleep and (sleep.any or sleeping.may_fall_asleep(sleep, dt)):
            with prof.stage("sleep"):
                reach = strategies.speculative_reach(step, contacts, unheld)
                woken = sleeping.reached(contacts, sleep.asleep, reach) if sleep.any else None
            if woken is not None and woken.any():
                sleep.wake(woken)
                free, ang, unheld = self._free_acceleration(step)
                with prof.stage("pairs"):
                    pairs = self._pairs.for_step(model, state, free, dt)
                with prof.stage("narrow phase"):
                    contacts = narrowphase.contact_points(model, state, pairs)
                with prof.stage("sleep"):
                    reach = strategies.speculative_reach(step, contacts, unheld)
        if model.sleep and len(self._warm.asleep[0]):
            with prof.stage("sleep"):
                self._warm.wake(sleep.asleep)  # the pairs of woken islands start from what they held
        with prof.stage("crowd test"):
            crowd = strategies.crowded(step, contacts, free)
        if crowd and strategies.crowded_step(step, contacts, (free, ang)):
            self.crowded_steps += 1
        else:
            if contacts.normal is None:  # a soft frame tried and undone let go of them: the same again
                with prof.stage("narrow phase"):
                    contacts = narrowphase.contact_points(model, state, pairs)
            strategies.split_at_impacts(step, contacts, pairs, (free, ang))
        if model.sleep:
            with prof.stage("sleep"):
                was = sleep.asleep.copy() if sleep.any or sleeping.may_fall_asleep(sleep, dt) else None
                sleeping.after_step(model, state, sleep, contacts, reach, dt)
                if was is not None and (sleep.asleep & ~was).any():
                    self._warm.put_to_sleep(sleep.asleep)
        validation.undo_non_finite_step(state.body, before)
        if model.moving_planes():  # else the step left them as they were checked
            self._remember_planes()
        else:
            self._good_planes = planes
        state.time += dt
        record = step.events.record()
        prof.intervals, prof.pairs, prof.contacts = step.intervals, len(pairs), len(record)
        prof.crowded = crowd
        prof.total = perf_counter() - began
        self.profile = prof
        return record

    def _free_acceleration(self, step: strategies.Step) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The free linear and angular accelerations at the step's start, and the linear ones had no
        ball been asleep. While some sleep, the step's force terms get one more that holds them
        (``step.forces`` changes)."""
        step.forces = self.model.forces()
        sleep = self.state.sleep
        self._pairs.awake = ~sleep.asleep if sleep.any else None
        free, ang = free_acceleration(self.state.body, step.forces)
        if not sleep.any:
            return free, ang, free
        held = sleeping.hold(sleep, (free, ang))
        step.forces.append(held)
        return free + held.lin, ang + held.ang, free

    # ------------------------------------------------------------------ snapshots
    def snapshot(self) -> Snapshot:
        """A deep copy of everything ``step`` reads or writes: the model (balls, planes, parameters),
        the state (ball states, time) and the caches that change results (kept pairs, warm start)."""
        parts = copy.deepcopy((self.model, self.state, self._pairs, self._warm))
        return Snapshot(*parts, crowded_steps=self.crowded_steps)

    def restore(self, snap: Snapshot) -> None:
        """Put the world back as it was at ``snap``; stepping on repeats the original run bit for bit.

        The snapshot stays usable: it can be restored again. Live views of balls that did not exist
        then raise IndexError, saying so, when used.
        """
        if not isinstance(snap, Snapshot):
            raise TypeError(f"restore takes a Snapshot from World.snapshot(), got {type(snap).__name__}")
        self.model, self.state, self._pairs, self._warm = copy.deepcopy(
            (snap.model, snap.state, snap.pairs, snap.warm)
        )
        self.crowded_steps = snap.crowded_steps
        self._remember_planes()
        self._good_balls = validation.LastGoodBalls()

    def copy(self) -> World:
        """An independent World in the same state (it steps on exactly as this one would)."""
        twin = World.__new__(World)
        twin.profile = StepProfile()
        twin._workspace = Workspace()
        twin.restore(self.snapshot())
        return twin

    # ------------------------------------------------------------------ measures
    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of all balls (J)."""
        return energy.kinetic(self.model, self.state)

    def potential_energy(self) -> float:
        """Gravitational potential energy −Σ m·g·x (J), zero at the origin."""
        return energy.potential(self.model, self.state)
