"""The balls' free motion at a step's start, and the collide stage: the kept pairs and the narrow phase."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..collision import narrowphase
from ..collision.pairs import KeptPairs
from ..core.contacts import ContactPoints
from ..core.profile import Stage
from ..core.state import State
from ..dynamics import sleeping
from ..dynamics.forces import ForceTerm, free_acceleration
from ..dynamics.model import Model
from .context import Step


class Motion(NamedTuple):
    """The balls' free motion at the step's start, and the force terms that give it.

    ``forces`` are the model's terms, plus one that holds the sleeping balls still while some sleep;
    ``lin`` and ``ang`` the free linear and angular accelerations under them, ``unheld`` the linear
    ones had no ball been asleep (how far a sleeping ball would fall once woken), and ``awake`` which
    balls are awake (None: all of them).
    """

    forces: list[ForceTerm]
    lin: np.ndarray
    ang: np.ndarray
    unheld: np.ndarray
    awake: np.ndarray | None

    @staticmethod
    def of(model: Model, state: State) -> Motion:
        """The motion of the balls of ``state`` under ``model``'s force terms now."""
        forces = model.forces()
        sleep = state.sleep
        free, ang = free_acceleration(state.body, forces)
        if not sleep.any:
            return Motion(forces, free, ang, free, None)
        held = sleeping.hold(sleep, (free, ang))
        return Motion([*forces, held], free + held.lin, ang + held.ang, free, ~sleep.asleep)


class Collision:
    """What the collide stage measured: the kept ``pairs`` (those with an awake ball in them) and their
    ``contacts`` at the step's start.

    A soft frame takes the contacts over (``take``): it keeps the normals and points of the pairs it
    solves and lets go of the rest (56 bytes a kept pair, the peak memory of a settled pile), so no
    stage reads them after it; a step split at impacts after an undone frame measures them again."""

    def __init__(self, pairs: KeptPairs, contacts: ContactPoints) -> None:
        self.pairs = pairs
        self._contacts: ContactPoints | None = contacts

    @property
    def contacts(self) -> ContactPoints:
        """The contacts measured (until they are taken)."""
        if self._contacts is None:
            raise RuntimeError("the contacts were taken by a stage before this one")
        return self._contacts

    def take(self) -> ContactPoints:
        """The contacts, handed over: this collision no longer holds them."""
        contacts, self._contacts = self.contacts, None
        return contacts


def collide(step: Step, motion: Motion) -> Collision:
    """The kept pairs for the step (found again when a path leaves its box) with an awake ball in
    them, and their contacts measured now."""
    model, state = step.model, step.state
    with step.profile.stage(Stage.PAIRS):
        pairs = step.pairs.for_step(model, state, motion.lin, step.dt, motion.awake)
    with step.profile.stage(Stage.NARROW_PHASE):
        contacts = narrowphase.contact_points(model, state, pairs)
    return Collision(pairs, contacts)


def measure(step: Step, pairs: KeptPairs) -> ContactPoints:
    """The contacts of ``pairs`` at the current positions (the narrow phase, timed)."""
    with step.profile.stage(Stage.NARROW_PHASE):
        return narrowphase.contact_points(step.model, step.state, pairs)
