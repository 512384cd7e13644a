"""Mechanical energy over a run: one sample per step, for ``simulate --plot`` and ``compare``.

A sample is three floats read from ``World.kinetic_energy`` and ``World.potential_energy``, so
recording every step costs next to nothing beside the step itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics import World


@dataclass(frozen=True, eq=False)
class EnergyTrace:
    """Kinetic, potential and total energy (J) at the sampled times (s), as equal-length arrays."""

    time: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.potential

    @property
    def drift(self) -> np.ndarray:
        """Total energy minus its first sample (J)."""
        total = self.total
        return total - total[0] if len(total) else total

    def __len__(self) -> int:
        return len(self.time)


class EnergyRecorder:
    """Call it with the world before the first step and after every step; ``trace()`` gives the samples."""

    def __init__(self) -> None:
        self._time: list[float] = []
        self._kinetic: list[float] = []
        self._potential: list[float] = []

    def __call__(self, world: World) -> None:
        self._time.append(world.time)
        self._kinetic.append(world.kinetic_energy())
        self._potential.append(0.0 + world.potential_energy())  # 0.0 +: no '-0' without gravity

    def __len__(self) -> int:
        return len(self._time)

    def trace(self) -> EnergyTrace:
        return EnergyTrace(
            time=np.array(self._time, dtype=float),
            kinetic=np.array(self._kinetic, dtype=float),
            potential=np.array(self._potential, dtype=float),
        )
