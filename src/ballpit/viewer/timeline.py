"""What a Simulation remembers and compares: the history you scrub, a replayed trajectory, the
integrator ghosts and the energy trace.

``Timeline`` is the one object the Simulation calls into: ``step`` takes a live step (and records it,
and steps the ghosts) or plays a replay on; ``back``, ``forward``, ``jump`` and ``scrub`` move in time
while paused; ``toggle_ghosts`` starts or stops the ghosts. It knows the world and the timestep, not
the Simulation: what the Simulation must hear about (a seek, the end of a replay) it is told through
the two callbacks it hands in. No GL here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..cli.trajectory import Trajectory
from .energyplot import EnergyWindow
from .ghosts import CATCH_UP_STEPS, Body, GhostRun, Ghosts, GhostSpec
from .history import History
from .replay import Replay

JUMP_SECONDS = 1.0  # Shift+← / Shift+→


class Timeline:
    """History (live runs) or Replay (trajectories), ghosts and the energy trace of one world.

    ``on_seek(contacts)`` is called after every move in time (with the contacts of the step reached,
    when the source kept them), ``on_replay_end()`` when a replay has shown its last frame. With
    ``host`` (giving a ghostproc.GhostHost) the ghosts are stepped in its process, else here.
    """

    def __init__(
        self,
        world: Any,
        timestep: float,
        trajectory: Trajectory | None = None,
        *,
        on_seek: Callable[[Any], None],
        on_replay_end: Callable[[], None],
        host: Callable[[], Any] | None = None,
    ) -> None:
        self.world = world
        self.timestep = timestep
        self._on_seek, self._on_replay_end = on_seek, on_replay_end
        self.history: History | None = None
        self.replay: Replay | None = Replay(world, trajectory) if trajectory is not None else None
        self.host = host
        self.ghosts: GhostRun | None = None
        self.energy = EnergyWindow()
        self._origin: Any = None  # the drop's snapshot, for ghosts started later

    # ------------------------------------------------------------------ state
    @property
    def source(self) -> History | Replay | None:
        """What ←/→ and the timeline bar move through: the replay, else the live history."""
        return self.replay if self.replay is not None else self.history

    @property
    def steps_per_second(self) -> float:
        source = self.source
        return 1.0 / source.timestep if source is not None else 1.0 / self.timestep

    def span(self) -> tuple[float, float, float] | None:
        """(oldest, current, newest) seconds of the span kept, or None before the drop."""
        s = self.source
        if s is None:
            return None
        return s.time_of(s.first), s.time_of(s.current), s.time_of(s.latest)

    # ------------------------------------------------------------------ live
    def started(self) -> None:
        """X: the drop. A live run starts its history here."""
        if self.replay is None and self.history is None:
            self.history = History(self.world, self.timestep)
            self._origin = self.world.snapshot()
            if self.ghosts is not None:  # G before X: the ghosts start with the drop
                self._start_ghosts(self._origin, 0)

    def step(self, dt: float) -> Any:
        """One fixed step: the physics (recorded, ghosts alongside) or the next replay frame."""
        world = self.world
        if self.replay is not None:
            balls = len(world.spheres)
            if not self.replay.advance(dt):
                self._on_replay_end()
            if len(world.spheres) != balls:  # the recording gained a ball here
                self._on_seek(None)
            return _no_contacts()
        contacts = world.step(dt)
        if self.history is not None:
            self.history.recorded(world.integrator)
        if self.ghosts is not None:
            self.ghosts.stepped()
        return contacts

    def resumed(self) -> bool:
        """Space while paused in the past: drop the future (true when something was dropped)."""
        h = self.history
        if h is None or not h.in_past:
            return False
        h.drop_future()
        return True

    def edited(self, change: Callable[[Any], object] | None) -> None:
        """The world was changed by hand at the present step: the history keeps the changed state (the
        steps after it are dropped); ``change``, if given, is made to each ghost as well."""
        if self.history is not None:
            self.history.changed()
        if self.ghosts is not None and change is not None:
            self.ghosts.edited(change, self.history.current if self.history is not None else None)

    # ------------------------------------------------------------------ moving in time
    def seek(self, step: int) -> bool:
        """Go to ``step`` of the source; the ghosts follow. False when there is nothing to move in."""
        source = self.source
        if source is None:
            return False
        source.seek(step)
        if self.ghosts is not None:
            self.ghosts.seek(source.current)
        self._on_seek(getattr(source, "last_contacts", None))
        return True

    def back(self) -> bool:
        s = self.source
        return s is not None and self.seek(s.current - 1)

    def forward(self) -> bool:
        """→ / N while paused: one step forward through what is kept (False at the newest step)."""
        s = self.source
        if s is None or s.current >= s.latest:
            return False
        return self.seek(s.current + 1)

    def jump(self, seconds: float) -> bool:
        s = self.source
        return s is not None and self.seek(s.current + round(seconds * self.steps_per_second))

    def scrub(self, fraction: float) -> bool:
        s = self.source
        if s is None:
            return False
        fraction = float(np.clip(fraction, 0.0, 1.0))
        return self.seek(s.first + round(fraction * (s.latest - s.first)))

    # ------------------------------------------------------------------ ghosts
    def toggle_ghosts(self) -> str:
        """G: start or stop the ghosts; returns the message for the HUD."""
        if self.ghosts is not None:
            self.close()
            return "ghosts off"
        if self.replay is not None:
            return "ghosts need a live run, not a replay"
        world = self.world
        h = self.history
        if h is None:  # before the drop: they start with it
            self._start_ghosts(world.snapshot(), 0)
            return "ghosts on: they drop with X"
        if h.current <= CATCH_UP_STEPS and h.first == 0:
            self._start_ghosts(self._origin, 0)
            return "ghosts on: energy drift since the drop"
        self._start_ghosts(world.snapshot(), h.current)
        return f"ghosts on: energy drift since t = {world.time:.2f} s"

    def _start_ghosts(self, origin: Any, origin_step: int) -> None:
        """Ghosts from ``origin`` (a snapshot of the world at ``origin_step``), caught up to the present."""
        self.close()
        spec = GhostSpec.of(self.world, origin, origin_step, self.history)
        if self.host is not None:
            from .ghostproc import RemoteGhosts

            self.ghosts = RemoteGhosts(self.host(), spec)
        else:
            self.ghosts = Ghosts(spec)

    def close(self) -> None:
        """The ghosts off (their process, if any, lets their worlds go)."""
        if self.ghosts is not None:
            self.ghosts.close()
            self.ghosts = None

    @property
    def _step(self) -> int | None:
        """The main run's step in its history (None before the drop)."""
        return self.history.current if self.history is not None else None

    def drifts(self) -> list[tuple[str, float, bool]]:
        return self.ghosts.drifts(self.world, self._step) if self.ghosts is not None else []

    def ghost_bodies(self) -> tuple[Body, ...]:
        """Each ghost's balls at the main run's step (or the nearest earlier one received)."""
        frame = self.ghosts.frame_at(self._step) if self.ghosts is not None else None
        return frame.bodies if frame is not None else ()

    def settle_ghosts(self, wait: float) -> None:
        """Lockstep: wait up to ``wait`` seconds for the ghosts to reach the main run's step, and put
        their energies in the trace (RuntimeError when their process does not answer)."""
        if self.ghosts is not None:
            self.ghosts.flush()
            self.ghosts.frame_at(self._step, wait=wait)
            self.take_ghost_news()

    def take_ghost_news(self) -> bool:
        """Put the ghosts' energies received since the last call in the energy trace; true when any
        came (what the window shows of the ghosts may have changed)."""
        news = self.ghosts.news() if self.ghosts is not None else []
        for frame in news:
            self.energy.fill(frame.time, frame.totals)
        return bool(news)

    # ------------------------------------------------------------------ energy
    def sample_energy(self) -> None:
        """One sample of the energy trace at the world's time (once per frame); the ghosts' totals at
        the same step join it now or when they come."""
        world = self.world
        kinetic, potential = world.kinetic_energy(), world.potential_energy()
        totals = {world.integrator: kinetic + potential}
        ghosts = self.ghosts
        if ghosts is not None:
            ghosts.flush(soon=True)
            totals |= ghosts.totals_at(self._step) or {}
        self.energy.add(world.time, kinetic, potential, totals)
        self.take_ghost_news()


def _no_contacts() -> Any:
    from ballpit import Contacts

    return Contacts.empty()
