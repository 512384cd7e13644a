"""Integrator ghosts (G): the same scene stepped in lockstep under every other registered integrator.

Each ghost is a ``World.copy()`` of the run at a common origin (the drop, when it can catch up from
there quickly; else the moment G was pressed) with its ``integrator`` set, and keeps its own History so
it follows the main run when you step back or scrub. Energy drift is measured from the total energy at
that origin, the same reference for the main run and every ghost. No GL here.

What the viewer reads of the ghosts is a ``GhostFrame`` per step of the main run (their balls' poses and
their total energies), asked by step: ``Ghosts`` steps the worlds here, on the caller's thread, so the
frame of the present is always there; ``ghostproc.RemoteGhosts`` steps them in a process of their own
and answers with the frames it has received (the window's physics thread gives the CPU to the main run).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..physics.dynamics.integrators import INTEGRATORS as REGISTRY
from .history import History

INTEGRATORS = tuple(REGISTRY)
LABELS = {name: integrator.label for name, integrator in REGISTRY.items()}
# Ghost tint per integrator (sRGB, its registered colour): what the HUD legend and the energy plot use too.
TINTS = {name: integrator.rgb for name, integrator in REGISTRY.items()}
GHOST_ALPHA = 0.38
CATCH_UP_STEPS = 720  # at most this many steps of re-running from the drop when G is pressed

Body = tuple[str, np.ndarray, np.ndarray, np.ndarray]  # (integrator, positions, orientations, radii)


def total_energy(world: Any) -> float:
    return float(world.kinetic_energy() + world.potential_energy())


def drift_percent(energy: float, reference: float) -> float:
    """(E − E₀)/|E₀| in %, or the change in J when E₀ is zero (printed as such by the HUD)."""
    return (energy - reference) / abs(reference) * 100.0 if reference != 0.0 else energy - reference


@dataclass(frozen=True)
class GhostFrame:
    """The ghosts at one step of the main run: each one's balls (None when only the energies were sent)
    and its total energy."""

    step: int
    time: float
    totals: dict[str, float]
    bodies: tuple[Body, ...] | None = None


@dataclass(frozen=True)
class GhostSpec:
    """Everything the ghosts start from (picklable, sent to the ghosts' process as it is): the main run
    put back at the origin, the integrators to run, and its history's settings."""

    reference: Any  # a World at the origin
    integrators: tuple[str, ...]
    main_integrator: str
    origin_step: int
    target: int  # the main run's step now: the ghosts are re-run from the origin up to it
    timestep: float
    keep_seconds: float
    anchor_seconds: float
    live: bool  # after the drop (a history runs): the ghosts may be stepped ahead of the main run

    @classmethod
    def of(cls, main: Any, origin: Any, origin_step: int, history: History | None) -> GhostSpec:
        """``origin`` is a snapshot of ``main`` at ``origin_step``."""
        reference = main.copy()
        reference.restore(origin)
        return cls(
            reference=reference,
            integrators=tuple(name for name in INTEGRATORS if name != main.integrator),
            main_integrator=main.integrator,
            origin_step=origin_step,
            target=history.current if history is not None else origin_step,
            timestep=history.timestep if history is not None else 1.0 / 240.0,
            keep_seconds=history.keep_steps * history.timestep if history is not None else 30.0,
            anchor_seconds=history.every * history.timestep if history is not None else 0.25,
            live=history is not None,
        )

    @property
    def reference_energy(self) -> float:
        return total_energy(self.reference)


class GhostRun:
    """What the viewer knows of the ghosts wherever they are stepped: their spec's facts and the drift."""

    remote = False  # stepped in another process: their frames come later than the main run's steps
    error: str | None = None  # what stopped them (a ghost world failed where they are stepped)
    # steps the main run may be ahead of the step the window shows with the ghosts' frames of both kept
    # (stepped here, they are stepped with it: no limit)
    span: float = float("inf")

    def __init__(self, spec: GhostSpec) -> None:
        self.integrators = spec.integrators
        self.main_integrator = spec.main_integrator
        self.reference_energy = spec.reference_energy
        self.origin_step = spec.origin_step
        self.origin_time = spec.reference.time

    def totals_at(self, step: int | None) -> dict[str, float] | None:
        """Each ghost's total energy at ``step`` of the main run, or None when not known (yet)."""
        raise NotImplementedError

    def drifts(self, main: Any, step: int | None) -> list[tuple[str, float, bool]]:
        """(integrator, drift, is the main run) for the main run and each ghost whose energy at ``step``
        is known (the nearest earlier one when not yet)."""
        out = [(main.integrator, drift_percent(total_energy(main), self.reference_energy), True)]
        frame = self.frame_at(step)
        totals = frame.totals if frame is not None else {}
        for name in self.integrators:
            if name in totals:
                out.append((name, drift_percent(totals[name], self.reference_energy), False))
        return out

    def frame_at(self, step: int | None, wait: float = 0.0) -> GhostFrame | None:
        """The latest frame with balls at or before ``step`` (None: the latest of all); with ``wait``,
        wait up to that many seconds for the one at ``step`` itself."""
        raise NotImplementedError

    def news(self) -> list[GhostFrame]:
        """Frames received since the last call (their energies fill the energy trace)."""
        return []

    def flush(self, soon: bool = False) -> None:
        """Say how far the main run has got (nothing to do when they are stepped here). ``soon``: only
        once it has got far enough on since last said."""

    def close(self) -> None:
        """Stop stepping them (nothing to do when they are stepped here)."""


class Ghosts(GhostRun):
    """The integrators the main run is not using, stepped alongside it on the caller's thread."""

    def __init__(self, spec: GhostSpec) -> None:
        super().__init__(spec)
        self.worlds: dict[str, Any] = {}
        self.histories: dict[str, History] = {}
        for name in self.integrators:
            ghost = spec.reference.copy()
            ghost.integrator = name
            ghost_history = History(
                ghost,
                spec.timestep,
                keep_seconds=spec.keep_seconds,
                anchor_seconds=spec.anchor_seconds,
                start=spec.origin_step,
            )
            for _ in range(spec.target - spec.origin_step):
                ghost.step(spec.timestep)
                ghost_history.recorded(name)
            self.worlds[name] = ghost
            self.histories[name] = ghost_history

    @classmethod
    def of(cls, main: Any, origin: Any, origin_step: int, history: History | None) -> Ghosts:
        """Ghosts of ``main`` from ``origin`` (a snapshot of it at ``origin_step``), re-run up to the
        main run's current step."""
        return cls(GhostSpec.of(main, origin, origin_step, history))

    @property
    def current(self) -> int:
        """The step of the main run the ghosts are at."""
        return next(iter(self.histories.values())).current if self.histories else self.origin_step

    @property
    def latest(self) -> int:
        return next(iter(self.histories.values())).latest if self.histories else self.origin_step

    def stepped(self) -> None:
        """The main run took a live step: each ghost takes one with its own integrator."""
        for name, ghost in self.worlds.items():
            history = self.histories[name]
            if history.in_past:
                history.drop_future()
            ghost.step(history.timestep)
            history.recorded(name)

    def edited(self, change: Callable[[Any], object], step: int | None = None) -> None:
        """The main run was changed by hand at ``step`` (the ghosts' own present when None): each ghost
        gets the same change there (one it refuses, having drifted elsewhere, is skipped) and keeps the
        changed state in its history."""
        if step is not None:
            self.seek(step)
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

    def frame(self, bodies: bool = True) -> GhostFrame:
        """The ghosts as they are now."""
        time = next(iter(self.worlds.values())).time if self.worlds else self.origin_time
        totals = {name: total_energy(ghost) for name, ghost in self.worlds.items()}
        shapes = None
        if bodies:
            shapes = tuple(
                (name, np.array(s.positions), np.array(s.orientations), np.array(s.radii))
                for name, s in ((name, g.spheres) for name, g in self.worlds.items())
            )
        return GhostFrame(self.current, float(time), totals, shapes)

    def totals_at(self, step: int | None) -> dict[str, float] | None:
        return self.frame(bodies=False).totals if step is None or step == self.current else None

    def frame_at(self, step: int | None, wait: float = 0.0) -> GhostFrame | None:
        return self.frame() if step is None or step >= self.current else None
