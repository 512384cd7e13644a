"""A step split at every impact, so balls meet exactly when they touch.

Each interval finds the contacts, pushes overlapping balls apart, bounces the ones that arrive,
solves the resting contacts for constant forces over the rest of the step, predicts the next impact
and integrates to it. This is what gives e²·h apexes at 60 Hz and Newton's cradle. Each stage is
given the restitution threshold and each contact's minimum normal speed (v_n ≥ min_normal_speed: 0
touching) explicitly.
"""

from __future__ import annotations

import numpy as np

from ..collision import narrowphase, toi
from ..collision.pairs import KeptPairs
from ..contact import energy_guard, impacts, penetration, resting, rows
from ..core.contacts import ContactPoints
from ..core.profile import Stage
from ..core.settings import BROAD_PHASE_STEPS, MAX_INTERVALS
from ..core.state import V, W
from ..dynamics.forces import ConstantPerBall, ForceTerm, free_acceleration
from .collide import Motion, measure
from .context import Step, integrate_interval


def split_at_impacts(step: Step, motion: Motion, contacts: ContactPoints, pairs: KeptPairs) -> None:
    """The step split at every impact.

    ``contacts`` are the kept ``pairs`` measured now, and ``motion`` the balls' free motion now.
    """
    model, state, prof, dt = step.model, step.state, step.profile, step.dt
    forces, free, ang = motion.forces, motion.lin, motion.ang
    start, elapsed = state.time, 0.0
    while elapsed < dt:
        remaining, now = dt - elapsed, start + elapsed
        first = step.intervals == 0
        if not first:
            contacts = measure(step, pairs)
        touching = contacts.subset(contacts.gap < step.touching)
        moved, push = False, None
        if len(touching):  # else nothing to push apart, bounce, stop or hold: those stages are skipped
            with prof.stage(Stage.CONTACT_ROWS):
                batch = rows.contact_rows(model, state, touching)
            with prof.stage(Stage.PENETRATION):
                moved = penetration.remove_penetration(model, state, touching, batch)
            if moved:  # the interval is planned from where the balls are now, not where they overlapped
                contacts, touching, batch, pairs = _measure_again(
                    step, motion, pairs, free, remaining, touching
                )
            min_normal_speed = np.zeros(len(touching))  # touching contacts may not close at all
            with prof.stage(Stage.IMPACTS):  # arrivals bounce in waves; then slower approaches stop
                impacts.in_waves(
                    model,
                    state,
                    touching,
                    batch,
                    step.restitution_threshold,
                    min_normal_speed,
                    step.events,
                    now,
                )
                impacts.stop_approaches(
                    model, state, touching, batch, min_normal_speed, step.events, now, interval=remaining
                )
            # a separating contact is held where it is, not brought to rest (no work)
            min_normal_speed = resting.workless_targets(batch, state, model.integrator.bend)
        if not first or len(touching):  # velocities may have changed since the step began
            free, ang = free_acceleration(state.body, forces)
        if len(touching):
            with prof.stage(Stage.RESTING_SOLVE):
                push = resting.resting_forces(
                    model,
                    state,
                    touching,
                    batch,
                    free,
                    ang,
                    remaining,
                    dt,
                    min_normal_speed,
                    step.warm,
                    step.events,
                    now,
                )
        lin = free if push is None else free + push.lin
        # The first interval's free path was checked against the boxes when the pairs were taken; a
        # path bent by a bounce or a contact force may leave them, and then the pairs are found again
        # for the rest of this step and the next ones (they replace the kept pairs).
        with prof.stage(Stage.PAIRS):
            if (not first or push is not None or moved) and pairs.escaped(model, state, lin, remaining):
                ahead = remaining + (BROAD_PHASE_STEPS - 1) * dt
                pairs = step.pairs.renew(model, state, remaining, ahead, lin, free, motion.awake)
                contacts = narrowphase.contact_points(model, state, pairs)
        if step.intervals + 1 >= MAX_INTERVALS:  # a pathological pile-up: no more splitting
            finish_conservatively(step, motion, contacts, push, lin, remaining)
            step.events.close_interval(1.0)
            return
        with prof.stage(Stage.TIME_OF_IMPACT):
            h = min(toi.next_impact(model, state, contacts, lin, remaining), remaining)
        _integrate(step, forces, push, h)
        step.events.close_interval(h / remaining)
        elapsed = dt if h >= remaining else elapsed + h


def _integrate(step: Step, forces: list[ForceTerm], push: ConstantPerBall | None, h: float) -> None:
    """``integrate_interval``, the energy the contact forces ``push`` added paid back out of the pushed
    balls' speed (``energy_guard.keep_interval``)."""
    if push is None:
        integrate_interval(step, forces, push, h)
        return
    pushed = np.flatnonzero((push.lin != 0.0).any(axis=1) | (push.ang != 0.0).any(axis=1))
    before = step.state.body[pushed]
    integrate_interval(step, forces, push, h)
    energy_guard.keep_interval(step.model, step.state, pushed, before)


def _measure_again(
    step: Step,
    motion: Motion,
    pairs: KeptPairs,
    free: np.ndarray,
    remaining: float,
    touching: ContactPoints,
) -> tuple[ContactPoints, ContactPoints, rows.ContactRows, KeptPairs]:
    """After the push-apart moved balls: the kept pairs measured again (found again first if a ball was
    moved out of the box they were found from), the ``touching`` contacts and their rows with the
    pairs the move brought into contact added after them.

    A ball pushed out of an overlap may now touch a wall it was far from (a small ball inside a big
    one beside a wall is pushed to it): planned from the gaps measured before the move, the interval
    would let it fly on through that wall. The contacts that touched before the move stay as they were
    measured, so a move that brings nothing new into contact solves what it solved before."""
    model, state, prof = step.model, step.state, step.profile
    with prof.stage(Stage.PAIRS):
        if pairs.escaped(model, state, free, remaining):
            ahead = remaining + (BROAD_PHASE_STEPS - 1) * step.dt
            pairs = step.pairs.renew(model, state, remaining, ahead, free, free, motion.awake)
    contacts = measure(step, pairs)
    met = (contacts.gap < step.touching) & ~np.isin(contacts.keys(), touching.keys())
    if np.count_nonzero(met):
        touching = ContactPoints.concatenate([touching, contacts.subset(met)])
    with prof.stage(Stage.CONTACT_ROWS):
        batch = rows.contact_rows(model, state, touching)
    return contacts, touching, batch, pairs


def finish_conservatively(
    step: Step,
    motion: Motion,
    contacts: ContactPoints,
    push: ConstantPerBall | None,
    lin: np.ndarray,
    remaining: float,
) -> None:
    """Take the rest of a step that ran out of intervals in one go, passing through nothing: every
    ball that could reach anything in that time stops where it is (velocity and spin zero, its
    forces balanced), and the others, which cannot, move on."""
    model, state = step.model, step.state
    with step.profile.stage(Stage.TIME_OF_IMPACT):
        stop = toi.threatened(model, state, contacts, lin, remaining)
    body = state.body
    body[stop, V] = 0.0
    body[stop, W] = 0.0
    free, ang = free_acceleration(body, motion.forces)
    held_lin = free if push is None else free + push.lin
    held_ang = ang if push is None else ang + push.ang
    hold = ConstantPerBall(np.where(stop[:, None], -held_lin, 0.0), np.where(stop[:, None], -held_ang, 0.0))
    if push is not None:
        hold = ConstantPerBall(hold.lin + push.lin, hold.ang + push.ang)
    integrate_interval(step, motion.forces, hold, remaining)
