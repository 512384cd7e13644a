"""The sleep stages of a step (the rules are sleeping.py's): ``at_rest``, whether the whole world sleeps
and the step has nothing to do; ``wake`` before the solve, with its loop of waking what the awake balls
reach and measuring again; and ``settle`` after it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.profile import Stage
from ..dynamics import sleeping
from .collide import Collision, Motion, collide
from .context import Step
from .plan import speculative_reach


@dataclass
class Awake:
    """What the wake stage leaves for the step: the balls' free ``motion``, the ``collision`` measured
    with every island that will move this step awake, and the ball–ball pairs that join islands
    (``sleeping.links``; None when no ball sleeps or may fall asleep at the step's end)."""

    motion: Motion
    collision: Collision
    links: tuple[np.ndarray, np.ndarray] | None


def wake(step: Step) -> Awake:
    """Wake what was moved or set moving by hand, collide, then wake the islands the awake balls touch
    or could reach within the step and collide again with them awake; the woken islands' pairs get back
    the warm start put aside when they fell asleep.

    Pairs within reach (sleeping balls counted as falling, as they will once awake) join islands, so
    the reach is needed only while some ball sleeps or may fall asleep at the end of this step.
    """
    model, state, prof = step.model, step.state, step.profile
    sleep = state.sleep
    with prof.stage(Stage.SLEEP):
        sleeping.before_step(model, state, sleep, model.sleep)
    motion = Motion.of(model, state)
    collision = collide(step, motion)
    links = None
    if model.sleep and (sleep.any or sleeping.may_fall_asleep(sleep, step.dt)):
        with prof.stage(Stage.SLEEP):
            reach = speculative_reach(step, collision.contacts, motion.unheld)
            woken = sleeping.reached(collision.contacts, sleep.asleep, reach) if sleep.any else None
        if woken is not None and woken.any():
            sleep.wake(woken)
            motion = Motion.of(model, state)
            collision = collide(step, motion)
            with prof.stage(Stage.SLEEP):
                reach = speculative_reach(step, collision.contacts, motion.unheld)
        with prof.stage(Stage.SLEEP):
            links = sleeping.links(collision.contacts, reach, step.touching)
    if model.sleep and len(step.warm.asleep[0]):
        with prof.stage(Stage.SLEEP):
            step.warm.wake(sleep.asleep)  # the pairs of woken islands start from what they held
    return Awake(motion, collision, links)


def at_rest(step: Step) -> bool:
    """Every ball asleep, none moved or set moving by hand since, no plane moving: the step would hold
    each ball where it fell asleep and measure no pair, so it would change nothing but the time (a
    settled scene's every step; slopes.toml's cost 0.45 ms each). Runs ``wake``'s first check, so what
    was moved by hand wakes here as it would there."""
    model, state = step.model, step.state
    sleep = state.sleep
    if not model.sleep or not sleep.any or model.moving_planes():
        return False
    with step.profile.stage(Stage.SLEEP):
        sleeping.before_step(model, state, sleep, model.sleep)
    return bool(sleep.asleep.all())


def struck(step: Step) -> np.ndarray | None:
    """The sleeping balls a contact impulse reached in the step just solved (a mask), or None.

    Only the islands an awake ball touches or could reach at the step's start are woken, so these were
    met by a path no contact foresaw (a ball bounced towards them inside the step). Solved as fixed
    walls (a sleeping ball has no inverse mass), they took no momentum: their islands are woken and
    the step solved again from its start."""
    sleep = step.state.sleep
    if not sleep.any:
        return None
    hit = step.events.balls_reached(sleep.asleep)
    return hit if hit.any() else None


def settle(step: Step, awake: Awake) -> None:
    """Still islands fall asleep (their pairs' warm start put aside); a sleeping ball the step left
    moving wakes."""
    model, state, sleep = step.model, step.state, step.state.sleep
    if not model.sleep:
        return
    with step.profile.stage(Stage.SLEEP):
        was = sleep.asleep.copy() if sleep.any or sleeping.may_fall_asleep(sleep, step.dt) else None
        sleeping.after_step(model, state, sleep, awake.links, step.dt)
        if was is not None and (sleep.asleep & ~was).any():
            step.warm.put_to_sleep(sleep.asleep)
