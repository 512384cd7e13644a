"""A step as a pipeline of typed stages (docs/architecture.md draws it; ``World.step`` reads as it):

    prepare -> (at rest: rest) -> wake -> plan -> solve (soft frames, retried; else split at impacts)
        -> struck -> settle -> finish

- ``prepare``: refuse what cannot be stepped; the step's settings and outputs (``Step``).
- ``at_rest`` (sleep.py): every ball asleep and nothing moved them; then ``rest`` only advances the time.
- ``wake`` (sleep.py): wake what was moved by hand, collide (collide.py: the kept pairs and the
  narrow phase), wake the islands the awake balls reach and collide again.
- ``plan`` (plan.py): the crowd test, split at impacts or a soft frame of n substeps.
- ``solve``: the soft frame (soft.py, softstep.py), tried with more substeps while it cannot keep its
  promises, else the step split at every impact (split.py).
- ``struck`` (sleep.py): an impulse that reached a sleeping ball (met by a path no contact foresaw)
  sends ``World.step`` back to the checkpoint, with that ball's island awake, to take the step again.
- ``settle`` (sleep.py): still islands fall asleep.
- ``finish``: undo a step that made anything non-finite; the time, the record and the profile.

Each stage takes what it reads and returns what it makes; the world's parts it changes (state, kept
pairs, warm start: ``checkpoint.Parts``) are the ``Step``'s. The one undo of a step is a
``checkpoint.Checkpoint`` of them taken before the solve: a soft frame's retry and a non-finite step's
undo both restore it.
"""

from __future__ import annotations

from time import perf_counter
from typing import NamedTuple

from ..core import steppable, validation
from ..core.contacts import ContactRecord, EventLog
from ..core.profile import StepProfile
from ..dynamics.integrators import Workspace
from ..dynamics.model import Model
from . import soft, split
from .checkpoint import Checkpoint, Parts
from .collide import measure
from .context import Step
from .plan import Plan, Strategy, plan
from .sleep import Awake, at_rest, settle, struck, wake

__all__ = [
    "Awake",
    "Plan",
    "Step",
    "Strategy",
    "Taken",
    "at_rest",
    "finish",
    "plan",
    "prepare",
    "rest",
    "settle",
    "solve",
    "struck",
    "take",
    "wake",
]


def prepare(
    model: Model,
    parts: Parts,
    workspace: Workspace,
    dt: float,
    good_planes: steppable.PlanesAsStepped | None,
    good_balls: steppable.LastGoodBalls | None = None,
) -> Step:
    """The step's context, once it is sure the engine can step the world: ValueError naming what it
    cannot (a bad plane value is put back to ``good_planes``, the columns as the last step left them)."""
    dt = validation.timestep(dt)
    began = perf_counter()
    state = parts.state
    steppable.reject_unsteppable_state(state.body, good_balls)
    planes = steppable.reject_bad_planes(model.planes, state.planes, good_planes)
    threshold, touching = model.restitution_threshold_for(dt), model.contact_slop()
    return Step(model, parts, workspace, dt, threshold, touching, EventLog(), StepProfile(), began, planes)


def solve(step: Step, awake: Awake, chosen: Plan, checkpoint: Checkpoint) -> Strategy:
    """Take the step as ``chosen``: a soft frame (undone to ``checkpoint`` and tried with more substeps
    while it cannot keep its promises) or, when it is split or no try held, split at every impact.
    Returns how it was taken."""
    collision = awake.collision
    if chosen.strategy is Strategy.SOFT:
        taken = soft.frames(step, awake.motion, collision, chosen, checkpoint)
        checkpoint.keep_balls(step.parts)  # before anything after the solve changes the balls
        if taken:
            return Strategy.SOFT
        contacts = measure(step, collision.pairs)  # the frame took the contacts: the same again
    else:
        checkpoint.keep_balls(step.parts)
        contacts = collision.take()
    split.split_at_impacts(step, awake.motion, contacts, collision.pairs)
    return Strategy.SPLIT


class Taken(NamedTuple):
    """A step solved (``take``): the step as last taken, what woke, its plan, its undo, how it went."""

    step: Step
    awake: Awake
    plan: Plan
    checkpoint: Checkpoint
    strategy: Strategy


def take(step: Step) -> Taken:
    """wake -> plan -> checkpoint -> solve; while the solve's impulses reached a sleeping ball (held
    as a wall, it took no momentum: ``struck``), back to the checkpoint with that ball's island awake,
    and the step taken again from its start. Each retry wakes at least one island, so it ends."""
    while True:
        awake = wake(step)
        chosen = plan(step, awake.collision, awake.motion)
        checkpoint = Checkpoint.of(step.parts, balls_later=True)  # the one undo (balls: when changed)
        strategy = solve(step, awake, chosen, checkpoint)
        hit = struck(step)
        if hit is None:
            return Taken(step, awake, chosen, checkpoint, strategy)
        checkpoint.restore(step.parts)
        step.state.sleep.wake(hit)
        step = step.again()


def rest(step: Step) -> ContactRecord:
    """The step of a world at rest (``at_rest``): only the time advances; no contact is resolved."""
    step.state.time += step.dt
    record = step.events.record()
    prof = step.profile
    prof.intervals, prof.pairs, prof.contacts, prof.crowded = 0, 0, 0, False
    prof.total = perf_counter() - step.began
    return record


def finish(step: Step, checkpoint: Checkpoint, chosen: Plan, pairs: int) -> ContactRecord:
    """Undo a step that made anything non-finite (or beyond what the engine can step): every part back
    to ``checkpoint``, and raise. Else advance the time, and return the contacts resolved with the
    profile filled in."""
    fault = steppable.step_fault(step.state.body)
    if fault is not None:
        checkpoint.restore(step.parts)
        raise fault
    step.state.time += step.dt
    record = step.events.record()
    prof = step.profile
    prof.intervals, prof.pairs, prof.contacts = step.intervals, pairs, len(record)
    prof.crowded = chosen.strategy is Strategy.SOFT
    prof.total = perf_counter() - step.began
    return record
