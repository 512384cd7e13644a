"""The two ways of taking a step, built from the same stages.

- ``split_at_impacts``: the step is split at every impact, so balls meet exactly when they touch.
  Each interval finds the contacts, pushes overlapping balls apart, bounces the ones that arrive,
  solves the resting contacts for constant forces over the rest of the step, predicts the next
  impact and integrates to it. This is what gives e²·h apexes at 60 Hz and Newton's cradle.
- ``crowded_step``: when many pairs may meet within one step (a pile landing or resting), splitting
  it at each impact costs a pass over the world per impact. The step is one frame of Box2D v3's soft
  step instead (softstep.py): contacts measured once, with a speculative margin (P. Firth,
  "Speculative contacts", 2011), then ``substeps`` soft-biased solves. Where it cannot keep the walls
  (balls too fast for a substep, or something it did not foresee) it is retried with more substeps
  and, failing that, split at impacts.

``crowded_contacts`` decides between them. Each strategy passes the restitution threshold and each
contact's minimum normal speed (v_n ≥ min_normal_speed: 0 touching, −gap/dt speculative) to the
stages explicitly.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from . import collision, impacts, moving_planes, narrowphase, penetration, resting, rows, softstep, toi
from .contacts import SPHERE_PLANE, ContactPoints, EventLog
from .forces import ConstantPerBall, ForceTerm, free_acceleration
from .integrators import Workspace, integrate
from .model import Model
from .pairs import KeptPairs, PairCache, contact_slop
from .profile import StepProfile
from .settings import (
    BROAD_PHASE_STEPS,
    CONTACT_SLOP,
    CROWD_OVERLAP,
    CROWD_PAIRS,
    DEEP_OVERLAP,
    MAX_INTERVALS,
    RETRIES,
    SPECULATIVE_REACH,
    SUBSTEP_TRAVEL,
)
from .state import State, V, W, X, with_static

DEEPER = "a contact overlapped deeper than DEEP_OVERLAP (more than it did)"


@dataclass
class Step:
    """What every stage of one step shares: the world's parts and this step's settings and outputs.

    ``intervals`` counts the intervals integrated so far in this step: the strategies read it (is this
    the first interval? is the bound MAX_INTERVALS reached?), and ``World.step`` copies it into the
    profile at the end, which only measures.
    """

    model: Model
    state: State
    pairs: PairCache
    warm: resting.WarmStart
    workspace: Workspace
    forces: list[ForceTerm]
    dt: float
    restitution_threshold: float  # m/s, approach speed below which nothing bounces
    events: EventLog
    profile: StepProfile
    intervals: int = 0
    doubt: str | None = None  # why a soft frame was undone and split at impacts instead (crowded_step)
    # the (N, 13) block as the step found it (World.step's copy, read only): a soft frame undoes to it
    # instead of copying it again (None: the frame copies)
    before: np.ndarray | None = None

    def integrate(self, push: ForceTerm | None, h: float) -> None:
        """Advance every ball by ``h`` under the force terms, plus the contact forces ``push``, and move
        the planes along with them."""
        with self.profile.stage("integrate"):
            terms = self.forces if push is None else [*self.forces, push]
            integrate(self.model.integrator, self.state.body, terms, h, self.workspace)
            moving_planes.advance(self.model, self.state, h)
        self.intervals += 1


def crowded(step: Step, c: ContactPoints, accel: np.ndarray) -> bool:
    """Whether the step is crowded: taken as one soft-step frame over every kept pair ``c`` instead of
    split at each impact.

    Meetings are counted along today's normals: the gap after dt, g + v_n·dt + ½·a_n·dt², falls to
    contact. More than ``model.crowd_limit`` meetings make the step crowded; so does, among
    CROWD_PAIRS kept pairs or more (a pile), any meeting or touching contact, and so does any overlap
    deeper than CROWD_OVERLAP of a radius (``model.crowd_limit`` inf: never).
    """
    dt, model = step.dt, step.model
    if len(c) == 0:  # nothing near anything (free flight): nothing can meet
        return False
    many = len(c) >= CROWD_PAIRS and model.crowd_limit != np.inf  # inf: always split at impacts
    # balls overlapping deeply (created at one point, or left so by a crowd) are pushed apart by the
    # soft step, whose planes hold, not jumped apart by positions
    deep = model.crowd_limit != np.inf and (c.gap < -CROWD_OVERLAP * model.spheres.radius[c.a]).any()
    if deep:
        return True
    if not many and len(c) <= model.crowd_limit:  # too few pairs to be more meetings
        return False
    dv, da = _relative_motion(step, c, accel)
    ahead = c.gap + np.einsum("ij,ij->i", dv * dt + 0.5 * dt * dt * da, c.normal)
    meetings = np.count_nonzero((c.gap >= CONTACT_SLOP) & (ahead < CONTACT_SLOP))
    # among many pairs (a pile) a touching contact makes the step crowded too: a pile rests in the
    # soft step it landed in, not alternately in the two
    return meetings > (0 if many else model.crowd_limit) or (many and bool((c.gap < CONTACT_SLOP).any()))


def speculative_reach(step: Step, c: ContactPoints, accel: np.ndarray, dv: np.ndarray | None = None,
                      da: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """The contacts of ``c`` within SPECULATIVE_REACH times the distance they could close in the step
    (by the same bound the time of impact uses), touching ones included; ``dv`` and ``da`` are the
    pairs' relative velocities and accelerations, worked out here when not given."""
    if dv is None or da is None:
        dv, da = _relative_motion(step, c, accel)
    closing = step.model.integrator.closing_speed_bound(dv, da, step.dt) * step.dt
    return c.gap < CONTACT_SLOP + SPECULATIVE_REACH * closing


def _relative_motion(step: Step, c: ContactPoints, accel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's relative velocity (against a moving plane's surface) and acceleration."""
    model = step.model
    v, acc = with_static(step.state.body[:, V]), with_static(accel)
    dv = np.take(v, c.a, axis=0) - np.take(v, c.b, axis=0)  # rows by index: faster than v[c.a]
    da = np.take(acc, c.a, axis=0) - np.take(acc, c.b, axis=0)
    if model.moving_planes():  # relative to a moving plane's surface under the contact point
        on = c.kind == SPHERE_PLANE
        dv[on] -= moving_planes.surface_velocity(model, step.state, c.other[on], c.point[on])
    return dv, da


def split_at_impacts(step: Step, contacts: ContactPoints, pairs: KeptPairs,
                     accel: tuple[np.ndarray, np.ndarray], elapsed: float = 0.0) -> None:  # fmt: skip
    """The step (from ``elapsed`` into it) split at every impact, so balls meet exactly when they
    touch.

    ``contacts`` are the kept ``pairs`` measured now, and ``accel`` the free linear and angular
    accelerations now.
    """
    model, state, prof, dt = step.model, step.state, step.profile, step.dt
    free, ang = accel
    start = state.time
    while elapsed < dt:
        remaining, now = dt - elapsed, start + elapsed
        first = step.intervals == 0
        if not first:
            with prof.stage("narrow phase"):
                contacts = narrowphase.contact_points(model, state, pairs)
        touching = contacts.subset(contacts.gap < contact_slop(model))
        with prof.stage("contact rows"):
            batch = rows.contact_rows(model, state, touching)
        with prof.stage("penetration"):
            moved = penetration.remove_penetration(model, state, touching, batch)
        if moved:  # the interval is planned from where the balls are now, not from where they overlapped
            contacts, touching, batch, pairs = _measure_again(step, pairs, free, remaining, touching, batch)
        min_normal_speed = np.zeros(len(touching))  # touching contacts may not close at all
        with prof.stage("impacts"):  # arrivals bounce in waves; then slower approaches stop
            impacts.in_waves(model, state, touching, batch, step.restitution_threshold, min_normal_speed,
                             step.events, now)  # fmt: skip
            impacts.stop_approaches(
                model, state, touching, batch, min_normal_speed, step.events, now, interval=remaining
            )
        if not first or len(touching):  # velocities may have changed since the step began
            free, ang = free_acceleration(state.body, step.forces)
        with prof.stage("resting solve"):
            push = resting.resting_forces(model, state, touching, batch, free, ang, remaining, dt,
                                          min_normal_speed, step.warm, step.events, now)  # fmt: skip
        lin = free if push is None else free + push.lin
        # The first interval's free path was checked against the boxes when the pairs were taken; a
        # path bent by a bounce or a contact force may leave them, and then the pairs are found again
        # for the rest of this step and the next ones (they replace the kept pairs).
        with prof.stage("pairs"):
            if (not first or push is not None or moved) and pairs.escaped(model, state, lin, remaining):
                ahead = remaining + (BROAD_PHASE_STEPS - 1) * dt
                pairs = step.pairs.renew(model, state, remaining, ahead, lin, free)
                contacts = narrowphase.contact_points(model, state, pairs)
        if step.intervals + 1 >= MAX_INTERVALS:  # a pathological pile-up: no more splitting
            finish_conservatively(step, contacts, push, lin, remaining)
            step.events.close_interval(1.0)
            return
        with prof.stage("time of impact"):
            h = min(toi.next_impact(model, state, contacts, lin, remaining), remaining)
        step.integrate(push, h)
        step.events.close_interval(h / remaining)
        elapsed = dt if h >= remaining else elapsed + h


Measured = tuple[ContactPoints, ContactPoints, rows.ContactRows, KeptPairs]


def _measure_again(
    step: Step,
    pairs: KeptPairs,
    free: np.ndarray,
    remaining: float,
    touching: ContactPoints,
    batch: rows.ContactRows,
) -> Measured:
    """After the push-apart moved balls: the kept pairs measured again (found again first if a ball was
    moved out of the box they were found from), the ``touching`` contacts and their rows with the
    pairs the move brought into contact added after them.

    A ball pushed out of an overlap may now touch a wall it was far from (a small ball inside a big
    one beside a wall is pushed to it): planned from the gaps measured before the move, the interval
    would let it fly on through that wall. The contacts that touched before the move stay as they were
    measured, so a move that brings nothing new into contact solves what it solved before."""
    model, state, prof = step.model, step.state, step.profile
    with prof.stage("pairs"):
        if pairs.escaped(model, state, free, remaining):
            ahead = remaining + (BROAD_PHASE_STEPS - 1) * step.dt
            pairs = step.pairs.renew(model, state, remaining, ahead, free, free)
    with prof.stage("narrow phase"):
        contacts = narrowphase.contact_points(model, state, pairs)
    met = (contacts.gap < contact_slop(model)) & ~np.isin(contacts.keys(), touching.keys())
    if met.any():
        touching = ContactPoints.concatenate([touching, contacts.subset(met)])
        with prof.stage("contact rows"):
            batch = rows.contact_rows(model, state, touching)
    return contacts, touching, batch, pairs


def finish_conservatively(step: Step, contacts: ContactPoints, push: ConstantPerBall | None,
                          lin: np.ndarray, remaining: float) -> None:  # fmt: skip
    """Take the rest of a step that ran out of intervals in one go, passing through nothing: every
    ball that could reach anything in that time stops where it is (velocity and spin zero, its
    forces balanced), and the others, which cannot, move on."""
    model, state = step.model, step.state
    with step.profile.stage("time of impact"):
        stop = toi.threatened(model, state, contacts, lin, remaining)
    body = state.body
    body[stop, V] = 0.0
    body[stop, W] = 0.0
    free, ang = free_acceleration(body, step.forces)
    held_lin = free if push is None else free + push.lin
    held_ang = ang if push is None else ang + push.ang
    hold = ConstantPerBall(np.where(stop[:, None], -held_lin, 0.0), np.where(stop[:, None], -held_ang, 0.0))
    if push is not None:
        hold = ConstantPerBall(hold.lin + push.lin, hold.ang + push.ang)
    step.integrate(hold, remaining)


def crowded_step(step: Step, contacts: ContactPoints, accel: tuple[np.ndarray, np.ndarray]) -> bool:
    """A crowded step as one frame of ``model.substeps`` soft substeps (softstep.py) over the kept
    pairs ``contacts`` that could meet within it; True when it was taken so.

    A pair could meet within the frame if its gap is less than SPECULATIVE_REACH times the distance
    its balls could cover towards each other at their own speeds, (|v_a| + |v_b| + (|a_a| + |a_b|)·dt)·dt
    (with every plane), not at their relative speed: within a frame a ball's neighbours change speed
    (the ball under it stops on the floor, the one beside it bounces back), so a pair falling together
    meets at 5 m/s before the frame ends. Pairs at rest beside each other a fraction of a radius apart
    are left out; a speculative pair pushes only if it closes faster than its gap allows.

    The soft step keeps the walls only while every ball it moves travels less than SUBSTEP_TRAVEL of
    its radius per substep, and while nothing it did not foresee happens. A frame is tried with twice
    the substeps (at most RETRIES times) when some ball could travel farther before it starts, or
    when it is undone after it because:

    - a ball moved farther than that in a substep, or left the box its pairs were found from (then a
      pair the broad phase never saw could have met);
    - a solved contact overlapped deeper than DEEP_OVERLAP of the smaller radius at any substep's end;
    - a pair left out of the contacts that could have met overlaps that deep at the end.

    When no try holds, the step is split at impacts instead (``split_at_impacts``, which passes
    through nothing, however fast).
    """
    model, state, dt, now = step.model, step.state, step.dt, step.state.time
    free, _ = accel
    radius = np.append(model.spheres.radius, np.inf)
    v, acc = state.body[:, V], free
    # each ball's speed and pull, and 0 for the static row N
    speed = np.append(np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2]), 0.0)
    pull = np.append(np.sqrt(acc[:, 0] * acc[:, 0] + acc[:, 1] * acc[:, 1] + acc[:, 2] * acc[:, 2]), 0.0)
    reach = (speed[contacts.a] + speed[contacts.b] + (pull[contacts.a] + pull[contacts.b]) * dt) * dt
    solved = (contacts.gap < CONTACT_SLOP + SPECULATIVE_REACH * reach) | (contacts.kind == SPHERE_PLANE)
    del reach
    c = contacts.subset(solved)
    # the normals laid out as (3, K) columns, which is how the solve reads them (jacobi.Contacts.n is
    # then this memory, not a copy of it)
    c.normal = np.asfortranarray(c.normal)
    # the frame and its checks read the normals and points of the pairs it solves alone (``c`` has
    # them), and b is N or other: the kept pairs' own go, 56 bytes a pair (World.step measures them
    # again if the step is split at impacts after all)
    contacts.normal = contacts.point = contacts.b = None
    for substeps in [model.substeps << k for k in range(RETRIES + 1)]:
        h = dt / substeps
        fast = speed * h + pull * h * h > SUBSTEP_TRAVEL * radius
        if fast[c.a].any() or fast[c.b].any():
            step.doubt = "a ball could travel farther than SUBSTEP_TRAVEL radii in a substep"
            continue
        last = substeps == model.substeps << RETRIES
        frame = _soft_frame(step, contacts, solved, c, substeps, last)
        if frame is not None:
            break
    else:
        return False
    step.events.add(now, c, c.keys(), frame.impulse)
    step.intervals += 1
    return True


def _soft_frame(step: Step, contacts: ContactPoints, solved: np.ndarray, c: ContactPoints, substeps: int,
                last: bool) -> softstep.Frame | None:  # fmt: skip
    """One try at the soft frame with ``substeps`` substeps: the frame, or None (everything undone,
    the reason in ``step.doubt``) when ``frame_doubt`` finds it cannot be trusted. The ``last`` try is
    kept when its only fault is a solved contact that overlapped deeper: that is no pass through
    anything, and splitting a heap of overlapping balls at impacts jumps them apart by positions."""
    model, state, dt = step.model, step.state, step.dt
    n = model.spheres.count
    # the balls as the frame found them: the step's own copy when nothing has moved them since (a frame
    # undone puts them back to it), so a settled pile holds one copy of its states, not two
    first = step.before is not None and step.intervals == 0
    body_before = step.before if first else state.body.copy()
    planes_before = copy.deepcopy(state.planes)
    warm_before = (step.warm.keys, step.warm.forces, step.warm.apart)
    kept_before = step.pairs.kept
    with step.profile.stage("soft step"):
        frame = softstep.frame(
            model, state, c, step.forces, dt, step.restitution_threshold, step.warm, substeps
        )
        balls = frame.balls[frame.balls < n]
        others = np.ones(n, bool)
        others[balls] = False
        if not model.moving_planes():  # then nothing does work on the balls but gravity
            softstep.hold_energy(model, state, body_before, balls)
    if others.any():  # balls touching nothing this frame fly on the world's integrator
        with step.profile.stage("integrate"):
            rows = state.body[others]
            terms = softstep.compact_terms(step.forces, np.flatnonzero(others), n)
            integrate(model.integrator, rows, terms, dt, step.workspace)
            state.body[others] = rows
    moving_planes.advance(model, state, dt)
    with step.profile.stage("time of impact"):
        step.doubt = frame_doubt(step, contacts, solved, c, frame, body_before)
    if step.doubt is None or (last and step.doubt == DEEPER):
        return frame
    state.body[:] = body_before  # undo it all
    state.planes = planes_before
    step.warm.keys, step.warm.forces, step.warm.apart = warm_before
    step.pairs.kept = kept_before
    return None


def frame_doubt(step: Step, contacts: ContactPoints, solved: np.ndarray, c: ContactPoints,
                frame: softstep.Frame, before: np.ndarray) -> str | None:  # fmt: skip
    """Why a soft frame cannot be trusted (see ``crowded_step``), or None when it kept its promises.

    A ball that left the box its pairs were found from may have met a body the broad phase never
    paired it with: the pairs are then found afresh around where the balls are now (they replace the
    kept pairs, as a split step's renewal does) and those new pairs are checked too."""
    model, state = step.model, step.state
    n = model.spheres.count
    radius = model.spheres.radius
    cols = frame.balls < n
    balls = frame.balls[cols]
    r = radius[balls]
    if (frame.largest_move[cols] > SUBSTEP_TRAVEL * r).any():
        return "a ball moved farther than SUBSTEP_TRAVEL radii in a substep"
    smaller = np.where(c.b < n, np.minimum(radius[c.a], np.append(radius, 0.0)[c.b]), radius[c.a])
    # a solved contact that overlapped deeper is said last: a frame kept in spite of it (the last try)
    # must still have met every pair it left out
    deeper = bool((frame.least_separation < np.minimum(c.gap, 0.0) - DEEP_OVERLAP * smaller).any())
    # how far each ball got from where it started (the others flew straight)
    far = np.zeros(n + 1)
    moved = state.body[:, X] - before[:, X]
    far[:n] = np.sqrt(moved[:, 0] ** 2 + moved[:, 1] ** 2 + moved[:, 2] ** 2)
    far[balls] = np.maximum(far[balls], frame.farthest[cols])
    kept = step.pairs.kept
    lo, hi = frame.lo, frame.hi
    centre = kept.centre[balls].T
    corner = np.maximum(np.abs(lo - centre), np.abs(hi - centre))
    escaped = (
        (lo - r < kept.lo[balls].T).any()
        or (hi + r > kept.hi[balls].T).any()
        or (np.sqrt(corner[0] ** 2 + corner[1] ** 2 + corner[2] ** 2) + r > kept.reach[balls]).any()
    )
    if escaped:  # pairs around where the balls are now; those not solved are the ones left out
        free, _ = free_acceleration(state.body, step.forces)
        pairs = step.pairs.renew(model, state, step.dt, BROAD_PHASE_STEPS * step.dt, free, free)
        now = narrowphase.contact_points(model, state, pairs)
        out = now.subset(~np.isin(now.keys(), c.keys()))
        out.gap = _gap_from(out, before, model, state)
    else:
        out = contacts.subset(~solved)
        b = np.where(out.kind == SPHERE_PLANE, n, out.other)  # crowded_step let go of contacts.b
        near = far[out.a] + far[b] >= out.gap  # only those whose balls got farther than their gap
        out = out.subset(near)
        start = np.minimum(out.gap, 0.0)
        out.gap = _gap_from(out, before, model, state) - start
    if len(out):
        on_plane = out.kind == SPHERE_PLANE
        smaller = np.where(
            on_plane, radius[out.a], np.minimum(radius[out.a], radius[np.where(on_plane, 0, out.other)])
        )
        if (out.gap < -DEEP_OVERLAP * smaller).any():
            return "a pair left out overlaps deeper than DEEP_OVERLAP"
    return DEEPER if deeper else None


def _gap_from(c: ContactPoints, before: np.ndarray, model: Model, state: State) -> np.ndarray:
    """The gaps of the pairs ``c`` now, each ball kept on the side of a plane it started the step on
    (``before``): a ball that crossed a plane overlaps it by its whole crossing."""
    gap = np.empty(len(c))
    if len(c) == 0:
        return gap
    x, radius = state.body[:, X], model.spheres.radius
    on_plane = c.kind == SPHERE_PLANE
    if on_plane.any():
        pose = state.planes
        s, p = c.a[on_plane], c.other[on_plane]
        d = before[s, 0:3] - pose.center[p]
        nrm = pose.normal[p]
        side = np.where(d[:, 0] * nrm[:, 0] + d[:, 1] * nrm[:, 1] + d[:, 2] * nrm[:, 2] < 0.0, -1.0, 1.0)
        gap[on_plane] = collision.sphere_plane(x, radius, s, p, side, pose.center, pose.normal, pose.axis_u,
                                               pose.axis_v, model.planes.half_size)[0]  # fmt: skip
    if (~on_plane).any():
        gap[~on_plane] = collision.sphere_sphere(x, radius, c.a[~on_plane], c.other[~on_plane])[0]
    return gap
