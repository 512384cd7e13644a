"""The World: the facade over the physics. Its parameters, ``add_*``, the live views, and ``step``.

A World is its ``model`` (what a step reads: balls, planes, parameters; dynamics/model.py) and its
``parts`` (what a step changes; step/checkpoint.py): the ``state`` and the two caches that change
results, the kept pairs (collision/pairs.py) and the warm start (contact/warm_start.py). ``step`` runs
the typed stages of step/, one a line.
"""

from __future__ import annotations

import copy

import numpy as np

from . import edits, energy
from . import step as pipeline
from .bodies import Plane, PlaneList, Sphere, SphereList
from .core import steppable, validation
from .core.contacts import ContactRecord
from .core.profile import StepProfile
from .core.state import Q, State, V, W, X
from .dynamics import moving_planes
from .dynamics.forces import ForceTerm
from .dynamics.integrators import Workspace
from .dynamics.model import (
    BALL_MASS,
    BALL_RADIUS,
    BALL_RESTITUTION,
    FRICTION,
    PLANE_RESTITUTION,
    ROLLING_FRICTION,
    Model,
)
from .dynamics.parameters import Count, Flag, Integrator, Number, Vector
from .snapshot import Snapshot
from .step.checkpoint import Checkpoint, Parts


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
        self.parts = Parts.new()  # what a step changes: the state and the caches that change results
        self.gravity = gravity
        self.integrator = integrator
        self.linear_drag = linear_drag
        self.angular_drag = angular_drag
        self.restitution_threshold = restitution_threshold
        self.sleep = sleep
        self.substeps = substeps
        self.crowded_steps = 0  # how many steps were taken as soft substeps (crowded)
        self.profile = StepProfile()  # the last step's time per stage (profile.py)
        self._workspace = Workspace()
        self._good_planes: steppable.PlanesAsStepped | None = None  # the plane columns after the last step
        self._good_balls = steppable.LastGoodBalls()  # the ball states, once views hand them out

    # ------------------------------------------------------------------ parameters
    @property
    def state(self) -> State:
        """What a step advances: the balls' (N, 13) block, the planes' poses, the time, sleep."""
        return self.parts.state

    @property
    def time(self) -> float:
        """Simulated time (s); ``step`` advances it."""
        return self.state.time

    @time.setter
    def time(self, value: float) -> None:
        self.state.time = validation.number("time", value)

    gravity = Vector(
        "Gravity (m/s²), read-only: assign a whole vector to change it (each component at most "
        "``validation.MAX_GRAVITY``, 1e9 m/s², in size).",
        limit=validation.MAX_GRAVITY,
    )
    integrator = Integrator(
        'One of ``INTEGRATOR_NAMES`` ("euler", "rk2", "rk4", "symplectic"); may be changed between steps.'
    )
    linear_drag = Number("Linear drag c (1/s): acceleration −c·v.", nonnegative=True)
    angular_drag = Number("Angular drag c_ω (1/s): angular acceleration −c_ω·ω.", nonnegative=True)
    solver_iterations = Count("Projected Gauss–Seidel sweeps per contact solve (at least 1).")
    substeps = Count(
        "Soft substeps per crowded step (Box2D v3's soft step, softstep.py): a crowded step's contacts "
        "are solved this many times, each over dt / substeps. The split-at-impacts path ignores it.",
        most=validation.MAX_SUBSTEPS,
    )
    crowd_limit = Number(
        "A step in which more pairs than this may meet is taken whole, with speculative contacts "
        "(inf: always split the step at each impact; 0: take every step with an impact whole). "
        "Among 256 kept pairs or more (a pile) any meeting does, unless this is inf.",
        nonnegative=True,
        infinite=True,
    )
    restitution_threshold = Number(
        "Approach speed (m/s) below which contacts do not bounce; None picks one from g and dt.",
        optional=True,
        nonnegative=True,
    )
    sleep = Flag(
        "Whether balls that have stayed still together for half a second fall asleep (cost nothing, "
        "move not at all) until something reaches them (dynamics/sleeping.py). Off by default."
    )

    @property
    def asleep(self) -> np.ndarray:
        """Which balls are asleep now (a read-only copy, one flag per ball)."""
        self.state.sleep.fit(self.model.spheres.count)
        flags = self.state.sleep.asleep.copy()
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
        row = validation.ball(
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
        )
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
        rows = validation.balls(
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
        )
        n = len(rows["position"])
        first = self._append_spheres(n, **rows)
        return np.arange(first, first + n)

    def _append_spheres(
        self, n: int, *, position, velocity, angular_velocity, orientation, **properties
    ) -> int:
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
        i = self.model.append_plane((0.5 * width, 0.5 * depth), {**mat, **motion})
        moving_planes.place(self.state.planes, i, center, q)
        if self._good_planes is None:
            self._remember_planes()
        else:
            self._good_planes.add(self.model.planes, self.state.planes)
        return Plane(self, i)

    # ------------------------------------------------------------------ edits between steps (edits.py)
    def set_sphere_size(self, index: int, radius: float | None = None, mass: float | None = None) -> None:
        """Give ball ``index`` a new ``radius`` and/or ``mass``; its inverse mass and inertia follow
        (2/5·m·r² solid, 2/3·m·r² hollow). Both are checked before either is written."""
        edits.set_sphere_size(self.model, self.parts, index, radius, mass)
        self._good_balls.forget()

    def remove_sphere(self, index: int) -> None:
        """Remove ball ``index``; the balls after it move down one index."""
        edits.remove_sphere(self.model, self.parts, index)
        self._good_balls.forget()  # a removed ball moves the rows after it

    def move_plane(self, index: int, position: object = None, rotation: object = None) -> None:
        """Put plane ``index``'s centre at ``position`` and/or turn it to ``rotation`` (extrinsic x, y, z
        degrees from the +y plane, as ``add_plane``). Both are checked before either is written."""
        edits.move_plane(self.model, self.parts, index, position, rotation)
        self._remember_planes()
        self._good_balls.forget()

    def first_overlap(self, position: object, radius: float) -> str | None:
        """What a ball of ``radius`` at ``position`` would overlap ("ball 3", "plane 0"), or None: the
        check a ball added by hand should pass (``add_sphere`` itself allows overlaps, which the step
        pushes apart)."""
        return edits.first_overlap(self.model, self.state, position, radius)

    def _remember_planes(self) -> None:
        """Copy the plane columns, to put back a bad value written into them before the next step."""
        self._good_planes = steppable.planes_as_stepped(self.model.planes, self.state.planes)

    # ------------------------------------------------------------------ stepping
    def forces(self) -> list[ForceTerm]:
        """The force terms acting on every ball: gravity, then the drags that are switched on."""
        return self.model.forces()

    def step(self, dt: float) -> ContactRecord:
        """Advance the world by ``dt`` seconds; returns the contacts resolved in the step.

        The stages, as docs/architecture.md draws them (step/): refuse what cannot be stepped; all
        asleep, only the time moves; wake what was moved, collide, wake what the awake balls reach and
        collide again; the crowd test plans the step; take it as a soft frame (retried with more
        substeps) or split at every impact, again if it struck a sleeping ball; still islands fall
        asleep; undo a step that made anything non-finite. ``profile`` holds its time per stage."""
        step = pipeline.prepare(
            self.model, self.parts, self._workspace, dt, self._good_planes, self._good_balls
        )
        if pipeline.at_rest(step):  # all asleep: nothing but the time moves
            record = pipeline.rest(step)
            self._after_step(step, pipeline.Strategy.SPLIT)
            return record
        taken = pipeline.take(step)  # wake, plan, checkpoint, solve: again while a sleeper was struck
        pipeline.settle(taken.step, taken.awake)
        record = pipeline.finish(taken.step, taken.checkpoint, taken.plan, len(taken.awake.collision.pairs))
        self._after_step(taken.step, taken.strategy)
        return record

    def _after_step(self, step: pipeline.Step, taken: pipeline.Strategy) -> None:
        """Keep what the next step checks against (the plane columns as this step left them) and
        what it measured."""
        if self.model.moving_planes():  # else the step left them as they were checked
            self._remember_planes()
        else:
            self._good_planes = step.checked_planes
        self.crowded_steps += taken is pipeline.Strategy.SOFT
        self.profile = step.profile

    # ------------------------------------------------------------------ snapshots
    def snapshot(self) -> Snapshot:
        """A deep copy of everything ``step`` reads or writes: the model (balls, planes, parameters)
        and a checkpoint of the parts a step changes (ball states, plane poses, time, sleep, and the
        caches that change results: kept pairs, warm start)."""
        model, checkpoint = copy.deepcopy((self.model, Checkpoint.of(self.parts)))
        return Snapshot(model, checkpoint, crowded_steps=self.crowded_steps)

    def restore(self, snap: Snapshot) -> None:
        """Put the world back as it was at ``snap``; stepping on repeats the original run bit for bit.

        The snapshot stays usable: it can be restored again. Live views of balls that did not exist
        then raise IndexError, saying so, when used.
        """
        if not isinstance(snap, Snapshot):
            raise TypeError(f"restore takes a Snapshot from World.snapshot(), got {type(snap).__name__}")
        self.model, checkpoint = copy.deepcopy((snap.model, snap.checkpoint))
        checkpoint.restore(self.parts)
        self.crowded_steps = snap.crowded_steps
        self._remember_planes()
        self._good_balls = steppable.LastGoodBalls()

    def copy(self) -> World:
        """An independent World in the same state (it steps on exactly as this one would)."""
        twin = World.__new__(World)
        twin.parts = Parts.new()
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
