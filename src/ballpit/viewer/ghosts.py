"""Integrator ghosts (G): the same scene stepped in lockstep under every other registered integrator.

Each ghost is a ``World.copy()`` of the run at a common origin (the drop, when it can catch up from
there quickly; else the moment G was pressed) with its ``integrator`` set, and keeps its own History so
it follows the main run when you step back or scrub. Energy drift is measured from the total energy at
that origin, the same reference for the main run and every ghost. No GL here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..physics.dynamics.integrators import INTEGRATORS as REGISTRY
from .history import History

INTEGRATORS = tuple(REGISTRY)
LABELS = {name: integrator.label for name, integrator in REGISTRY.items()}
# Ghost tint per integrator (sRGB, its registered colour): what the HUD legend and the energy plot use too.
TINTS = {name: integrator.rgb for name, integrator in REGISTRY.items()}
GHOST_ALPHA = 0.38
CATCH_UP_STEPS = 720  # at most this many steps of re-running from the drop when G is pressed


def total_energy(world: Any) -> float:
    return float(world.kinetic_energy() + world.potential_energy())


def drift_percent(energy: float, reference: float) -> float:
    """(E − E₀)/|E₀| in %, or the change in J when E₀ is zero (printed as such by the HUD)."""
    return (energy - reference) / abs(reference) * 100.0 if reference != 0.0 else energy - reference


class Ghosts:
    """The integrators the main run is not using, stepped alongside it."""

    def __init__(self, main: Any, origin: Any, origin_step: int, history: History | None) -> None:
        """``origin`` is a snapshot of ``main`` at ``origin_step``; the ghosts are re-run from it up to
        the main run's current step."""
        self.integrators = tuple(name for name in INTEGRATORS if name != main.integrator)
        self.main_integrator = main.integrator
        timestep = history.timestep if history is not None else 1.0 / 240.0
        self.worlds: dict[str, Any] = {}
        self.histories: dict[str, History] = {}
        target = history.current if history is not None else origin_step
        reference = main.copy()
        reference.restore(origin)
        self.reference_energy = total_energy(reference)
        self.origin_step = origin_step
        self.origin_time = reference.time
        for name in self.integrators:
            ghost = reference.copy()
            ghost.integrator = name
            ghost_history = History(
                ghost,
                timestep,
                keep_seconds=_keep(history),
                anchor_seconds=_anchor(history),
                start=origin_step,
            )
            for _ in range(target - origin_step):
                ghost.step(timestep)
                ghost_history.recorded(name)
            self.worlds[name] = ghost
            self.histories[name] = ghost_history

    def stepped(self) -> None:
        """The main run took a live step: each ghost takes one with its own integrator."""
        for name, ghost in self.worlds.items():
            history = self.histories[name]
            if history.in_past:
                history.drop_future()
            ghost.step(history.timestep)
            history.recorded(name)

    def edited(self, change: Callable[[Any], object]) -> None:
        """The main run was changed by hand: each ghost gets the same change (one it refuses, having
        drifted elsewhere, is skipped) and keeps the changed state in its history."""
        for name, ghost in self.worlds.items():
            try:
                change(ghost)
            except (ValueError, TypeError, IndexError):
                continue
            self.histories[name].changed()

    def seek(self, step: int) -> None:
        """Follow the main run to ``step`` (as near as each ghost's history reaches)."""
        for history in self.histories.values():
            history.seek(step)

    def drifts(self, main: Any) -> list[tuple[str, float, bool]]:
        """(integrator, drift, is the main run) for the main run and each ghost."""
        out = [(main.integrator, drift_percent(total_energy(main), self.reference_energy), True)]
        for name, ghost in self.worlds.items():
            out.append((name, drift_percent(total_energy(ghost), self.reference_energy), False))
        return out


def _keep(history: History | None) -> float:
    return history.keep_steps * history.timestep if history is not None else 30.0


def _anchor(history: History | None) -> float:
    return history.every * history.timestep if history is not None else 0.25
