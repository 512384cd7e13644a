"""The two ways of taking a step, built from the same stages.

- ``split_at_impacts``: the step is split at every impact, so balls meet exactly when they touch.
  Each interval finds the contacts, pushes overlapping balls apart, bounces the ones that arrive,
  solves the resting contacts for constant forces over the rest of the step, predicts the next
  impact and integrates to it. This is what gives e²·h apexes at 60 Hz and Newton's cradle.
- ``whole_with_speculative_contacts``: when many pairs may meet within one step (a pile landing),
  splitting it at each impact costs a pass over the world per impact. The step is taken whole instead
  (P. Firth, "Speculative contacts", 2011; as in Box2D v3 and Bullet): every pair that could meet
  joins the solves as a contact with a gap, which may close by at most that gap, v_n ≥ −gap/dt.

``crowded_contacts`` decides between them. Each strategy passes the restitution threshold and each
contact's minimum normal speed (v_n ≥ min_normal_speed: 0 touching, −gap/dt speculative) to the
stages explicitly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import impacts, moving_planes, narrowphase, penetration, resting, rows, toi
from .contacts import SPHERE_PLANE, ContactPoints, EventLog
from .forces import ConstantPerBall, ForceTerm, free_acceleration
from .integrators import Workspace, integrate
from .model import Model
from .pairs import KeptPairs, PairCache, contact_slop
from .profile import StepProfile
from .settings import (
    BROAD_PHASE_STEPS,
    CONTACT_SLOP,
    CROWD_PAIRS,
    MAX_INTERVALS,
    SPECULATIVE_REACH,
    UNGUARDED_OVERLAP,
)
from .state import State, V, W, with_static


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

    def integrate(self, push: ForceTerm | None, h: float) -> None:
        """Advance every ball by ``h`` under the force terms, plus the contact forces ``push``, and move
        the planes along with them."""
        with self.profile.stage("integrate"):
            terms = self.forces if push is None else [*self.forces, push]
            integrate(self.model.integrator, self.state.body, terms, h, self.workspace)
            moving_planes.advance(self.model, self.state, h)
        self.intervals += 1


def crowded_contacts(step: Step, c: ContactPoints, accel: np.ndarray) -> np.ndarray | None:
    """Which of the contacts ``c`` a crowded step solves (a mask), or None when few enough pairs meet
    to split the step.

    Meetings are counted along today's normals: the gap after dt, g + v_n·dt + ½·a_n·dt², falls to
    contact. More than ``model.crowd_limit`` meetings make the step crowded. Its contacts are every
    pair within SPECULATIVE_REACH times the distance it could close (by the same bound the time of
    impact uses), touching ones included.
    """
    dt, model = step.dt, step.model
    many = len(c) >= CROWD_PAIRS and model.crowd_limit != np.inf  # inf: always split at impacts
    if len(c) == 0 or (not many and len(c) <= model.crowd_limit):  # too few pairs to be more meetings
        return None
    dv, da = _relative_motion(step, c, accel)
    ahead = c.gap + np.einsum("ij,ij->i", dv * dt + 0.5 * dt * dt * da, c.normal)
    meetings = np.count_nonzero((c.gap >= CONTACT_SLOP) & (ahead < CONTACT_SLOP))
    if meetings <= (0 if many else model.crowd_limit):
        return None
    return speculative_reach(step, c, accel, dv, da)


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
            penetration.remove_penetration(model, state, touching, batch)
        min_normal_speed = np.zeros(len(touching))  # touching contacts may not close at all
        with prof.stage("impacts"):  # arrivals bounce in waves; then slower approaches stop
            impacts.in_waves(model, state, touching, batch, step.restitution_threshold, min_normal_speed,
                             step.events, now)  # fmt: skip
            impacts.stop_approaches(model, state, touching, batch, min_normal_speed, step.events, now)
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
            if (not first or push is not None) and pairs.escaped(model, state, lin, remaining):
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


def whole_with_speculative_contacts(step: Step, contacts: ContactPoints, pairs: KeptPairs,
                                    solved: np.ndarray) -> None:  # fmt: skip
    """The whole step as one interval, with speculative contacts: those of ``contacts`` (all the kept
    ``pairs`` measured now) where ``solved`` holds (from ``crowded_contacts``).

    A contact with a gap may close by at most that gap: its minimum normal speed is −gap/dt, and the
    constraint only pushes if the pair would otherwise pass it. A pair arriving faster than the
    restitution threshold leaves at e times its approach speed, as in a split step, but from where it
    was when the step began: a bounce is early by at most the gap it had left (≤ v·dt). Slower
    approaches start no bounce island; the resting forces stop them within the step.

    A bounce can turn a ball towards a body it was not near, whose pair is not among ``c``. Before
    moving, every such pair is followed along the new paths; if one would overlap by more than
    UNGUARDED_OVERLAP of a radius within the step, the step goes only as far as its impact and the rest
    of it is split at impacts. So nothing passes through a plane or a ball, however hard it was hit;
    shallower overlaps are removed at the next step's start.
    """
    model, state, prof, dt, now = step.model, step.state, step.profile, step.dt, step.state.time
    c = contacts.subset(solved)
    min_normal_speed = np.where(c.gap < CONTACT_SLOP, 0.0, -c.gap / dt)  # each may close by its gap (m/s)
    with prof.stage("contact rows"):
        batch = rows.contact_rows(model, state, c)
    with prof.stage("penetration"):
        penetration.remove_penetration(model, state, c, batch)
    with prof.stage("impacts"):
        impacts.bounce(model, state, c, batch, step.restitution_threshold, min_normal_speed, step.events, now,
                       arrivals_only=True, jacobi_from=0)  # fmt: skip
    free, ang = free_acceleration(state.body, step.forces)
    # The bounces turned some balls towards neighbours they were not closing on before: those pairs
    # join the speculative contacts, and bounce in turn if they now arrive.
    with prof.stage("crowd test"):
        joined = speculative_reach(step, contacts, free) & ~solved
    if joined.any():
        solved = solved | joined
        new = np.r_[np.zeros(len(c), bool), np.ones(np.count_nonzero(joined), bool)]
        c = ContactPoints.concatenate([c, contacts.subset(joined)])
        min_normal_speed = np.where(c.gap < CONTACT_SLOP, 0.0, -c.gap / dt)
        with prof.stage("contact rows"):
            batch = rows.contact_rows(model, state, c)
        # Only the joined pairs start islands: a contact the first pass bounced and that still closes
        # is caught between neighbours bouncing too, and the resting solve stops it.
        with prof.stage("impacts"):
            impacts.bounce(model, state, c, batch, step.restitution_threshold, min_normal_speed,
                           step.events, now, arrivals_only=True, seeds_among=new, jacobi_from=0)  # fmt: skip
        free, ang = free_acceleration(state.body, step.forces)
    with prof.stage("resting solve"):
        push = resting.resting_forces(model, state, c, batch, free, ang, dt, dt, min_normal_speed,
                                      step.warm, step.events, now, jacobi_from=0)  # fmt: skip
    lin = free if push is None else free + push.lin
    with prof.stage("pairs"):
        if pairs.escaped(model, state, lin, dt):
            pairs = step.pairs.renew(model, state, dt, BROAD_PHASE_STEPS * dt, lin, free)
            contacts = narrowphase.contact_points(model, state, pairs)
            solved = np.isin(contacts.keys(), c.keys())
        else:  # the same pairs, where penetration removal left them
            contacts = narrowphase.contact_points(model, state, pairs)
        unguarded = contacts.subset(~solved)
    with prof.stage("time of impact"):
        deep = toi.deep_overlaps(model, state, unguarded, lin, dt, UNGUARDED_OVERLAP)
        h = toi.next_impact(model, state, unguarded.subset(deep), lin, dt) if deep.any() else np.inf
    if h >= dt:
        step.integrate(push, dt)
        step.events.close_interval(1.0)
        return
    step.integrate(push, h)
    step.events.close_interval(h / dt)
    # the rest of the step, split at impacts (its first interval measures the contacts afresh)
    split_at_impacts(step, contacts, pairs, (free, ang), elapsed=h)
