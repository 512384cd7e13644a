"""The World: ball and plane arrays plus the step pipeline that advances them."""

from __future__ import annotations

import numpy as np

from . import broadphase, collision, quaternion, solver, toi, validation
from .bodies import Plane, PlaneList, Sphere, SphereList
from .contacts import SPHERE_PLANE, SPHERE_SPHERE, Candidates, Contacts, ContactSet, EventLog
from .forces import AngularDrag, ConstantPerBall, ForceTerm, Gravity, LinearDrag
from .integrators import INTEGRATORS, Integrator, Workspace, integrate
from .solver import ContactBatch, Impulses
from .state import Q, V, W, X, plane_columns, sphere_columns

# The step a scene, the viewer and the command line take unless told otherwise (s): 240 Hz.
DEFAULT_TIMESTEP = 1.0 / 240.0

# Moments of inertia of a sphere about a diameter, as a fraction of m·r².
SOLID_INERTIA = 2.0 / 5.0
HOLLOW_INERTIA = 2.0 / 3.0

# Balls closer than this (m) are in contact: the solver holds them, time of impact stops here.
CONTACT_SLOP = 1e-5
# The bounce is solved over the contacts within this many balls of an arriving one.
BOUNCE_HOPS = 3
# Overlaps shallower than this (m) are left alone: rounding, not penetration.
OVERLAP_TOLERANCE = 1e-7
# Normal speeds (m/s) below this count as not approaching (rounding, not an impact).
APPROACH_SPEED = 1e-6
# Impacts whose times are this close (as an overlap, in radii) are resolved together: a pile of 1,000
# balls landing then takes ~4 intervals per step instead of ~19. A lone impact is still met exactly.
IMPACT_OVERLAP = 0.005
# Broad-phase boxes cover this many steps of each ball's path, so most steps reuse the pairs.
BROAD_PHASE_STEPS = 4
# … or as far as a ball travels this fraction of its radius, if that is sooner (but never less than
# the step itself) …
BROAD_PHASE_REACH = 0.2
# … and are grown by this fraction of the ball's radius, so slow balls keep their pairs for longer.
BROAD_PHASE_MARGIN = 0.1
# A step in which more than this many pairs not yet touching may meet is taken whole, with
# speculative contacts (World.crowd_limit; see World._crowded_step).
CROWD_LIMIT = 32
# … and the pairs that take part are those within this many times the distance they could close.
SPECULATIVE_REACH = 2.0
# Resting forces found over less than this fraction of a step do not warm-start the next solve.
WARM_START_SPAN = 0.5
# A step is split at most this many times; past it the rest of the step is taken whole.
MAX_INTERVALS = 10_000
# Explicit Euler's default restitution threshold, in units of |g|·dt (see _bounce_threshold).
EULER_THRESHOLD_STEPS = 8.0


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
        self.solver_iterations = 10
        self.crowd_limit = CROWD_LIMIT
        self.crowded_steps = 0  # how many steps were taken whole, with speculative contacts
        self._spheres = sphere_columns()
        self._planes = plane_columns()
        self._workspace = Workspace()
        # Resting contact forces from the last interval, by pair key, to warm-start the solver.
        self._warm_keys = np.zeros(0, np.int64)
        self._warm_forces = Impulses.zeros(0)
        self._candidates: Candidates | None = None

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
    def crowd_limit(self) -> float:
        """A step in which more pairs than this may meet is taken whole, with speculative contacts
        (``inf``: always split the step at each impact; 0: take every step with an impact whole)."""
        return self._crowd_limit

    @crowd_limit.setter
    def crowd_limit(self, value: float) -> None:
        self._crowd_limit = validation.number("crowd_limit", value, nonnegative=True, infinite=True)

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
        """Advance the world by ``dt`` seconds; returns the contacts resolved in the step.

        The broad phase's pairs come first (kept from earlier steps while they still cover every
        ball's path). A step in which few pairs can meet is split at every impact, and each interval
        runs the same stages: find the contacts, push overlapping balls apart, bounce the ones that
        arrive, solve the resting contacts for constant forces over the interval, predict the next
        impact, and integrate to it. A crowded step (a pile landing) is taken whole instead, with
        speculative contacts (see ``_crowded_step``).
        """
        dt = validation.number("dt", dt, positive=True)
        state = self._spheres.state
        self._reject_non_finite_input()
        before = state.copy()
        forces = self.forces()
        threshold = self._bounce_threshold(dt)
        events = EventLog()
        free, ang = self._free_acceleration(forces)
        candidates = self._candidate_pairs(dt, free)
        contacts = self._narrow_phase(candidates)
        crowd = self._crowd(contacts, free, dt)
        if crowd is not None:
            self._crowded_step(crowd, forces, threshold, dt, events)
            self.crowded_steps += 1
        else:
            self._exact_step(contacts, candidates, forces, (free, ang), threshold, dt, events)
        self._reject_non_finite(before)
        self.time += dt
        return events.record()

    def _exact_step(self, contacts: ContactSet, candidates: Candidates, forces: list[ForceTerm],
                    accel: tuple[np.ndarray, np.ndarray], threshold: float, dt: float,
                    events: EventLog) -> None:  # fmt: skip
        """The step split at every impact, so balls meet exactly when they touch."""
        state = self._spheres.state
        free, ang = accel
        elapsed, intervals = 0.0, 0
        while elapsed < dt:
            remaining = dt - elapsed
            if intervals:
                contacts = self._narrow_phase(candidates)
            touching = contacts.subset(contacts.gap < CONTACT_SLOP)
            batch = self._contact_batch(touching)
            self._remove_penetration(touching, batch)
            now = self.time + elapsed
            self._bounce(touching, batch, threshold, events, now)
            if intervals or len(touching):  # velocities may have changed since the step began
                free, ang = self._free_acceleration(forces)
            push = self._resting_forces(touching, batch, free, ang, remaining, dt, events, now)
            lin = free if push is None else free + push.lin
            # The first interval's free path was checked against the boxes when the pairs were taken.
            if (intervals or push is not None) and self._escapes_boxes(candidates, lin, remaining):
                ahead = remaining + (BROAD_PHASE_STEPS - 1) * dt
                candidates = self._broad_phase(remaining, ahead, lin, free)
                contacts = self._narrow_phase(candidates)
            intervals += 1
            if intervals < MAX_INTERVALS:
                h = min(self._next_impact(contacts, lin, remaining), remaining)
            else:  # a pathological pile-up: finish the step without splitting it further
                h = remaining
            terms = forces if push is None else [*forces, push]
            integrate(self._integrator, state, terms, h, self._workspace)
            events.close_interval(h / remaining)
            elapsed = dt if h >= remaining else elapsed + h

    def _crowded_step(self, c: ContactSet, forces: list[ForceTerm], threshold: float, dt: float,
                      events: EventLog) -> None:  # fmt: skip
        """The whole step as one interval, with speculative contacts (P. Firth, "Speculative
        contacts", 2011; as in Box2D v3 and Bullet).

        When many pairs may meet within the step, splitting it at each impact costs a pass over the
        world per impact. Instead every pair that could meet within the step joins the solves as a
        contact with a gap: it may close by at most that gap, v_n ≥ −gap/dt, and the constraint only
        pushes if the pair would otherwise pass it. A pair arriving faster than the bounce threshold
        leaves at e times its approach speed, as in an exact step, but from where it was when the
        step began: a bounce is early by at most the gap it had left (≤ v·dt). Pairs missed because a
        bounce turned a ball towards a ball it was not near overlap slightly; the next step's
        penetration removal and bounce deal with them, and its broad phase checks every path again.
        """
        state = self._spheres.state
        allowed = np.where(c.gap < CONTACT_SLOP, 0.0, c.gap / dt)
        batch = self._contact_batch(c)
        self._remove_penetration(c, batch)
        self._bounce(c, batch, threshold, events, self.time, allowed)
        free, ang = self._free_acceleration(forces)
        push = self._resting_forces(c, batch, free, ang, dt, dt, events, self.time, allowed)
        integrate(self._integrator, state, forces if push is None else [*forces, push], dt, self._workspace)
        events.close_interval(1.0)

    # ------------------------------------------------------------------ step stages
    def _free_acceleration(self, forces: list[ForceTerm]) -> tuple[np.ndarray, np.ndarray]:
        """Linear and angular acceleration from the force terms alone, at the current state."""
        state = self._spheres.state
        lin = np.zeros((len(state), 3))
        ang = np.zeros((len(state), 3))
        for term in forces:
            term.add(state, lin, ang)
        return lin, ang

    def _path_end(self, accel: np.ndarray, h: float) -> np.ndarray:
        """Where each ball would be after ``h`` along the path the integrator takes."""
        state = self._spheres.state
        end = state[:, X] + state[:, V] * h
        if self._integrator.quadratic_path:
            end += 0.5 * h * h * accel
        return end

    def _candidate_pairs(self, dt: float, accel: np.ndarray) -> Candidates:
        """The broad phase's pairs, kept from earlier steps while every ball's path stays in its box.

        Boxes are swept over BROAD_PHASE_STEPS steps ahead, so most steps reuse them; the side each
        ball is on of each plane is refreshed every step (a ball moved by hand may have crossed one).
        """
        c = self._candidates
        counts = (self._spheres.count, self._planes.count)
        if c is None or c.counts != counts or self._escapes_boxes(c, accel, dt):
            c = self._candidates = self._broad_phase(dt, BROAD_PHASE_STEPS * dt, accel, accel)
        else:
            c.side = self._plane_sides(c.sphere, c.plane)
        return c

    def _plane_sides(self, sphere: np.ndarray, plane: np.ndarray) -> np.ndarray:
        """±1: which side of each plane each ball's centre is on (+1 on the normal's side or in it)."""
        pl = self._planes
        signed = np.einsum("ij,ij->i", self._spheres.state[sphere, 0:3] - pl.center[plane], pl.normal[plane])
        return np.where(signed < 0.0, -1.0, 1.0)

    def _broad_phase(self, h: float, ahead: float, accel: np.ndarray, free: np.ndarray) -> Candidates:
        """Candidate pairs from boxes around each ball's swept path.

        Each box covers the next ``h`` seconds under ``accel`` (contact forces included), and beyond it
        up to ``ahead`` seconds of free flight under ``free`` for balls slow enough to travel less than
        BROAD_PHASE_REACH radii in that time: slow balls keep their pairs for several steps while fast
        ones do not drag big boxes through a crowd.
        """
        state, radius = self._spheres.state, self._spheres.radius
        x = state[:, X]
        speed = np.linalg.norm(state[:, V], axis=1)
        horizon = np.clip(BROAD_PHASE_REACH * radius / np.maximum(speed, 1e-12), h, max(h, ahead))
        now, later = self._path_end(accel, h), x + state[:, V] * horizon[:, None]
        if self._integrator.quadratic_path:
            later += 0.5 * horizon[:, None] ** 2 * free
        # a parabola strays at most ⅛·|a|·t² from its chord
        sag = 0.125 * (np.linalg.norm(accel, axis=1) * h * h + np.linalg.norm(free, axis=1) * horizon**2)
        pad = (radius + sag + BROAD_PHASE_MARGIN * radius + CONTACT_SLOP)[:, None]
        lo = np.minimum(np.minimum(x, now), later)
        hi = np.maximum(np.maximum(x, now), later)
        centre = 0.5 * (lo + hi)
        reach = 0.5 * np.linalg.norm(hi - lo, axis=1) + pad[:, 0]
        lo -= pad
        hi += pad
        i, j = broadphase.within_reach(*broadphase.sphere_pairs(lo, hi), centre, reach)
        pl = self._planes
        s, p = broadphase.sphere_plane_pairs(lo, hi, pl.center, pl.normal, pl.axis_u, pl.axis_v, pl.half_size)
        counts = (self._spheres.count, self._planes.count)
        self._candidates = Candidates(lo, hi, centre, reach, i, j, s, p, self._plane_sides(s, p), counts)
        return self._candidates

    def _escapes_boxes(self, candidates: Candidates, accel: np.ndarray, h: float) -> bool:
        """True when some ball's path for the next ``h`` leaves the box or sphere it was paired from."""
        x, radius = self._spheres.state[:, X], self._spheres.radius
        end = self._path_end(accel, h)
        # a parabola strays at most ⅛·|a|·h² from the chord between its ends
        sag = 0.125 * h * h * np.linalg.norm(accel, axis=1) if self._integrator.quadratic_path else 0.0
        pad = radius + sag
        c, box_pad = candidates, pad[:, None]
        if np.any(np.minimum(x, end) - box_pad < c.lo) or np.any(np.maximum(x, end) + box_pad > c.hi):
            return True
        # the chord's ends inside the sphere keep the whole chord inside (spheres are convex)
        farthest = np.maximum(np.linalg.norm(x - c.centre, axis=1), np.linalg.norm(end - c.centre, axis=1))
        return bool(np.any(farthest + pad > c.reach))

    def _narrow_phase(self, candidates: Candidates) -> ContactSet:
        """Gap, normal and point of every candidate pair at the current positions."""
        x, radius = self._spheres.state[:, X], self._spheres.radius
        c = candidates
        gp, np_, pp = collision.sphere_plane(x, radius, c.sphere, c.plane, c.side, self._planes)
        gs, ns, ps = collision.sphere_sphere(x, radius, c.pair_i, c.pair_j)
        static = np.full(len(c.sphere), self._spheres.count)
        return ContactSet(
            kind=np.concatenate((np.full(len(gp), SPHERE_PLANE), np.full(len(gs), SPHERE_SPHERE))),
            a=np.concatenate((c.sphere, c.pair_i)),
            b=np.concatenate((static, c.pair_j)),
            other=np.concatenate((c.plane, c.pair_j)),
            gap=np.concatenate((gp, gs)),
            normal=np.concatenate((np_, ns)),
            point=np.concatenate((pp, ps)),
        )

    def _contact_batch(self, c: ContactSet) -> ContactBatch:
        """Masses, lever arms and mixed materials of the touching contacts, grouped into colours."""
        sph, pl = self._spheres, self._planes
        with_static = lambda arr: np.append(arr, 0.0)  # noqa: E731 - row N is the static world
        radius, inv_mass, inv_inertia = (with_static(a) for a in (sph.radius, sph.inv_mass, sph.inv_inertia))
        on_plane = c.kind == SPHERE_PLANE
        p = np.where(on_plane, c.other, 0)
        o = np.where(on_plane, 0, c.other)

        def mixed(ball: np.ndarray, plane: np.ndarray, rule) -> np.ndarray:
            other = np.where(on_plane, plane[p] if len(plane) else 0.0, ball[o])
            return rule(ball[c.a], other)

        ra, rb = radius[c.a], radius[c.b]
        # Rolling resistance acts through the rolling radius: r for a ball on a plane, the reduced
        # radius 2·r_a·r_b/(r_a + r_b) between two balls.
        roll_radius = np.where(on_plane, ra, 2.0 * ra * rb / np.where(on_plane, 1.0, ra + rb))
        return ContactBatch(
            a=c.a,
            b=c.b,
            normal=c.normal,
            arm_a=-ra[:, None] * c.normal,
            arm_b=rb[:, None] * c.normal,
            inv_mass_a=inv_mass[c.a],
            inv_mass_b=inv_mass[c.b],
            inv_inertia_a=inv_inertia[c.a],
            inv_inertia_b=inv_inertia[c.b],
            restitution=mixed(sph.restitution, pl.restitution, np.multiply),
            friction=np.sqrt(mixed(sph.friction, pl.friction, np.multiply)),
            rolling=np.sqrt(mixed(sph.rolling_friction, pl.rolling_friction, np.multiply)) * roll_radius,
            colours=solver.colour(c.a, c.b, sph.count),
        )

    def _velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """Copies of v and ω with the static row N (always zero) appended."""
        state = self._spheres.state
        return _with_static(state[:, V]), _with_static(state[:, W])

    def _remove_penetration(self, c: ContactSet, batch: ContactBatch) -> None:
        """Move overlapping balls apart along the contact normals, positions only (no velocity is added).

        A few Gauss–Seidel sweeps over the linearised gaps g = n·(x_a − x_b) − offset, each ball moved in
        proportion to its inverse mass.
        """
        if not np.any(c.gap < -OVERLAP_TOLERANCE):
            return
        x = self._spheres.state[:, X]
        pos = _with_static(x)
        n = c.normal
        offset = np.einsum("ij,ij->i", n, pos[c.a] - pos[c.b]) - c.gap
        share = batch.inv_mass_a / (batch.inv_mass_a + batch.inv_mass_b)
        for _ in range(4):
            for idx in batch.colours:
                a, b = c.a[idx], c.b[idx]
                gap = np.einsum("ij,ij->i", n[idx], pos[a] - pos[b]) - offset[idx]
                depth = np.maximum(-gap, 0.0)[:, None] * n[idx]
                pos[a] += depth * share[idx, None]
                pos[b] -= depth * (1.0 - share[idx, None])
            pos[-1] = 0.0
        x[:] = pos[:-1]

    def _bounce(self, c: ContactSet, batch: ContactBatch, threshold: float, events: EventLog, now: float,
                allowed: np.ndarray | None = None) -> None:  # fmt: skip
        """Impacts: contacts arriving faster than the threshold leave at e times their approach speed.

        The touching contacts within BOUNCE_HOPS balls of an arriving one take part, so a ball landing
        on a stack pushes through it; contacts arriving slower than the threshold just stop. A
        speculative contact may approach at its ``allowed`` speed (gap/dt) and arrives only faster.
        """
        if len(c) == 0:
            return
        crowded = allowed is not None
        allowed = allowed if crowded else np.zeros(len(c))
        v, w = self._velocities()
        ra, rb = batch.arm_a, batch.arm_b
        rel = v[c.a] + np.cross(w[c.a], ra) - v[c.b] - np.cross(w[c.b], rb)
        vn = np.einsum("ij,ij->i", rel, c.normal)
        approaching = vn < -(allowed + APPROACH_SPEED)
        arriving = approaching & (-vn > threshold)
        # In a crowded step only real impacts start an island: a slower approach is stopped by the
        # resting forces within the step (an overlap of at most threshold·dt/2, removed next step).
        seeds = arriving if crowded else approaching
        if not seeds.any():
            return
        # The island around the impacts: contacts within BOUNCE_HOPS balls of an approaching one.
        n = self._spheres.count
        involved = np.zeros(n + 1, bool)
        near = seeds
        for _ in range(BOUNCE_HOPS):
            involved[c.a[near]] = True
            involved[c.b[near]] = True
            involved[n] = False
            near = involved[c.a] | involved[c.b]
        island = batch.subset(near, n)
        target = np.where(arriving[near], -island.restitution * vn[near], -allowed[near])
        imp = solver.solve(island, v, w, target, Impulses.zeros(len(island)), self.solver_iterations)
        state = self._spheres.state
        state[:, V] = v[:-1]
        state[:, W] = w[:-1]
        hit = c.subset(near)
        events.add(now, hit, hit.keys(n), imp.normal)

    def _resting_forces(
        self,
        c: ContactSet,
        batch: ContactBatch,
        lin: np.ndarray,
        ang: np.ndarray,
        h: float,
        dt: float,
        events: EventLog,
        now: float,
        allowed: np.ndarray | None = None,
    ) -> ConstantPerBall | None:
        """Constant contact forces over the next ``h`` seconds that leave every touching contact
        not approaching, not slipping beyond the friction cone, at the end of the interval (a
        speculative contact may approach at its ``allowed`` speed).

        Solving for end-of-interval velocities and applying the impulses as constant forces keeps the
        integrators exact: a resting ball's force cancels gravity, so it reports zero velocity.

        The forces warm-start the next solve only when ``h`` is at least WARM_START_SPAN of the step
        ``dt``: the force that stops a slow arrival in the last sliver of a step is no force to hold
        for the next whole step. Warm-started with it, a column of balls is pre-stressed: the impulses
        cancel ball by ball, so the sweeps see nothing to correct until the stress reaches the top.
        """
        n = self._spheres.count
        if len(c) == 0:
            return None
        v, w = self._velocities()
        v[:-1] += lin * h
        w[:-1] += ang * h
        v_free, w_free = v.copy(), w.copy()
        keys = c.keys(n)
        imp = self._warm_impulses(keys, c.normal, h)
        solver.warm_start(batch, v, w, imp)
        target = np.zeros(len(c)) if allowed is None else -allowed
        solver.solve(batch, v, w, target, imp, self.solver_iterations)
        if h >= WARM_START_SPAN * dt:
            order = np.argsort(keys)
            self._warm_keys = keys[order]
            parts = (imp.normal, imp.friction, imp.rolling)
            self._warm_forces = Impulses(*(part[order] / h for part in parts))
        events.add_resting(now, c, keys, imp.normal)
        return ConstantPerBall((v[:-1] - v_free[:-1]) / h, (w[:-1] - w_free[:-1]) / h)

    def _warm_impulses(self, keys: np.ndarray, normal: np.ndarray, h: float) -> Impulses:
        """Last interval's contact forces for the pairs still touching, as impulses over ``h``."""
        imp = Impulses.zeros(len(keys))
        if len(self._warm_keys) == 0:
            return imp
        pos = np.searchsorted(self._warm_keys, keys)
        pos = np.minimum(pos, len(self._warm_keys) - 1)
        found = self._warm_keys[pos] == keys
        src = pos[found]
        imp.normal[found] = self._warm_forces.normal[src] * h
        friction = self._warm_forces.friction[src] * h
        n = normal[found]
        imp.friction[found] = (
            friction - np.einsum("ij,ij->i", friction, n)[:, None] * n
        )  # onto today's tangent plane
        imp.rolling[found] = self._warm_forces.rolling[src] * h
        return imp

    def _next_impact(self, c: ContactSet, accel: np.ndarray, h: float) -> float:
        """Time until the first pair not yet touching comes into contact (inf if none within h)."""
        apart = np.flatnonzero(c.gap >= CONTACT_SLOP)
        if apart.size == 0:
            return np.inf
        state = self._spheres.state
        x, v = _with_static(state[:, X]), _with_static(state[:, V])
        acc = _with_static(accel) if self._integrator.quadratic_path else np.zeros((len(x), 3))
        a, b = c.a[apart], c.b[apart]
        bound = _closing_speed_bound(v[a] - v[b], acc[a] - acc[b], h)
        reachable = c.gap[apart] <= bound * h
        apart, a, b, bound = apart[reachable], a[reachable], b[reachable], bound[reachable]
        if apart.size == 0:
            return np.inf
        on_plane = c.kind[apart] == SPHERE_PLANE
        radius = np.append(self._spheres.radius, 0.0)
        reach = radius[a] + radius[b]
        pl = self._planes

        def gap_at(k: np.ndarray, t: np.ndarray) -> np.ndarray:
            tt = t[:, None]
            pa = x[a[k]] + v[a[k]] * tt + 0.5 * acc[a[k]] * tt * tt
            pb = x[b[k]] + v[b[k]] * tt + 0.5 * acc[b[k]] * tt * tt
            plane_k = on_plane[k]
            if plane_k.any():
                pk = c.other[apart[k[plane_k]]]
                pb[plane_k] = collision.closest_point_on_planes(
                    pa[plane_k], pk, pl.center, pl.axis_u, pl.axis_v, pl.half_size
                )
            return np.linalg.norm(pa - pb, axis=1) - reach[k]

        when = toi.first_contact(gap_at, bound, h, 0.5 * CONTACT_SLOP)
        hit = np.isfinite(when)
        if not hit.any():
            return np.inf
        # Impacts close in time are taken together: advance to the latest impact that leaves every
        # earlier pair overlapping by less than IMPACT_OVERLAP of the smallest radius (removed next
        # interval by moving positions). A lone impact is always met exactly.
        order = np.argsort(when[hit], kind="stable")
        t, speed = when[hit][order], bound[hit][order]
        overlap = (t - t[0]) * np.maximum.accumulate(speed)
        allowed = IMPACT_OVERLAP * float(self._spheres.radius.min())
        return float(t[np.searchsorted(overlap, allowed, side="right") - 1])

    def _crowd(self, c: ContactSet, accel: np.ndarray, dt: float) -> ContactSet | None:
        """The contacts of a crowded step, or None when few enough pairs meet to split the step.

        Meetings are counted along today's normals: the gap after dt, g + v_n·dt + ½·a_n·dt², falls to
        contact. The step's contacts are every pair within SPECULATIVE_REACH times the distance it
        could close (by the same bound the time of impact uses), touching ones included.
        """
        v, acc = _with_static(self._spheres.state[:, V]), _with_static(accel)
        dv, da = v[c.a] - v[c.b], acc[c.a] - acc[c.b]
        ahead = c.gap + np.einsum("ij,ij->i", dv * dt + 0.5 * dt * dt * da, c.normal)
        if np.count_nonzero((c.gap >= CONTACT_SLOP) & (ahead < CONTACT_SLOP)) <= self.crowd_limit:
            return None
        path_da = da if self._integrator.quadratic_path else np.zeros_like(da)
        closing = _closing_speed_bound(dv, path_da, dt) * dt
        return c.subset(c.gap < CONTACT_SLOP + SPECULATIVE_REACH * closing)

    def _bounce_threshold(self, dt: float) -> float:
        """The approach speed below which contacts do not bounce.

        Default 2·|g|·dt: a ball bouncing slower than that would land again within a step or two.
        Explicit Euler gains g·dt of speed every flight, so a ball with restitution e settles into
        endless bounces at an arrival speed of g·dt/(1 − e) unless the threshold is above it; its
        default of 8·|g|·dt brings every bounce with e ≤ 0.85 to rest.
        """
        if self._restitution_threshold is not None:
            return self._restitution_threshold
        factor = EULER_THRESHOLD_STEPS if self._integrator.name == "euler" else 2.0
        return factor * float(np.linalg.norm(self._gravity)) * dt

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of all balls (J)."""
        sph = self._spheres
        v, w = sph.state[:, V], sph.state[:, W]
        return float(
            0.5 * (sph.mass @ np.einsum("ij,ij->i", v, v))
            + 0.5 * ((1.0 / sph.inv_inertia) @ np.einsum("ij,ij->i", w, w))
        )

    def potential_energy(self) -> float:
        """Gravitational potential energy −Σ m·g·x (J), zero at the origin."""
        sph = self._spheres
        return float(-(sph.mass @ (sph.state[:, X] @ self._gravity)))

    def _reject_non_finite_input(self) -> None:
        """Refuse to step from a NaN/inf written straight into the arrays (the setters check theirs)."""
        state = self._spheres.state
        if np.isfinite(state).all():
            return
        row, col = np.argwhere(~np.isfinite(state))[0]
        fields = (("position", X), ("velocity", V), ("orientation", Q), ("angular_velocity", W))
        field = next(name for name, cols in fields if cols.start <= col < cols.stop)
        raise ValueError(
            f"sphere #{row} has a non-finite {field} ({state[row, col]}); the world was not stepped"
        )

    def _reject_non_finite(self, before: np.ndarray) -> None:
        """Keep the world free of NaN/inf: restore the state and raise if a step produced any."""
        state = self._spheres.state
        if not np.isfinite(state).all():
            bad = int(np.flatnonzero(~np.isfinite(state).all(axis=1))[0])
            state[:] = before
            raise FloatingPointError(f"step made sphere #{bad}'s state non-finite; the step was undone")


def _with_static(rows: np.ndarray) -> np.ndarray:
    """Per-ball rows with the static world's zero row N appended (planes are body N in the solver)."""
    return np.vstack((rows, np.zeros(rows.shape[1])))


def _closing_speed_bound(dv: np.ndarray, da: np.ndarray, h: float) -> np.ndarray:
    """A bound on how fast each pair can close over the next ``h``, from the relative velocity and
    acceleration along the integrator's path (zero acceleration for Euler): |Δv| + |Δa|·h."""
    return np.linalg.norm(dv, axis=1) + np.linalg.norm(da, axis=1) * h
