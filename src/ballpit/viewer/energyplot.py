"""The energy trace the panel's plot (P) draws: kinetic, potential and total energy over the last
``WINDOW_SECONDS``, one total per integrator with ghosts on.

``EnergyWindow`` keeps one sample per frame (stepping back in the history cuts the samples after the
present). No GL here.
"""

from __future__ import annotations

from collections import deque

import numpy as np

WINDOW_SECONDS = 10.0
# Kinetic and potential energy: pink and lavender, apart from every integrator's colour (red, orange,
# blue, green: physics/integrators.py), which the totals take.
KINETIC_COLOR = (1.0, 0.5, 0.9, 1.0)
POTENTIAL_COLOR = (0.72, 0.62, 1.0, 1.0)


class EnergyWindow:
    """Samples (time, kinetic, potential, total per integrator) over the last ``window`` seconds."""

    def __init__(self, window: float = WINDOW_SECONDS) -> None:
        self.window = window
        self.samples: deque[tuple[float, float, float, dict[str, float]]] = deque()

    def clear(self) -> None:
        self.samples.clear()

    def add(self, time: float, kinetic: float, potential: float, totals: dict[str, float]) -> None:
        """Add a sample at simulated ``time``; samples later than it (after stepping back) are dropped."""
        while self.samples and self.samples[-1][0] >= time:
            self.samples.pop()
        self.samples.append((time, kinetic, potential, dict(totals)))
        while self.samples and self.samples[0][0] < time - self.window:
            self.samples.popleft()

    def fill(self, time: float, totals: dict[str, float]) -> None:
        """Totals that came later for the sample at simulated ``time`` (the ghosts stepped elsewhere);
        nothing when no sample is at that time. A total the sample has already is kept (an edit at
        that time came after the sample was taken)."""
        for sample in reversed(self.samples):
            if abs(sample[0] - time) <= 1e-9:
                for name, total in totals.items():
                    sample[3].setdefault(name, total)
                return
            if sample[0] < time:
                return

    def series(self) -> dict[str, np.ndarray]:
        """``time``, ``kinetic``, ``potential`` and ``total <integrator>`` arrays (NaN where missing)."""
        if not self.samples:
            return {}
        out = {
            "time": np.array([s[0] for s in self.samples]),
            "kinetic": np.array([s[1] for s in self.samples]),
            "potential": np.array([s[2] for s in self.samples]),
        }
        names: list[str] = []
        for s in self.samples:
            names.extend(n for n in s[3] if n not in names)
        for name in names:
            out[f"total {name}"] = np.array([s[3].get(name, np.nan) for s in self.samples])
        return out
