"""The viewer's history: every physics step of the last ``keep_seconds`` of a run, kept compactly.

A ``World.snapshot()`` is taken every ``every`` steps (an anchor; wider apart for scenes with many
balls, to bound the memory); any step in between is reached by
restoring the nearest anchor at or before it and stepping on. Stepping is deterministic, so the state
reached is bit for bit the one the run had. The integrator used for each step is remembered too, so a
run whose integrator was switched live (keys 1/2/3) re-steps exactly.

Steps are numbered from the drop: step 0 is the state when the history began. No GL here.
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from typing import Any

ANCHOR_SECONDS = 0.25  # simulated seconds between snapshots
KEEP_SECONDS = 30.0  # at least this much simulated time stays reachable
ANCHOR_BALL_BUDGET = 500_000  # balls × anchors held at most: big scenes space their anchors wider
DENSE_BALL_BUDGET = 200_000  # balls × snapshots kept of the steps last re-stepped


class History:
    """Snapshots every ``every`` steps plus re-stepping: ``seek(k)`` puts ``world`` at step k exactly.

    ``start`` numbers the world's present step (0: the drop)."""

    def __init__(
        self,
        world: Any,
        timestep: float,
        keep_seconds: float = KEEP_SECONDS,
        anchor_seconds: float = ANCHOR_SECONDS,
        start: int = 0,
    ) -> None:
        self.world = world
        self.timestep = float(timestep)
        balls = max(len(world.spheres), 1)
        anchor_seconds = max(anchor_seconds, keep_seconds * balls / ANCHOR_BALL_BUDGET)
        self.every = max(1, round(anchor_seconds / self.timestep))
        self._dense_cap = min(2 * self.every, max(4, DENSE_BALL_BUDGET // balls))
        self.keep_steps = max(1, math.ceil(keep_seconds / self.timestep - 1e-9))
        self.current = start  # the step the world is at now
        self.latest = start  # the newest step kept
        self._anchor_steps: list[int] = [start]
        self._anchors: dict[int, Any] = {start: world.snapshot()}
        self._integrators: deque[str] = deque()  # the integrator of each step first+1 .. latest
        self._dense: dict[int, Any] = {}  # snapshots of the steps last re-stepped (fast stepping back)
        # snapshots of steps taken ahead of what the window shows (stepper.py), to go back to at once
        self._marks: dict[int, Any] = {}
        self.last_contacts: Any = None  # what the last step taken by ``seek`` returned

    # ------------------------------------------------------------------ the span
    @property
    def first(self) -> int:
        """The oldest step that can still be reached."""
        return self._anchor_steps[0]

    @property
    def in_past(self) -> bool:
        """True when the world is behind the newest step kept (after stepping back)."""
        return self.current < self.latest

    def time_of(self, step: int) -> float:
        """Seconds since the history began at ``step``."""
        return step * self.timestep

    # ------------------------------------------------------------------ recording
    def recorded(self, integrator: str) -> None:
        """The world just took one live step from ``current`` with ``integrator``. Stepping live from
        the past drops the future first."""
        if self.in_past:
            self.drop_future()
        self._dense.clear()
        self.current += 1
        self.latest = self.current
        self._integrators.append(integrator)
        if self.current % self.every == 0:
            self._add_anchor(self.current)
        self._trim()

    def changed(self) -> None:
        """The world was changed by hand at the current step (not by stepping): the future is dropped
        and the changed state becomes an anchor, so re-stepping starts from it."""
        self.drop_future()
        self._dense.clear()
        self._marks.pop(self.current, None)
        self._add_anchor(self.current)

    def mark(self) -> None:
        """Keep a snapshot of the current step until ``unmark_before`` passes it: the physics thread
        running ahead of the window marks each step it queues ahead, so going back to the one shown
        (``seek``) is one restore, not a re-stepping from the last anchor."""
        self._marks[self.current] = self.world.snapshot()

    def unmark_before(self, step: int) -> None:
        """Forget the marks of the steps before ``step`` (the window shows it or a later one)."""
        for k in [k for k in self._marks if k < step]:
            del self._marks[k]

    def drop_future(self) -> None:
        """Forget every step after the current one."""
        if not self.in_past:
            return
        for k in [k for k in self._marks if k > self.current]:
            del self._marks[k]
        cut = bisect.bisect_right(self._anchor_steps, self.current)
        for step in self._anchor_steps[cut:]:
            del self._anchors[step]
        del self._anchor_steps[cut:]
        for _ in range(self.latest - self.current):
            self._integrators.pop()
        self.latest = self.current

    def _add_anchor(self, step: int) -> None:
        if step not in self._anchors:
            bisect.insort(self._anchor_steps, step)
        self._anchors[step] = self.world.snapshot()

    def _trim(self) -> None:
        """Drop anchors no longer needed to reach the last ``keep_steps`` steps."""
        oldest_needed = self.latest - self.keep_steps
        while len(self._anchor_steps) > 1 and self._anchor_steps[1] <= oldest_needed:
            gone = self._anchor_steps.pop(0)
            del self._anchors[gone]
            for _ in range(self._anchor_steps[0] - gone):
                self._integrators.popleft()

    # ------------------------------------------------------------------ moving in time
    def seek(self, step: int) -> int:
        """Put the world at ``step`` (clamped to the span kept); returns the step reached.

        From the nearest anchor at or before it (or from the current state when that is nearer and not
        later), re-step with the integrators the run used. The world's integrator is left as the one the
        next live step would have used at that point in the run.
        """
        step = int(min(max(step, self.first), self.latest))
        if step == self.current:
            return step
        if step in self._marks:
            self.world.restore(self._marks[step])
            self.current, self.last_contacts = step, None
            if self.current < self.latest:
                self.world.integrator = self._integrators[self.current - self.first]
            return step
        anchor = self._anchor_steps[bisect.bisect_right(self._anchor_steps, step) - 1]
        cached = max((k for k in self._dense if anchor <= k <= step), default=None)
        if cached is not None and not (cached <= self.current < step):
            self.world.restore(self._dense[cached])
            self.current = cached
        elif not (anchor <= self.current < step):
            self.world.restore(self._anchors[anchor])
            self.current = anchor
        if cached is None:
            self._dense = {}
        integrators = self._integrators
        base = self.first
        while self.current < step:
            self.world.integrator = integrators[self.current - base]
            self.last_contacts = self.world.step(self.timestep)
            self.current += 1
            if len(self._dense) < self._dense_cap:
                self._dense[self.current] = self.world.snapshot()
        if self.current < self.latest:
            self.world.integrator = integrators[self.current - base]
        return self.current

    def step_by(self, steps: int) -> int:
        """Move ``steps`` steps forward (positive) or back (negative) within the span."""
        return self.seek(self.current + steps)

    def fraction(self) -> float:
        """Where the current step sits in the span kept, 0 (oldest) to 1 (newest)."""
        span = self.latest - self.first
        return 1.0 if span <= 0 else (self.current - self.first) / span

    def memory_anchors(self) -> int:
        """How many snapshots are held."""
        return len(self._anchors)
