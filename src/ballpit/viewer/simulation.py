"""The viewer's simulation driver: fixed timestep, interpolation, run state, reset and reload.

Physics advances in fixed steps of the scene's timestep from an accumulator fed by real time (Glenn
Fiedler, "Fix Your Timestep!"). Frames render the state interpolated between the last two steps, so
motion is smooth at any frame rate. A frame never steps for more than ``step_budget`` seconds of wall
time nor more than ``MAX_FRAME_SECONDS`` of real time: when physics cannot keep up, the backlog is
dropped (the real-time factor falls below the time scale) instead of spiralling.

No GL here, and nothing per ball in Python: everything works on whole arrays.
"""

from __future__ import annotations

import copy
import itertools
import os
import sys
import time
from collections.abc import Callable
from enum import Enum
from operator import methodcaller
from pathlib import Path
from typing import Any

import numpy as np

from ..cli.trajectory import Trajectory
from ..physics.core.profile import RunProfile
from ..scene import Appearance, Scene, read_scene, scene_of
from ..scene.colours import palette_colors
from .timeline import Timeline

MAX_FRAME_SECONDS = 0.25
TRAIL_POINT_BUDGET = 200_000  # trail samples kept over all balls
TRAIL_MAX_SAMPLES = 120
TRAIL_INTERVAL = 1.0 / 30.0  # simulated seconds between trail samples
STATS_WINDOW = 0.5  # wall seconds over which steps/s and the real-time factor are measured


_GENERATIONS = itertools.count(1)


class Phase(Enum):
    WAITING = "waiting: press X to drop"
    RUNNING = "running"
    PAUSED = "paused: Space resumes, N steps"


def _file_signature(path: Path | None) -> tuple[int, int] | None:
    try:
        st = os.stat(path) if path is not None else None
    except OSError:
        return None
    return None if st is None else (st.st_mtime_ns, st.st_size)


def _describe(exc: BaseException) -> str:
    return str(exc).strip() or type(exc).__name__


class Trails:
    """A ring buffer of recent ball positions, sized so all balls together keep a bounded number."""

    def __init__(self, count: int) -> None:
        self.length = int(np.clip(TRAIL_POINT_BUDGET // max(count, 1), 2, TRAIL_MAX_SAMPLES))
        self._samples = np.zeros((self.length, count, 3), dtype=np.float32)
        self._head = 0
        self.filled = 0
        self.last_time = -np.inf

    def record(self, positions: np.ndarray, sim_time: float) -> None:
        if sim_time - self.last_time < TRAIL_INTERVAL * 0.999:
            return
        self._samples[self._head] = positions
        self._head = (self._head + 1) % self.length
        self.filled = min(self.filled + 1, self.length)
        self.last_time = sim_time

    def grow(self, position: np.ndarray) -> None:
        """Make room for one more ball, whose trail starts where it is now."""
        extra = np.broadcast_to(np.asarray(position, dtype=np.float32), (self.length, 1, 3))
        self._samples = np.concatenate([self._samples, extra], axis=1)

    def ordered(self) -> np.ndarray:
        """(filled, N, 3) samples, oldest first."""
        order = (self._head - self.filled + np.arange(self.filled)) % self.length
        return self._samples[order]


class Simulation:
    """A World being watched: the run phase, the fixed-step clock and what the viewer draws from it.

    Give it a Scene (from ``read_scene``), or a World built in code and optionally the file to reload;
    ``loader`` reads that file again (``read_scene`` by default).
    """

    def __init__(
        self,
        world: Scene | object,
        path: Path | None = None,
        loader: Callable[[Path], Scene] | None = None,
        step_budget: float = 0.05,
        clock: Callable[[], float] = time.perf_counter,
        trajectory: Trajectory | None = None,
    ) -> None:
        self.trajectory = trajectory  # a replayed run (``view --replay``) instead of live physics
        self.loader = loader or read_scene
        self.step_budget = step_budget
        self.clock = clock
        self.time_scale = 1.0
        self.error: str | None = None
        self.message: str = ""
        self.generation = 0  # bumps whenever the world is replaced, so the renderer rebuilds geometry
        self.dropped_seconds = 0.0  # simulated time skipped because physics could not keep up
        # Hooks (no arguments): before and after every physics step, and whenever the run restarts
        # (a new world, a reset or a reload). Reaching in and recording attach here.
        self.before_step: list[Callable[[], None]] = []
        self.after_step: list[Callable[[], None]] = []
        self.after_reset: list[Callable[[], None]] = []
        self.after_resume_from_past: list[Callable[[int], None]] = []  # gets the step resumed from
        self.ghost_host: Any = None  # ghostproc.GhostHost: the ghosts stepped in a process of their own
        self._ghosts_apart = False
        self._install(scene_of(world, path))

    # ------------------------------------------------------------------ world management
    def _install(self, scene: Scene) -> None:
        world = scene.world
        self.scene = scene
        self.world = world
        self.appearance: Appearance = scene.appearance
        self.path = scene.path
        self.initial = copy.deepcopy(world)
        self._signature = _file_signature(self.path)
        self._reset_dynamics()
        self.generation = next(_GENERATIONS)  # unique across Simulations too

    def _reset_dynamics(self) -> None:
        spheres = self.world.spheres
        self.appearance.sphere_colors = self.appearance.sphere_colors[: len(spheres)]  # drop added balls
        self.phase = Phase.WAITING
        self.held = False  # dropped but held at its first state until X (``hold``)
        self._held_message = ""
        self.accumulator = 0.0
        self.alpha = 1.0
        self.prev_positions = np.array(spheres.positions, dtype=float)
        self.prev_orientations = np.array(spheres.orientations, dtype=float)
        self.prev_plane_centers = np.array(self.world.planes.centers, dtype=float)
        self.prev_plane_orientations = np.array(self.world.planes.orientations, dtype=float)
        self.contacts = None  # Contacts of the last frame that stepped
        self.last_step_contacts = 0
        self.trails = Trails(len(spheres))
        self.trails.record(np.asarray(spheres.positions, dtype=np.float32), self.world.time)
        self.steps_total = 0
        self.steps_per_second = 0.0
        self.real_time_factor = 0.0
        self._restart_stats()
        self.profile = RunProfile()  # the steps of the last stats window, stage by stage
        self._profile = RunProfile()
        self._new_timeline()
        for hook in self.after_reset:
            hook()

    def _new_timeline(self) -> None:
        """History, replay, ghosts and energy trace start afresh (ghosts stay on if they were)."""
        ghosts = getattr(self, "timeline", None) is not None and self.timeline.ghosts is not None
        trajectory = self.trajectory
        if trajectory is not None and trajectory.balls_at(0) != self.ball_count:
            balls = trajectory.balls_at(0)
            self.error = f"{trajectory.path}: the trajectory has {balls} balls, the scene {self.ball_count}"
            trajectory = None
        if trajectory is not None and trajectory.balls > self.ball_count:  # balls added in the recording
            look, first = self.appearance, self.ball_count
            look.sphere_colors = np.vstack(
                [look.sphere_colors, palette_colors(trajectory.balls - first, first)]
            )
        if getattr(self, "timeline", None) is not None:
            self.timeline.close()
        self.timeline = Timeline(
            self.world,
            self.timestep,
            trajectory,
            on_seek=self.after_seek,
            on_replay_end=self.end_of_replay,
            host=self._host if self._ghosts_apart else None,
        )
        if trajectory is not None:
            self.after_seek(None)  # frame 0 of the replay is in the world now
        if ghosts:
            self.timeline.toggle_ghosts()
        self.timeline.sample_energy()

    def ghosts_apart(self) -> None:
        """Step the integrator ghosts in a process of their own from the next time they start
        (ghostproc.py; the process starts then): the viewer's physics thread steps the main run alone."""
        self._ghosts_apart = True
        self.timeline.host = self._host

    def _host(self) -> Any:
        if self.ghost_host is None:
            from .ghostproc import GhostHost

            self.ghost_host = GhostHost()
        return self.ghost_host

    def close(self) -> None:
        """Stop the ghosts' process, if any (never waits for it)."""
        if self.ghost_host is not None:
            self.ghost_host.close()

    @property
    def timestep(self) -> float:
        return self.scene.timestep

    @property
    def ball_count(self) -> int:
        return len(self.world.spheres)

    # ------------------------------------------------------------------ controls
    @property
    def shown_phase(self) -> Phase:
        """The phase a state captured now is shown in: running for the steps taken while held before X
        (they are shown after it), else the phase."""
        return Phase.RUNNING if self.held else self.phase

    def start(self) -> None:
        """X: start the drop (only from the waiting state); a held one goes on from the steps it took."""
        if self.phase is not Phase.WAITING:
            return
        if not self.held:
            self.timeline.started()
        self.held, self.phase, self.accumulator = False, Phase.RUNNING, 0.0
        self._restart_stats()
        self.message = "dropped"

    def hold(self) -> bool:
        """Start the drop, but held at its first state until X: the physics thread steps its first lead
        ahead while the scene waits (stepper.py, "Held before X"), and X lets it go on from there. The
        phase stays WAITING, so everything else asked before X sees the run waiting; it undoes the hold
        first (``unhold``). False when there is nothing to hold (not waiting, or a replay)."""
        if self.phase is not Phase.WAITING or self.held or self.timeline.replay is not None:
            return False
        self.timeline.started()
        self.held, self._held_message = True, self.message
        self.message = "dropped"  # what the states stepped meanwhile say when they are shown, after X
        self.accumulator = 0.0
        self._restart_stats()
        return True

    def unhold(self) -> None:
        """Undo a hold: the world goes back to the drop's first state (its snapshot, bit for bit) and
        waits for X as if it had never started. The steps taken meanwhile are forgotten, and what kept
        them (the recording, the traces) hears of it as of a resume from step 0."""
        if not self.held:
            return
        self.held = False
        self.timeline.seek(0)
        for hook in self.after_resume_from_past:
            hook(0)
        self.message = self._held_message
        self._new_timeline()  # no history before X; ghosts, if on, wait for X again
        self._restart_stats()

    def toggle_pause(self) -> None:
        """Space: pause a running simulation or resume a paused one."""
        if self.phase is Phase.RUNNING:
            self.phase = Phase.PAUSED
            self.alpha = 1.0
            self.message = "paused"
        elif self.phase is Phase.PAUSED:
            self.phase = Phase.RUNNING
            self.accumulator = 0.0
            self._restart_stats()
            self.message = "resumed"
            if self.resume_from_here():
                self.message = "resumed from the past: the later history is dropped"
        else:
            self.message = "press X to start the drop"

    def resume_from_here(self) -> bool:
        """The run goes on from the step the world is at: the later history is dropped and the hooks
        (the recording) hear of it. False when the world was at the newest step already."""
        if not self.timeline.resumed():
            return False
        for hook in self.after_resume_from_past:
            hook(self.timeline.history.current)
        return True

    def step_once(self) -> None:
        """N / →: one fixed step, only while paused."""
        if self.phase is not Phase.PAUSED:
            self.message = "N steps only while paused (Space pauses)"
            return
        if self.timeline.forward() or self.timeline.replay is not None:
            return
        contacts = []
        self._step(contacts)
        self._finish_steps(contacts)
        self.alpha = 1.0

    def reset(self) -> None:
        """R: back to the initial state, waiting for X again. The live integrator choice is kept."""
        integrator = self.world.integrator
        self.world = copy.deepcopy(self.initial)
        self.world.integrator = integrator
        self._reset_dynamics()
        self.message = "reset: press X to drop"

    def set_integrator(self, name: str) -> None:
        self.world.integrator = name
        self.message = f"integrator {name.upper()}"
        ghosts = self.timeline.ghosts
        if ghosts is not None and name in ghosts.integrators:  # the ghosts become the other two again
            self.timeline.toggle_ghosts()
            self.message += "; " + self.timeline.toggle_ghosts()

    def faster(self) -> None:
        from .controls import faster

        self.time_scale = faster(self.time_scale)
        self.message = f"time ×{self.time_scale:g}"

    def slower(self) -> None:
        from .controls import slower

        self.time_scale = slower(self.time_scale)
        self.message = f"time ×{self.time_scale:g}"

    def reload(self) -> bool:
        """Ctrl+R / F5 / file saved: load the file again. On any error keep the last good world running,
        remember the error for the HUD and print it."""
        if self.path is None:
            self.error = "no scene file to reload (this world was built in code)"
            return False
        self._signature = _file_signature(self.path)
        name = self.path.name
        return self._load(self.path, f"reload of {name} failed", f"reloaded {name}", "the last good scene")

    def file_changed(self) -> bool:
        """True once each time the scene file's modification time or size changes."""
        if self.path is None:
            return False
        signature = _file_signature(self.path)
        if signature is None or signature == self._signature:
            return False
        self._signature = signature
        return True

    # ------------------------------------------------------------------ time
    def advance(self, frame_seconds: float) -> int:
        """Feed one frame's real time to the accumulator and take the fixed steps it pays for.

        Returns the number of steps taken.
        """
        frame_seconds = max(0.0, float(frame_seconds))
        steps = 0
        if self.phase is Phase.RUNNING:
            dt = self.timestep
            self.accumulator += min(frame_seconds, MAX_FRAME_SECONDS) * self.time_scale
            started = self.clock()
            contacts: list = []
            while self.accumulator >= dt and self.phase is Phase.RUNNING:
                if steps > 0 and self.clock() - started > self.step_budget:
                    # Physics is slower than real time: drop the backlog rather than spiral.
                    dropped = self.accumulator - self.accumulator % dt
                    self.dropped_seconds += dropped
                    self.accumulator -= dropped
                    break
                self._step(contacts)
                self.accumulator -= dt
                steps += 1
            self._finish_steps(contacts)
            self.alpha = min(self.accumulator / dt, 1.0) if self.phase is Phase.RUNNING else 1.0
        if steps:
            self.timeline.sample_energy()
        self._update_stats(frame_seconds, steps)
        return steps

    def lead(self, steps: int, before_each: Callable[[], None] | None = None) -> int:
        """Take up to ``steps`` fixed steps now, whatever the wall clock: the physics thread running ahead
        of what the window shows (stepper.py), calling ``before_each`` before each step. The state is
        handed over as it is, not interpolated, and the simulated time and steps counted for the
        real-time factor and the steps per second are those shown (``count_shown``), not those stepped
        (which come in bursts, taken before X when the scene was held). Returns the steps taken."""
        taken, stepped, counted = 0, self._stats_sim, self._stats_steps
        contacts: list = []
        while taken < steps and (self.phase is Phase.RUNNING or self.held):
            if before_each is not None:
                before_each()
            self._step(contacts)
            taken += 1
        self._finish_steps(contacts)
        self._stats_sim, self._stats_steps = stepped, counted
        self.accumulator, self.alpha = 0.0, 1.0
        if taken:
            self.timeline.sample_energy()
        return taken

    def count_shown(self, wall_seconds: float, shown_seconds: float) -> None:
        """While running ahead: ``wall_seconds`` passed and the window's state moved on by
        ``shown_seconds`` of simulated time (the real-time factor is the speed the run is shown at, the
        steps per second those it shows)."""
        self._stats_sim += shown_seconds
        self._stats_steps += shown_seconds / self.timestep
        self._update_stats(wall_seconds, 0)
        if self.real_time_factor == 0.0 and self._stats_wall >= 0.2 * STATS_WINDOW:  # before the first end
            self.real_time_factor = self._stats_sim / self._stats_wall

    def _step(self, contacts: list) -> None:
        for hook in self.before_step:
            hook()
        spheres, planes = self.world.spheres, self.world.planes
        self.prev_positions[:] = spheres.positions
        self.prev_orientations[:] = spheres.orientations
        self.prev_plane_centers[:] = planes.centers
        self.prev_plane_orientations[:] = planes.orientations
        try:
            result = self.timeline.step(self.timestep)
        except Exception as exc:  # a physics failure pauses the viewer instead of killing it
            self.phase, self.held = Phase.PAUSED, False
            self.error = f"physics step failed: {_describe(exc)}"
            print(f"ballpit: {self.error}", file=sys.stderr, flush=True)
            return
        contacts.append(result)
        self._profile.add(self.world.profile)
        self.last_step_contacts = len(result)
        self.steps_total += 1
        self._stats_steps += 1
        self._stats_sim += self.timestep
        self.trails.record(np.asarray(spheres.positions, dtype=np.float32), self.world.time)
        for hook in self.after_step:
            hook()

    def edit(self, change: Callable[[object], object], ghosts: bool = True) -> object:
        """A change by hand between steps: ``change(world)`` (a World method that refuses bad values
        with ValueError/TypeError and then changes nothing; with ``ghosts``, picklable: a methodcaller
        or a partial, sent to the ghosts' process when they run in one). The history keeps the changed
        state as the present (re-stepping starts from it; any later steps are dropped) and, with
        ``ghosts``, each ghost gets the same change, so an edited run is recorded and compared as what
        it is. A replay refuses (ValueError): it writes the recorded frames into the world."""
        if self.timeline.replay is not None:
            raise ValueError("a replay plays a recorded run: it cannot be edited")
        result = change(self.world)
        self.timeline.edited(change if ghosts else None)
        return result

    def remove_ball(self, index: int) -> None:
        """Remove ball ``index`` (it and the ghosts' copies); what is kept per ball shrinks with it."""
        self.edit(methodcaller("remove_sphere", index))
        look = self.appearance
        look.sphere_colors = np.delete(look.sphere_colors, index, axis=0)
        self.prev_positions = np.delete(self.prev_positions, index, axis=0)
        self.prev_orientations = np.delete(self.prev_orientations, index, axis=0)
        self.trails = Trails(self.ball_count)
        self.trails.record(np.asarray(self.world.spheres.positions, dtype=np.float32), self.world.time)

    def open(self, path: Path) -> bool:
        """Open another scene file in place of this one; on any error keep the scene running and
        remember the error (as a failed reload does)."""
        path = Path(path)
        return self._load(path, f"cannot open {path.name}", f"opened {path.name}", "the current scene")

    def _load(self, path: Path, failed: str, done: str, kept: str) -> bool:
        """Put the scene file ``path`` in place of the world; on any error keep the world running and
        say ``failed`` (with the reason) in ``error`` and on stderr."""
        try:
            scene = self.loader(path)
        except Exception as exc:  # any failure: the viewer must stay up with the old world
            self.error = f"{failed}: {_describe(exc)}"
            print(f"ballpit: {self.error} (keeping {kept})", file=sys.stderr, flush=True)
            return False
        self._install(scene)
        self.error = None
        self.message = f"{done}: press X to drop"
        return True

    def add_ball(self, color: object, **kwargs: object) -> int:
        """Add a ball to the live world (``World.add_sphere`` arguments) drawn in ``color``; returns its
        index. Everything kept per ball (colours, trails, interpolation) grows with it."""
        ball = self.edit(methodcaller("add_sphere", **kwargs))
        look = self.appearance
        look.sphere_colors = np.vstack([look.sphere_colors, np.asarray(color, dtype=float).reshape(1, 3)])
        self.prev_positions = np.vstack([self.prev_positions, ball.position])
        self.prev_orientations = np.vstack([self.prev_orientations, ball.orientation])
        self.trails.grow(np.asarray(ball.position, dtype=np.float32))
        return ball.index

    # ------------------------------------------------------------------ history, replay, ghosts
    def step_back(self) -> None:
        """←: one step back through the history, only while paused."""
        self._move(lambda t: t.back(), "← steps back only while paused (Space pauses)")

    def jump(self, seconds: float) -> None:
        """Shift+← / Shift+→: a second back or forward through the history, only while paused."""
        self._move(lambda t: t.jump(seconds), "Shift+←/→ jump only while paused (Space pauses)")

    def scrub(self, fraction: float) -> None:
        """Dragging on the timeline bar: pause and go to that point of the span kept (0 oldest, 1 newest)."""
        if self.phase is Phase.RUNNING:
            self.toggle_pause()
        self._move(lambda t: t.scrub(fraction), "")

    def _move(self, how: Callable[[Timeline], bool], refusal: str) -> None:
        if self.phase is not Phase.PAUSED:
            self.message = refusal if self.phase is Phase.RUNNING else "press X to start the drop"
            return
        if not how(self.timeline):
            self.message = "no history yet"

    def after_seek(self, contacts: object) -> None:
        """The timeline moved the world: draw it as it is now, with no interpolation or old trails."""
        spheres = self.world.spheres
        self.prev_positions = np.array(spheres.positions, dtype=float)
        self.prev_orientations = np.array(spheres.orientations, dtype=float)
        self.alpha = 1.0
        self.contacts = contacts
        self.last_step_contacts = len(contacts) if contacts is not None else 0
        self.trails = Trails(len(spheres))
        self.trails.record(np.asarray(spheres.positions, dtype=np.float32), self.world.time)
        self.timeline.sample_energy()

    def end_of_replay(self) -> None:
        """The replay showed its last frame: pause there."""
        self.phase = Phase.PAUSED
        self.message = "end of the replay: ← / drag the timeline to go back, R restarts"

    def toggle_ghosts(self) -> None:
        """G: integrator ghosts on or off."""
        self.message = self.timeline.toggle_ghosts()
        self.timeline.sample_energy()

    def _finish_steps(self, contacts: list) -> None:
        if contacts:
            from ballpit import Contacts

            self.contacts = Contacts.concatenate(contacts)

    def _restart_stats(self) -> None:
        """A new measuring window: after each one, and when the run starts or resumes, so that none of
        the wall time spent waiting or paused is in it. That time read as a slow run: 0.10 of real time
        right after X, which the HUD showed for a second while the states computed ahead carried it."""
        self._stats_wall, self._stats_steps, self._stats_sim = 0.0, 0, 0.0

    def _update_stats(self, frame_seconds: float, steps: int) -> None:
        self._stats_wall += frame_seconds
        if self._stats_wall >= STATS_WINDOW:
            self.steps_per_second = self._stats_steps / self._stats_wall
            self.real_time_factor = self._stats_sim / self._stats_wall
            self._restart_stats()
            if self._profile.steps:  # paused: keep showing the last window that stepped
                self.profile, self._profile = self._profile, RunProfile()

    # ------------------------------------------------------------------ what to draw
    def render_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (N, 3) and orientations (N, 4) interpolated ``alpha`` of the way from the previous
        step to the current one (positions lerped, quaternions nlerped along the short arc)."""
        spheres = self.world.spheres
        pos = np.asarray(spheres.positions, dtype=float)
        quat = np.asarray(spheres.orientations, dtype=float)
        return self._interpolated(self.prev_positions, pos, self.prev_orientations, quat)

    def render_planes(self) -> tuple[np.ndarray, np.ndarray]:
        """Plane centres (P, 3) and orientations (P, 4) at the same ``alpha`` as ``render_state``."""
        planes = self.world.planes
        pos = np.asarray(planes.centers, dtype=float)
        quat = np.asarray(planes.orientations, dtype=float)
        return self._interpolated(self.prev_plane_centers, pos, self.prev_plane_orientations, quat)

    def _interpolated(self, prev_pos: np.ndarray, pos: np.ndarray, prev_q: np.ndarray,
                      quat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """``alpha`` of the way from the previous step's poses to these: positions lerped, quaternions
        nlerped along the short arc (the current poses themselves once the step is reached or paused)."""
        a = self.alpha
        if a >= 1.0 or self.phase is not Phase.RUNNING:
            return pos, quat
        sign = np.where(np.einsum("ij,ij->i", prev_q, quat) < 0.0, -1.0, 1.0)[:, None]
        q = prev_q * (1.0 - a) + quat * sign * a
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        return prev_pos + (pos - prev_pos) * a, q

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of all balls, J (the physics' own measure)."""
        return self.world.kinetic_energy()
