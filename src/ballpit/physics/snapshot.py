"""A World frozen at one moment: what ``World.snapshot`` returns and ``World.restore`` puts back."""

from __future__ import annotations

from dataclasses import dataclass

from .core.state import SavedState
from .dynamics.model import Model
from .step.checkpoint import Checkpoint


@dataclass(frozen=True)
class Snapshot:
    """Everything a World's future depends on, frozen at one moment (``World.snapshot``): its model and
    a deep copy of the checkpoint of its parts."""

    model: Model
    checkpoint: Checkpoint
    crowded_steps: int

    @property
    def state(self) -> SavedState:
        """The state as it was: the balls' (N, 13) block, the planes' poses, the time, sleep."""
        return self.checkpoint.state
