"""One transaction for everything a step changes.

``Parts`` are what a ``World.step`` changes: the state (the balls, the planes' poses, the time, the
sleep bookkeeping) and the two caches that change results (the kept pairs, the warm start). A
``Checkpoint`` holds each part as it was at one moment, and puts them all back:

- a soft frame that cannot keep its promises is undone to the checkpoint its step took before it
  began, and tried again (step/soft.py);
- a step that made anything non-finite is undone to the same checkpoint (step/__init__.py: finish);
- ``World.snapshot`` is a deep copy of a checkpoint (and of the model, which a step only reads).

A part is anything with ``checkpoint()`` (what it needs to be put back, sharing only what is never
changed in place) and ``restore(saved)``; a cache added to the World is added as a field of ``Parts``,
so every undo and every snapshot carries it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..collision.pairs import PairCache
from ..contact.warm_start import WarmStart
from ..core.state import SavedState, State


@dataclass
class Parts:
    """What a step changes, part by part."""

    state: State
    pairs: PairCache
    warm: WarmStart

    @staticmethod
    def new() -> Parts:
        """An empty world's parts."""
        return Parts(State(), PairCache(), WarmStart())


_PARTS = tuple(f.name for f in fields(Parts))


@dataclass(frozen=True)
class Checkpoint:
    """Every part of a world as it was at one moment: ``saved`` holds each part's ``checkpoint()`` by
    its name in ``Parts``."""

    saved: dict[str, object]

    @staticmethod
    def of(parts: Parts, balls_later: bool = False) -> Checkpoint:
        """The parts as they are now. With ``balls_later`` the balls' block is copied only by
        ``keep_balls``, which whatever changes the balls calls first: a soft frame solves on columns of
        its own and writes the balls back at its end, so while it solves the block is held once, not
        twice (104 bytes a ball)."""
        saved = {name: getattr(parts, name).checkpoint() for name in _PARTS if name != "state"}
        saved["state"] = parts.state.checkpoint(balls=not balls_later)
        return Checkpoint(saved)

    def keep_balls(self, parts: Parts) -> np.ndarray:
        """Copy the balls' block of ``parts`` into this checkpoint, if it was taken without it
        (``balls_later``): to be called before the balls first change. Returns the checkpoint's block
        (read only: the balls as they were)."""
        saved = self.saved["state"]
        if saved.body is None:
            saved = self.saved["state"] = saved._replace(body=parts.state.body.copy())
        return saved.body

    @property
    def state(self) -> SavedState:
        """The state as it was: the balls' (N, 13) block, the planes' poses, the time, sleep."""
        saved = self.saved["state"]
        if saved.body is None:
            raise RuntimeError("the checkpoint's balls are copied when they first change (keep_balls)")
        return saved

    def restore(self, parts: Parts) -> None:
        """Put every part back as it was (the checkpoint stays usable: it can be restored again)."""
        for name in _PARTS:
            getattr(parts, name).restore(self.saved[name])
