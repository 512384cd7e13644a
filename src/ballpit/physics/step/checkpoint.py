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

from ..collision.pairs import PairCache
from ..contact.resting import WarmStart
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
    def of(parts: Parts) -> Checkpoint:
        """The parts as they are now."""
        return Checkpoint({name: getattr(parts, name).checkpoint() for name in _PARTS})

    @property
    def state(self) -> SavedState:
        """The state as it was: the balls' (N, 13) block, the planes' poses, the time, sleep."""
        return self.saved["state"]

    def restore(self, parts: Parts) -> None:
        """Put every part back as it was (the checkpoint stays usable: it can be restored again)."""
        for name in _PARTS:
            getattr(parts, name).restore(self.saved[name])
