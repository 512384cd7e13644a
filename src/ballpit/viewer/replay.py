"""Replaying a trajectory written by ``ballpit simulate --out`` (or the viewer's ``--record``).

The file is read by ``ballpit.cli.trajectory.read_trajectory``; ``Replay`` is the viewer's timeline
for it: frame k is written into the scene's World (positions, velocities, spins, orientations, time),
so everything that reads the world draws it. No GL here.
"""

from __future__ import annotations

import bisect
from typing import Any

import numpy as np

from ballpit.cli.trajectory import Trajectory

SHOT_RADIUS, SHOT_MASS = 0.25, 1.0  # what B shoots when the scene has no balls (interaction.py)


class Replay:
    """A trajectory as the viewer's timeline: steps are frames; ``seek(k)`` shows frame k.

    A recording that gained balls (B) shows each from the frame it appears in: the world holds the
    scene's balls plus those of the frame shown. An added ball is as big and heavy as the scene's
    median ball, as B makes it (a trajectory has no radius column)."""

    def __init__(self, world: Any, trajectory: Trajectory) -> None:
        self.world = world
        self.trajectory = trajectory
        self._scene = world.snapshot() if trajectory.counts is not None else None
        spheres = world.spheres
        self._added = (
            (float(np.median(spheres.radii)), float(np.median(spheres.masses)))
            if len(spheres)
            else (SHOT_RADIUS, SHOT_MASS)
        )
        self.first = 0
        self.latest = trajectory.frames - 1
        self.current = -1
        self.last_contacts: Any = None
        diffs = np.diff(trajectory.times)
        positive = diffs[diffs > 0]
        self.timestep = float(np.median(positive)) if len(positive) else 1.0 / 60.0
        self.clock = float(trajectory.times[0])  # replay time reached by ``step``
        self.seek(0)

    in_past = False  # resuming a replay plays on; nothing is dropped

    def time_of(self, step: int) -> float:
        return float(self.trajectory.times[step] - self.trajectory.times[0])

    def seek(self, step: int) -> int:
        """Write frame ``step`` (clamped) into the world."""
        step = int(min(max(step, self.first), self.latest))
        t = self.trajectory
        n = t.balls_at(step)
        self._hold(n, step)
        spheres = self.world.spheres
        spheres.positions[:] = t.position[step, :n]
        spheres.velocities[:] = t.velocity[step, :n]
        spheres.angular_velocities[:] = t.angular_velocity[step, :n]
        spheres.orientations[:] = t.orientation[step, :n]
        self.world.time = float(t.times[step])
        self.current = step
        self.clock = float(t.times[step])
        return step

    def _hold(self, n: int, step: int) -> None:
        """Make the world hold ``n`` balls: the scene's, then those added in the recording."""
        world = self.world
        if self._scene is None or len(world.spheres) == n:
            return
        world.restore(self._scene)
        first = len(world.spheres)
        if n > first:
            radius, mass = self._added
            world.add_spheres(self.trajectory.position[step, first:n], radius=radius, mass=mass)

    def step_by(self, steps: int) -> int:
        return self.seek(self.current + steps)

    def advance(self, seconds: float) -> bool:
        """Play on by ``seconds`` of recorded time; False once the last frame is shown."""
        times = self.trajectory.times
        self.clock += seconds
        frame = max(bisect.bisect_right(times.tolist(), self.clock + 1e-12) - 1, self.current)
        clock = self.clock
        if frame != self.current:
            self.seek(frame)
            self.clock = clock
        return self.current < self.latest

    def fraction(self) -> float:
        span = self.latest - self.first
        return 1.0 if span <= 0 else (self.current - self.first) / span
