"""``ballpit view SCENE --record run.npz|run.csv``: the timeline the viewer showed, every physics step,
in ``simulate``'s trajectory columns, written when the window closes.

The record starts with the state the run starts from and gains one record after every step the viewer
takes, through the same writer ``simulate`` uses, so a record of an untouched run equals ``ballpit
simulate`` of the scene for as many steps, bit for bit. Balls added while running (B) get the next ids
from the step after they appear. A reset (R) or a reload starts the timeline again from its new start.
Resuming from the past (after stepping back through the history) drops the records of the steps that
were dropped, so the record holds the timeline as it stands, with no step twice.

The steps are recorded on the physics thread and the file is written from the window's when it closes,
so both hold the recorder's lock: a step that ends after the file was written is not recorded.
"""

from __future__ import annotations

import threading
from pathlib import Path

from ballpit.cli.trajectory import TrajectoryWriter

from .simulation import Simulation


class Recorder:
    """Records every step of one Simulation into a trajectory file, committed by ``finish``."""

    def __init__(self, path: Path, sim: Simulation) -> None:
        self.path = Path(path)
        self.sim = sim
        self.finished = False
        self._lock = threading.Lock()
        self._start()
        sim.after_step.append(self.record)
        sim.after_reset.append(self.restart)
        sim.after_resume_from_past.append(self.cut)

    def _writer(self) -> TrajectoryWriter:
        # one record per chunk, so the steps after a point in the past can be cut off again
        balls = len(self.sim.world.spheres)
        return TrajectoryWriter(self.path, balls, option="--record", records_per_chunk=1)

    def _start(self) -> None:
        self.writer = self._writer()
        self.record()  # where the run starts

    @property
    def steps(self) -> int:
        """Steps recorded so far (after the starting state)."""
        return self.writer.records - 1

    def record(self) -> None:
        """Step hook: append the world's state now."""
        with self._lock:
            if not self.finished:
                self._record()

    def _record(self) -> None:
        history = self.sim.timeline.history
        if history is not None:  # a step taken after the future was dropped (resumed or edited in the past)
            self.writer.truncate(history.current)
        world = self.sim.world
        balls = world.spheres
        self.writer.record(
            world.time, balls.positions, balls.velocities, balls.angular_velocities, balls.orientations
        )

    def cut(self, step: int) -> None:
        """Resume hook: the run goes on from ``step`` (since the start); later records are dropped."""
        with self._lock:
            if not self.finished:
                self.writer.truncate(step + 1)

    def restart(self) -> None:
        """Reset hook: the timeline starts again from the new world's start."""
        with self._lock:
            if self.finished:
                return
            self.writer.discard()
            self.writer = self._writer()
            self._record()

    def finish(self, shown: int | None = None) -> tuple[Path, int, int] | None:
        """Write the file (once), up to the step ``shown`` (the one the window shows: steps the physics
        took ahead of it were never seen); returns (its path, the steps recorded, the balls), or None if
        it was written already."""
        with self._lock:
            if self.finished:
                return None
            self.finished = True
            if shown is not None and self.sim.timeline.history is not None:
                self.writer.truncate(shown + 1)
            steps, balls = self.steps, self.writer.n
            self.writer.commit()
            return self.path, steps, balls
