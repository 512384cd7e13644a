"""The two ways of taking a step, built from the same stages.

- ``split_at_impacts``: the step is split at every impact, so balls meet exactly when they touch.
  Each interval finds the contacts, pushes overlapping balls apart, bounces the ones that arrive,
  solves the resting contacts for constant forces over the rest of the step, predicts the next
  impact and integrates to it. This is what gives e²·h apexes at 60 Hz and Newton's cradle.
- ``whole_with_speculative_contacts``: when many pairs may meet within one step (a pile landing),
  splitting it at each impact costs a pass over the world per impact. The step is taken whole instead
  (P. Firth, "Speculative contacts", 2011; as in Box2D v3 and Bullet): every pair that could meet
  joins the solves as a contact with a gap, which may close by at most that gap, v_n ≥ −gap/dt.

``crowded_contacts`` decides between them. Each strategy passes its targets to the stages explicitly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import impacts, moving_planes, narrowphase, penetration, resting, rows, toi
from .contacts import SPHERE_PLANE, ContactPoints, EventLog
from .forces import ForceTerm, free_acceleration
from .integrators import Workspace, integrate
from .model import Model
from .pairs import BROAD_PHASE_STEPS, CONTACT_SLOP, KeptPairs, PairCache
from .profile import StepProfile
from .state import State, V, with_static

# The pairs of a crowded step are those within this many times the distance they could close.
SPECULATIVE_REACH = 2.0
# A step is split at most this many times; past it the rest of the step is taken whole.
MAX_INTERVALS = 10_000


@dataclass
class Step:
    """What every stage of one step shares: the world's parts and this step's settings and outputs."""

    model: Model
    state: State
    pairs: PairCache
    warm: resting.WarmStart
    workspace: Workspace
    forces: list[ForceTerm]
    dt: float
    threshold: float  # restitution threshold (m/s)
    events: EventLog
    profile: StepProfile

    def integrate(self, push: ForceTerm | None, h: float) -> None:
        """Advance every ball by ``h`` under the force terms, plus the contact forces ``push``, and move
        the planes along with them."""
        with self.profile.stage("integrate"):
            terms = self.forces if push is None else [*self.forces, push]
            integrate(self.model.integrator, self.state.body, terms, h, self.workspace)
            moving_planes.advance(self.model, self.state, h)
        self.profile.intervals += 1


def crowded_contacts(step: Step, c: ContactPoints, accel: np.ndarray) -> ContactPoints | None:
    """The contacts of a crowded step, or None when few enough pairs meet to split the step.

    Meetings are counted along today's normals: the gap after dt, g + v_n·dt + ½·a_n·dt², falls to
    contact. More than ``model.crowd_limit`` meetings make the step crowded. Its contacts are every
    pair within SPECULATIVE_REACH times the distance it could close (by the same bound the time of
    impact uses), touching ones included.
    """
    dt, model = step.dt, step.model
    v, acc = with_static(step.state.body[:, V]), with_static(accel)
    dv, da = v[c.a] - v[c.b], acc[c.a] - acc[c.b]
    if model.moving_planes():  # relative to a moving plane's surface under the contact point
        on = c.kind == SPHERE_PLANE
        dv[on] -= moving_planes.surface_velocity(model, step.state, c.other[on], c.point[on])
    ahead = c.gap + np.einsum("ij,ij->i", dv * dt + 0.5 * dt * dt * da, c.normal)
    if np.count_nonzero((c.gap >= CONTACT_SLOP) & (ahead < CONTACT_SLOP)) <= model.crowd_limit:
        return None
    closing = model.integrator.closing_speed_bound(dv, da, dt) * dt
    return c.subset(c.gap < CONTACT_SLOP + SPECULATIVE_REACH * closing)


def split_at_impacts(step: Step, contacts: ContactPoints, pairs: KeptPairs,
                     accel: tuple[np.ndarray, np.ndarray]) -> None:  # fmt: skip
    """The step split at every impact, so balls meet exactly when they touch.

    ``contacts`` are the kept ``pairs`` measured at the step's start, and ``accel`` the free linear
    and angular accelerations there.
    """
    model, state, prof, dt = step.model, step.state, step.profile, step.dt
    free, ang = accel
    start, elapsed = state.time, 0.0
    while elapsed < dt:
        remaining, now = dt - elapsed, start + elapsed
        first = prof.intervals == 0
        if not first:
            with prof.stage("narrow phase"):
                contacts = narrowphase.contact_points(model, state, pairs)
        touching = contacts.subset(contacts.gap < CONTACT_SLOP)
        with prof.stage("contact rows"):
            batch = rows.contact_rows(model, state, touching)
        with prof.stage("penetration"):
            penetration.remove_penetration(state, touching, batch)
        no_allowance = np.zeros(len(touching))
        with prof.stage("impacts"):
            impacts.bounce(model, state, touching, batch, step.threshold, no_allowance, step.events, now,
                           arrivals_only=False)  # fmt: skip
        if not first or len(touching):  # velocities may have changed since the step began
            free, ang = free_acceleration(state.body, step.forces)
        with prof.stage("resting solve"):
            push = resting.resting_forces(model, state, touching, batch, free, ang, remaining, dt,
                                          no_allowance, step.warm, step.events, now)  # fmt: skip
        lin = free if push is None else free + push.lin
        # The first interval's free path was checked against the boxes when the pairs were taken; a
        # path bent by a bounce or a contact force may leave them, and then the pairs are found again
        # for the rest of this step and the next ones (they replace the kept pairs).
        with prof.stage("pairs"):
            if (not first or push is not None) and pairs.escaped(model, state, lin, remaining):
                ahead = remaining + (BROAD_PHASE_STEPS - 1) * dt
                pairs = step.pairs.renew(model, state, remaining, ahead, lin, free)
                contacts = narrowphase.contact_points(model, state, pairs)
        if prof.intervals + 1 < MAX_INTERVALS:
            with prof.stage("time of impact"):
                h = min(toi.next_impact(model, state, contacts, lin, remaining), remaining)
        else:  # a pathological pile-up: finish the step without splitting it further
            h = remaining
        step.integrate(push, h)
        step.events.close_interval(h / remaining)
        elapsed = dt if h >= remaining else elapsed + h


def whole_with_speculative_contacts(step: Step, c: ContactPoints) -> None:
    """The whole step as one interval, with speculative contacts ``c`` (from ``crowded_contacts``).

    A contact with a gap may close by at most that gap, v_n ≥ −gap/dt, and the constraint only pushes
    if the pair would otherwise pass it. A pair arriving faster than the bounce threshold leaves at e
    times its approach speed, as in a split step, but from where it was when the step began: a bounce
    is early by at most the gap it had left (≤ v·dt). Slower approaches start no bounce island; the
    resting forces stop them within the step. Pairs missed because a bounce turned a ball towards a
    ball it was not near overlap slightly; the next step's penetration removal and bounce deal with
    them, and its broad phase checks every path again.
    """
    model, state, prof, dt, now = step.model, step.state, step.profile, step.dt, step.state.time
    allowance = np.where(c.gap < CONTACT_SLOP, 0.0, c.gap / dt)  # how fast each may close (m/s)
    with prof.stage("contact rows"):
        batch = rows.contact_rows(model, state, c)
    with prof.stage("penetration"):
        penetration.remove_penetration(state, c, batch)
    with prof.stage("impacts"):
        impacts.bounce(model, state, c, batch, step.threshold, allowance, step.events, now,
                       arrivals_only=True)  # fmt: skip
    free, ang = free_acceleration(state.body, step.forces)
    with prof.stage("resting solve"):
        push = resting.resting_forces(model, state, c, batch, free, ang, dt, dt, -allowance, step.warm,
                                      step.events, now)  # fmt: skip
    step.integrate(push, dt)
    step.events.close_interval(1.0)
