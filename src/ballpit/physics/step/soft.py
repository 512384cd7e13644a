"""A crowded step as one soft frame: contacts measured once, with a speculative margin (P. Firth,
"Speculative contacts", 2011), then ``substeps`` soft-biased solves (Box2D v3's soft step,
softstep.py). A frame that cannot keep its promises is undone and tried with more substeps; when no
try holds, the step is split at impacts instead (split.py, which passes through nothing).
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from ..collision import geometry, narrowphase
from ..collision.pairs import KeptPairs
from ..contact import energy_guard, softstep
from ..core import exact
from ..core.contacts import SPHERE_PLANE, SPHERE_SPHERE, ContactPoints, find_keys, take_indices
from ..core.profile import Stage
from ..core.settings import (
    BROAD_PHASE_STEPS,
    DEEP_OVERLAP,
    RETRIES,
    SPECULATIVE_REACH,
    SUBSTEP_TRAVEL,
    SWEEP_CHUNK,
)
from ..core.state import State, V, X
from ..dynamics import moving_planes
from ..dynamics.forces import forces_of, free_acceleration
from ..dynamics.integrators import integrate
from ..dynamics.model import Model
from .checkpoint import Checkpoint
from .collide import Collision, Motion
from .context import Step
from .plan import Plan


class Verdict(Enum):
    """What the checks make of a soft frame: kept, or why it cannot be trusted (``frames``)."""

    KEPT = "the frame kept its promises"
    MOVED_TOO_FAR = "a ball moved farther than SUBSTEP_TRAVEL radii in a substep"
    DEEPER = "a contact overlapped deeper than DEEP_OVERLAP (more than it did)"
    LEFT_OUT = "a pair left out overlaps deeper than DEEP_OVERLAP"


def frames(step: Step, motion: Motion, collision: Collision, plan: Plan, checkpoint: Checkpoint) -> bool:
    """The step as one soft frame of ``plan.substeps`` substeps (softstep.py) over the kept pairs of
    ``collision`` that could meet within it; True when it was taken so (False: every try was undone to
    ``checkpoint``, taken before the frame, and the step is to be split at impacts). The frame takes
    the collision's contacts over (``Collision.take``).

    A pair could meet within the frame if its gap is less than SPECULATIVE_REACH times the distance
    its balls could cover towards each other at their own speeds, (|v_a| + |v_b| + (|a_a| + |a_b|)·dt)·dt
    (with every plane), not at their relative speed: within a frame a ball's neighbours change speed
    (the ball under it stops on the floor, the one beside it bounces back), so a pair falling together
    meets at 5 m/s before the frame ends. Pairs at rest beside each other a fraction of a radius apart
    are left out; a speculative pair pushes only if it closes faster than its gap allows.

    The soft step keeps the walls only while every ball it moves travels less than SUBSTEP_TRAVEL of
    its radius per substep, and while nothing it did not foresee happens. A frame is tried with twice
    the substeps (at most RETRIES times) when some ball could travel farther before it starts, or
    when it is undone after it because (``verdict``):

    - a ball moved farther than that in a substep, or left the box its pairs were found from (then a
      pair the broad phase never saw could have met);
    - a solved contact overlapped deeper than DEEP_OVERLAP of the smaller radius at any substep's end;
    - a pair left out of the contacts that could have met overlaps that deep at the end.

    When no try holds, the step is split at impacts instead (split.py, which passes through nothing,
    however fast).
    """
    model, state, dt, now = step.model, step.state, step.dt, step.state.time
    radius = np.append(model.spheres.radius, np.inf)
    v, acc = state.body[:, V], motion.lin
    # each ball's speed and pull, and 0 for the static row N
    speed, pull = np.append(exact.norm_rows(v), 0.0), np.append(exact.norm_rows(acc), 0.0)
    contacts = collision.take()
    reach = (speed[contacts.a] + speed[contacts.b] + (pull[contacts.a] + pull[contacts.b]) * dt) * dt
    solved = (contacts.gap < step.touching + SPECULATIVE_REACH * reach) | (contacts.kind == SPHERE_PLANE)
    del reach
    c = contacts.subset(solved, without=("normal", "point"))
    # the normals laid out as (3, K) columns, which is how the solve reads them (jacobi.ContactColumns.n is
    # then this memory, not a copy of it), gathered a coordinate at a time (no (K, 3) copy on the way)
    idx = take_indices(solved)
    columns = np.empty((3, len(idx)))
    for r, into in enumerate(columns):
        into[:] = contacts.normal[idx, r]
    c.normal = columns.T
    del columns
    # the points of the pairs between balls are made again for the record (``_points``), not held
    # through the frame (24 bytes a contact); the rows of a moving plane read them (taken after the
    # normals: the order the settled pile's peak RSS was measured with, docs/benchmarks.md)
    c.point = contacts.point.take(idx, axis=0)
    plane_points = None if model.moving_planes() else c.point[c.kind == SPHERE_PLANE]
    if plane_points is not None:
        c.point = None
    del idx
    # the frame and its checks read the normals and points of the pairs it solves alone (``c`` has
    # them), and of the others, the pairs left out, only which bodies they join (found again from the
    # kept pairs, ``LeftOut``) and their gaps
    left = LeftOut(collision.pairs, ~solved, contacts.gap)
    del solved
    del contacts
    for substeps in [plan.substeps << k for k in range(RETRIES + 1)]:
        h = dt / substeps
        fast = speed * h + pull * h * h > SUBSTEP_TRAVEL * radius
        if fast[c.a].any() or fast[c.b].any():  # too fast for a substep: not worth a try
            continue
        last = substeps == plan.substeps << RETRIES
        frame = _try(step, motion, left, c, substeps, last, checkpoint)
        if frame is not None:
            break
    else:
        return False
    if plane_points is not None:
        c.point = _points(c, plane_points, checkpoint.state.body, model)
    step.events.add(now, c, c.keys(), frame.impulse)
    step.intervals += 1
    return True


class LeftOut:
    """The kept pairs a soft frame does not solve, with their gaps at its start: which of the
    narrow phase's contacts of ``pairs`` they are (``out``, a mask over them: a byte a pair) and their
    gaps, not their kinds and bodies (9 bytes a pair), which ``points`` takes from ``pairs`` again, in
    the order ``narrowphase.contact_points`` lays them out (sphere–plane pairs first)."""

    def __init__(self, pairs: KeptPairs, out: np.ndarray, gap: np.ndarray) -> None:
        self.pairs, self.out, self.gap = pairs, out, gap[out]

    def points(self) -> ContactPoints:
        """The pairs left out, as ``ContactPoints.gaps`` of their contacts: kind, a, other and gap."""
        p, planes = self.pairs, len(self.pairs.sphere)
        on_plane, between = self.out[:planes], self.out[planes:]
        index = p.pair_i.dtype
        plane_pairs = np.count_nonzero(on_plane)
        kind = np.full(plane_pairs + np.count_nonzero(between), SPHERE_SPHERE, np.int8)
        kind[:plane_pairs] = SPHERE_PLANE
        a = np.concatenate((p.sphere[on_plane], p.pair_i[between]), dtype=index)
        other = np.concatenate((p.plane[on_plane], p.pair_j[between]), dtype=index)
        return ContactPoints(kind, a, None, other, self.gap, None, None)


def _try(
    step: Step,
    motion: Motion,
    left: LeftOut,
    c: ContactPoints,
    substeps: int,
    last: bool,
    checkpoint: Checkpoint,
) -> softstep.Frame | None:
    """One try at the soft frame with ``substeps`` substeps: the frame, or None (everything undone to
    ``checkpoint``) when its ``verdict`` is not KEPT. The ``last`` try is kept when its only fault is a
    solved contact that overlapped DEEPER: that is no pass through anything, and splitting a heap of
    overlapping balls at impacts jumps them apart by positions."""
    model, state, dt = step.model, step.state, step.dt
    n = model.spheres.count
    frame = softstep.frame(
        model,
        state,
        c,
        motion.forces,
        dt,
        step.restitution_threshold,
        step.warm,
        substeps,
        step.profile,
        lambda: checkpoint.keep_balls(step.parts),
    )
    body_before = checkpoint.state.body  # the balls as the frame found them
    balls = frame.balls[frame.balls < n]
    others = np.ones(n, bool)
    others[balls] = False
    with step.profile.stage(Stage.ENERGY_GUARD):
        energy_guard.hold_frame(model, state, body_before, balls, dt)
    if others.any():  # balls touching nothing this frame fly on the world's integrator
        with step.profile.stage(Stage.INTEGRATE):
            rows = state.body[others]
            terms = forces_of(motion.forces, np.flatnonzero(others), n)
            integrate(model.integrator, rows, terms, dt, step.workspace)
            state.body[others] = rows
    moving_planes.advance(model, state, dt)
    with step.profile.stage(Stage.TIME_OF_IMPACT):
        found = verdict(step, motion, left, c, frame, body_before)
    if found is Verdict.KEPT or (last and found is Verdict.DEEPER):
        return frame
    checkpoint.restore(step.parts)  # undo it all
    return None


def verdict(
    step: Step,
    motion: Motion,
    left: LeftOut,
    c: ContactPoints,
    frame: softstep.Frame,
    before: np.ndarray,
) -> Verdict:
    """Whether a soft frame kept its promises (see ``frames``), or why it cannot be trusted.

    ``left`` are the kept pairs the frame did not solve (``c``), with their gaps at the frame's start
    (``LeftOut``), and ``before`` the balls' states then. A ball that left the box
    its pairs were found from may have met a body the broad phase never paired it with: the pairs are
    then found afresh around where the balls are now (they replace the kept pairs, as a split step's
    renewal does) and those new pairs are checked too."""
    model, state = step.model, step.state
    n = model.spheres.count
    radius = model.spheres.radius
    cols = frame.balls < n
    balls = frame.balls[cols]
    r = radius[balls]
    if (frame.largest_move[cols] > SUBSTEP_TRAVEL * r).any():
        return Verdict.MOVED_TOO_FAR
    smaller = np.where(c.b < n, np.minimum(radius[c.a], np.append(radius, 0.0)[c.b]), radius[c.a])
    if (frame.least_separation < np.minimum(c.gap, 0.0) - DEEP_OVERLAP * smaller).any():
        return Verdict.DEEPER
    # how far each ball got from where it started (the others flew straight)
    far = np.zeros(n + 1)
    moved = state.body[:, X] - before[:, X]
    far[:n] = exact.norm_rows(moved)
    far[balls] = np.maximum(far[balls], frame.farthest[cols])
    kept = step.pairs.kept
    lo, hi = frame.lo, frame.hi
    centre = kept.centre[balls].T
    corner = np.maximum(np.abs(lo - centre), np.abs(hi - centre))
    escaped = (
        (lo - r < kept.lo[balls].T).any()
        or (hi + r > kept.hi[balls].T).any()
        or (exact.norm_cols(corner) + r > kept.reach[balls]).any()
    )
    if escaped:  # pairs around where the balls are now; those not solved are the ones left out
        free, _ = free_acceleration(state.body, motion.forces)
        pairs = step.pairs.renew(model, state, step.dt, BROAD_PHASE_STEPS * step.dt, free, free, motion.awake)
        now = narrowphase.contact_points(model, state, pairs)
        out = now.subset(~_among(now.keys(), c.keys()))
        out.gap = _gap_from(out, before, model, state)
    else:
        out = left.points()
        b = np.where(out.kind == SPHERE_PLANE, n, out.other)
        near = far[out.a] + far[b] >= out.gap  # only those whose balls got farther than their gap
        out = out.subset(near)
        start = np.minimum(out.gap, 0.0)
        out.gap = _gap_from(out, before, model, state) - start
    if len(out) == 0:
        return Verdict.KEPT
    on_plane = out.kind == SPHERE_PLANE
    smaller = np.where(
        on_plane, radius[out.a], np.minimum(radius[out.a], radius[np.where(on_plane, 0, out.other)])
    )
    if (out.gap < -DEEP_OVERLAP * smaller).any():
        return Verdict.LEFT_OUT
    return Verdict.KEPT


def _among(keys: np.ndarray, of: np.ndarray) -> np.ndarray:
    """Which of ``keys`` are among the distinct pair keys ``of`` (``find_keys``: ``np.isin``'s answer at
    about half its cost)."""
    if len(of) == 0:
        return np.zeros(len(keys), bool)
    return find_keys(np.sort(of), keys)[0]


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
        side = np.where(exact.dot_rows(d, nrm) < 0.0, -1.0, 1.0)
        gap[on_plane] = geometry.sphere_plane(
            x, radius, s, p, side, pose.center, pose.normal, pose.axis_u, pose.axis_v, model.planes.half_size
        )[0]
    if (~on_plane).any():
        gap[~on_plane] = geometry.sphere_sphere(x, radius, c.a[~on_plane], c.other[~on_plane])[0]
    return gap


def _points(c: ContactPoints, plane_points: np.ndarray, before: np.ndarray, model: Model) -> np.ndarray:
    """The contacts' points as the narrow phase measured them from the balls ``before`` the frame: the
    plane contacts' as kept, each pair of balls' at the middle of its gap, x_j + n·(r_j + ½·gap), by the
    same operations as ``geometry.sphere_sphere``, SWEEP_CHUNK pairs at a time (the (chunk, 3)
    temporaries of a chunk, not of every pair: 72 bytes a contact each)."""
    on_plane = c.kind == SPHERE_PLANE
    point = np.empty((len(c), 3))
    point[on_plane] = plane_points
    pairs = np.flatnonzero(~on_plane)
    for lo in range(0, len(pairs), SWEEP_CHUNK):
        pair = pairs[lo : lo + SWEEP_CHUNK]
        j, gap = c.other[pair], c.gap[pair]
        xj = before[j, 0:3]
        point[pair] = xj + c.normal[pair] * (model.spheres.radius[j] + 0.5 * gap)[:, None]
    return point
