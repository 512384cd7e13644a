"""A World frozen at one moment: what ``World.snapshot`` returns and ``World.restore`` puts back."""

from __future__ import annotations

from dataclasses import dataclass

from .model import Model
from .pairs import PairCache
from .resting import WarmStart
from .state import State


@dataclass(frozen=True)
class Snapshot:
    """Everything a World's future depends on, frozen at one moment (``World.snapshot``)."""

    model: Model
    state: State
    pairs: PairCache
    warm: WarmStart
    crowded_steps: int
