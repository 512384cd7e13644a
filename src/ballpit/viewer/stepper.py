"""Physics beside the drawing: a thread of its own steps the Simulation; the window draws what it hands over.

As in MuJoCo's ``simulate``, the window owns input and drawing and the physics owns the World, and they
meet at one small hand-over: after each batch of steps the physics thread captures a ``Shown`` (see
handover.py) and swaps it in under a lock; the window draws the latest one. Whatever a step costs, the
window keeps drawing and answering keys, and quitting never waits for a step in progress (the thread
is a daemon and is never joined).

Everything the window asks of the World (keys, picking and throwing, tilting planes, B, reload, Ctrl+S)
is a command, ``submit(fn)``: the physics side runs ``fn(sim)`` between steps, never in the middle of
one, and the window gets its result back in ``deliver`` on its own thread (where GL and pyglet live).

Two ways to run:

- free (``run_free``): the thread steps on the wall clock, through ``Simulation.advance`` (a fixed
  timestep from an accumulator; when a step costs more than real time the backlog is dropped, so the
  HUD's real-time factor is simulated seconds over wall seconds, as measured). Between batches it
  sleeps until the next step is due, counting the batch's own time as passed: a batch that ran late
  is followed by the next at once (timed from the batch's start, pile.toml's 15-20 ms frames of 1/60 s
  slept away a fifth of the wall time while the pile landed). ``busy_fraction`` says how much of the
  last half second it did not sleep by choice; the window draws less while it is near 1 (pacing.py);
- lockstep (``advance(dt)``): the caller's thread takes the lock and advances exactly ``dt`` of real
  time, applying the commands first. Tests and scripted runs use it for exact, repeatable frames.

Running ahead. While a live run plays at real speed and nothing is asked of it, the thread does not
wait for the wall clock: it steps up to ``lead`` (LEAD_SECONDS) ahead of what the window shows and queues a
``Shown`` per LEAD_FRAME of simulated time, each due at the wall time its simulated time maps to; the
window shows the latest one due (``shown``). What a cheap stretch saves pays for a dear one: pile.toml's
fall costs 2-4 ms a 1/60 s frame and the heaviest part of its landing 18-22 ms, so beside the window
it lands in real time instead of at 0.8 of it. When the queue runs dry the window shows each state as
it comes, in slow motion, and the real-time factor (``Simulation.lead``) says so: it is the speed the
run is shown at. Whatever the window asks (a key, a drag, B, Ctrl+S: every command but the file watch)
is answered from the state it shows: the steps taken ahead are dropped first, the World put back at
the step shown (``History.mark`` keeps a snapshot of each step queued ahead, so that is one restore),
and the run goes on from there, as resuming from the past does.

Held before X. While a scene waits for X and nothing is asked of the thread (for ``HOLD_QUIET``),
the drop is started but held at its first state (``Simulation.hold``): the thread steps the first
``hold_reach`` of it (HOLD_REACH, 10 s; less where the states queued would take more than
HOLD_MEMORY) and queues the states without a due time, while the window goes on showing the first
one. The run goes no further than the integrator ghosts have reached in their process (each state
queued shows them, and the HUD their energies, at its own step), and past the lead each step waits
first while the window lays out a frame (the scene before X is drawn as often as ever). X lets it go
(``Simulation.start``, a command that does not rewind): the queued states get their due times from
that instant, so the run starts with its lead already taken instead of building it meanwhile, and a
scene's first seconds are shown without a step taken beside them (the thread steps again once the
queue is down to the lead): the slopes with their ghosts landed at 58.6-59.9 FPS with the physics at
0.005 of a core, against 55.3-59.4 FPS and 0.24-0.33 held 1.5 s; pile.toml, held past its landing, at
59.3-59.5 against 46.8-49.8 held 1.9 s (docs/benchmarks.md). Anything else asked before X undoes the
hold first (``Simulation.unhold``: the world back at its first state, bit for bit, waiting as
before), then is done; the hold starts again once the thread is left alone. The integrator ghosts,
if on, start with the hold too. Scenes of more than ``HOLD_MAX_BALLS`` balls are not held (a batch of
their steps would keep the window's commands waiting), and a hold stops after ``HOLD_SECONDS`` of
stepping.

A thread rather than a process. First by benchmarks/physics_beside_drawing.py on a 2-core machine
with a CPU rasteriser (2026-12-02, heavily loaded): while pile.toml lands, 9.3 and 8.7 frames/s with
the physics on a thread against 8.3 and 10.1 in a process (physics 18 and 16 steps/s against 17 and
17); with slopes.toml stepping flat out, 15 and 19 frames/s against 16 and 16 (194 and 225 steps/s
against 177 and 182). Then, with the physics near real time (1/60 s frames, later that day), by the
physics thread's own clocks in benchmarks/viewer_window_fps.py --threads: while pile.toml lands beside
the window it is asleep about 2 % of the wall time beyond the sleeps it chose, which bounds what it
waits for the GIL; the rest is on a core (55-65 %) or waiting for one (30-40 %, the machine shared),
and it spends as much CPU per simulated second as headless. What it lacks is CPU, not the GIL, and a
process would share the same cores (and, with the kernel's autogroups, the same share of them). A
thread keeps every World-touching feature (history, ghosts, recording, picking, saving) in one address
space with plain function calls as commands. The GIL switch interval is lowered while it runs so the
window, coming back from a GL call, waits at most about a millisecond for the physics to let go.

The window's frame first. Each GL call the window's thread makes lets go of the GIL, and coming back
it waits for the physics thread to let go in turn, up to the switch interval: a frame of a hundred
calls laid out beside a batch of steps is a hundred hand-overs. A run at least ``GATE_AHEAD`` s ahead
of what the window shows, stepping at most ``GATE_BUSY`` of the time, has time to spare, so before
each step it waits (``GATE_WAIT`` at most) while the window's thread lays out a frame
(``window_drawing``), and steps while the window waits for the rasteriser, for the display, or for
its next frame. Otherwise it steps at once, as before: a physics busy nearly all the time made to
wait falls behind, and the window then draws less to give it the CPU back (pile.toml after its
landing: 42.1-44.7 FPS against 45.9-52.7 in 4 pairs when it waited too). The slopes with ghosts, 6
pairs in a slow spell of the host: landing at 50.0, 41.8, 45.3, 50.1, 54.3, 58.7 FPS against 48.1,
40.0, 50.9, 40.1, 31.3, 41.0, the window's thread at 3.1-6.0 ms of CPU a frame against 4.9-7.5.

The integrator ghosts are the exception (``ghosts_apart``, the viewer's default; ghostproc.py): their
three worlds are stepped in a process of their own. They depend on nothing the main run does after
their origin but its edits and moves in time, so the child steps them ahead on its own and sends
back each step's poses and energies; this thread steps the main run alone. With all four worlds here
the slopes demo with ghosts took 0.51-0.64 CPU s per simulated s, the window was paced at 33 FPS
(the thread busy) and shown at 24.6 FPS; in paired runs on a loaded machine (load 4-7) the ghosts'
process had the landing shown at 0.92-1.00 of real time against 0.36-0.58 (docs/benchmarks.md). Lockstep
(``advance``, ``sync``) waits for the ghosts to reach the main run's step, so tests see them exactly.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

from .handover import HudFacts, Needs, Shown, capture
from .pacing import BUSY_FAST
from .simulation import Phase, Simulation

HUD_INTERVAL = 0.1  # seconds between readings of the HUD's facts (energy, drifts, profile)
IDLE_HANDOVER = 0.5  # seconds between hand-overs while nothing steps and no command came
IDLE_WAIT = 0.05  # seconds the thread sleeps when nothing runs (a command wakes it at once)
BUSY_WINDOW = 0.5  # seconds of wall time over which the thread's busy share is measured
# s of wall time the physics may run ahead of what the window shows while a live run plays (see
# "Running ahead" above; 0 turns it off, for comparisons), and s of simulated time per hand-over
# meanwhile. 1.5 s: held before X, pile.toml's lead then reaches 0.9 s into its landing. Half a
# second held stopped at the end of its fall, and the landing still ran the queue dry (0.89-0.93 of
# real time shown); a second fell short in the host's slow spells (0.92 and 0.96 in 24 runs); 1.5 s
# kept it at 0.995-0.999 in four runs alternated with 1 s (docs/benchmarks.md)
LEAD_SECONDS = 1.5
LEAD_FRAME = 1.0 / 60.0
# s: Python's GIL switch interval while the thread runs (5 ms by default): how long the window may
# wait for the GIL when it comes back from a GL call while the physics holds it
SWITCH_INTERVAL = 0.001
GHOST_WAIT = 120.0  # s lockstep waits at most for the ghosts' process to reach the main run's step
# s: how far ahead of what the window shows the run must be for the thread to wait, before each step
# while the window's thread lays out a frame (at most GATE_WAIT s; see "The window's frame first")
GATE_AHEAD = 0.5
GATE_WAIT = 0.01
GATE_BUSY = BUSY_FAST  # ... and only while it steps at most this share of the time: the pacer's full rate
HOLD_QUIET = 0.3  # s with no command before a waiting scene is held (see "Held before X")
# s of wall time a hold steps at most (not counting its waits): pile.toml's 3.6 s took 4-6 s of it
HOLD_SECONDS = 8.0
HOLD_MAX_BALLS = 20_000  # balls a scene may have to be held
# s of simulated time a hold steps ahead at most (see "Held before X"), and bytes the states it queues
# may take: each keeps a snapshot to go back to (History.mark; pile.toml's: 556 B a ball pickled) and a
# hand-over (the balls' poses and colours, about 150 B a ball, and the panel's copies of its plots'
# traces: the slopes' 600 states held 19 MB). The slopes' balls come to rest 5.5 s into their drop;
# pile.toml's 192 MB reach 3.6 s of it (its viewer 399 MB resident, against 296 with 96 MB and 1.9 s),
# past its landing: shown at 59.3-59.5 FPS against 46.8-49.8 (3 pairs)
HOLD_REACH = 10.0
HOLD_MEMORY = 192 << 20
QUEUED_BYTES_PER_BALL = 720
QUEUED_BYTES = 32 << 10


def tuning_from(environ: Mapping[str, str]) -> dict[str, Any]:
    """The thread's tuning as a benchmark sets it in the environment (read by the viewer when it starts
    the thread, and passed in): ``BALLPIT_LEAD`` (s; 0 holds the physics to the wall clock),
    ``BALLPIT_SWITCH`` (s), each LEAD_SECONDS and SWITCH_INTERVAL when not set, and ``BALLPIT_GHOSTS``
    (``process``, the default, or ``thread``: the integrator ghosts stepped on this thread),
    ``BALLPIT_HOLD`` (``0``: no hold before X), ``BALLPIT_HOLD_REACH`` (s, HOLD_REACH when not set)
    and ``BALLPIT_GATE`` (s, GATE_AHEAD when not set; ``inf``: the thread never waits for the window's
    frame)."""
    return {
        "lead": float(environ.get("BALLPIT_LEAD", LEAD_SECONDS)),
        "gate_ahead": float(environ.get("BALLPIT_GATE", GATE_AHEAD)),
        "hold": environ.get("BALLPIT_HOLD", "1") != "0",
        "hold_reach": float(environ.get("BALLPIT_HOLD_REACH", HOLD_REACH)),
        "switch_interval": float(environ.get("BALLPIT_SWITCH", SWITCH_INTERVAL)),
        "ghosts_apart": environ.get("BALLPIT_GHOSTS", "process") != "thread",
    }


Command = Callable[[Simulation], Any]
Then = Callable[[Any], None]


class PhysicsThread:
    """Steps one Simulation beside the window and hands over a ``Shown`` after every batch of steps."""

    def __init__(
        self,
        sim: Simulation,
        needs: Callable[[], Needs] = Needs,
        watch: Callable[[Simulation], Any] | None = None,
        lead: float = LEAD_SECONDS,
        switch_interval: float = SWITCH_INTERVAL,
        ghosts_apart: bool = False,
        hold: bool = True,
        gate_ahead: float = GATE_AHEAD,
        hold_reach: float = HOLD_REACH,
    ) -> None:
        self.sim = sim
        self.hold_reach = hold_reach  # s of its drop a waiting scene's hold steps at most
        self.gate_ahead = gate_ahead  # s ahead from which each step waits for the window's frame
        self.hold = hold  # a waiting scene is held, its first lead stepped before X
        if ghosts_apart:  # the integrator ghosts' worlds in a process of their own (ghostproc.py)
            sim.ghosts_apart()
        self.lead = lead  # s of wall time the run may be stepped ahead of what the window shows
        self.needs = needs  # what the window draws now (asked at each capture)
        self.watch = watch  # the panel's copy of the run, made at each capture (Shown.watch)
        self.lock = threading.Lock()  # held while the World changes: a step, a command, a capture
        self._handover_lock = threading.Lock()
        self._commands: deque[tuple[Command, Then | None, bool]] = deque()
        self._ahead: deque[tuple[float, Shown]] = deque()  # (due wall time, state), oldest first
        self._base: tuple[float, float] | None = None  # (wall, simulated) times that map to each other
        self._counted = (0.0, 0.0)  # (wall, simulated time shown) when the factor was last fed
        self._rewind = False  # the window asked for the state it shows (what it draws changed)
        self._holding = False  # the Simulation is held before X by this thread
        self._held_seconds = 0.0  # wall s the hold has stepped (not counting its waits for the window)
        self._asked_at = time.perf_counter()  # when a command last came
        self._results: deque[tuple[Then, Any]] = deque()
        self._wake = threading.Event()
        self._window_free = threading.Event()  # clear while the window's thread lays out a frame
        self._window_free.set()
        self._free = False
        self._restart_clock = True
        self._stopped = False
        self._hud: HudFacts | None = None
        self._hud_at = 0.0
        self.crash: str | None = None  # an error that stopped the thread (shown in the HUD)
        self.captures = 0
        self.idle_seconds = 0.0  # wall s slept by choice (paused, waiting for X, ahead of the clock)
        # the share of the latest BUSY_WINDOW the thread spent stepping or waiting for a core or the
        # GIL, not sleeping by choice: near 1, it is behind real time (the window draws less, pacing.py)
        self.busy_fraction = 0.0
        self._busy_since, self._busy_idle = time.perf_counter(), 0.0
        self.capture_seconds = 0.0  # wall s spent capturing hand-overs (benchmarks read both)
        with self.lock:
            self._shown = self._capture(force_hud=True)
        self._previous_switch = sys.getswitchinterval()
        sys.setswitchinterval(switch_interval)
        self._thread = threading.Thread(target=self._run, name="ballpit physics", daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ the window's side
    @property
    def shown(self) -> Shown:
        """The latest finished state handed over that is due now (see "Running ahead")."""
        with self._handover_lock:
            return self._take_due(time.perf_counter())

    def _take_due(self, now: float) -> Shown:
        """The queued states due by ``now`` become the one shown (call it under the hand-over lock)."""
        ahead = self._ahead
        while ahead and ahead[0][0] <= now:
            self._shown = ahead.popleft()[1]
        return self._shown

    def submit(self, command: Command, then: Then | None = None, rewind: bool = True) -> None:
        """Run ``command(sim)`` on the physics side between steps; ``then(result)`` later in ``deliver``.
        With ``rewind`` (the default) the command acts on the state the window shows: steps taken
        ahead of it are dropped first. Only what reads nothing the steps change may pass False."""
        self._commands.append((command, then, rewind))
        if rewind:  # the file watch's twice a second does not keep a waiting scene from being held
            self._asked_at = time.perf_counter()
        self._wake.set()

    def show_again(self) -> None:
        """What the window draws changed (an overlay on or off): hand the shown state over again, with
        it, instead of the states already captured ahead without it."""
        self._rewind = True
        self._asked_at = time.perf_counter()
        self._wake.set()

    def window_drawing(self, drawing: bool) -> None:
        """The window's thread starts (True) or ends (False) laying out a frame (see "The window's
        frame first")."""
        if drawing:
            self._window_free.clear()
        else:
            self._window_free.set()

    def run_free(self) -> None:
        """Step on the wall clock from now on (the window's real-time loop)."""
        if not self._free:
            self._restart_clock = True
            self._free = True
            self._wake.set()

    def advance(self, seconds: float) -> int:
        """Lockstep: stop running free, then advance exactly ``seconds`` of real time here (waiting for a
        step in progress to end). Returns the steps taken."""
        self._free = False
        with self.lock:
            self._rewind_to_shown()
            self._apply_commands()
            steps = self.sim.advance(seconds)
            self.sim.timeline.settle_ghosts(GHOST_WAIT)
            self._publish(force_hud=False)
        self.deliver()
        return steps

    def sync(self) -> None:
        """Apply the pending commands now, waiting for a step in progress (tests and scripted runs)."""
        with self.lock:
            if self.sim.held:
                self._rewind_to_shown()
            self._apply_commands()
            self.sim.timeline.settle_ghosts(GHOST_WAIT)
            self._publish(force_hud=True)
        self.deliver()

    def deliver(self) -> None:
        """Run the ``then`` callbacks of finished commands, on the caller's (the window's) thread."""
        while self._results:
            then, result = self._results.popleft()
            then(result)

    def refresh_hud(self) -> None:
        """Read the HUD's facts again at the next capture (after a key changed what it shows)."""
        self._hud_at = 0.0

    def stop(self) -> None:
        """Stop stepping. Never waits for a step in progress: the daemon thread ends after it, or with the
        process."""
        self._stopped = True
        self._free = False
        self._wake.set()
        sys.setswitchinterval(self._previous_switch)
        self.sim.close()  # the ghosts' process, if any: terminated, not waited for

    @property
    def pace(self) -> float:
        """The share of the asked speed the physics reached lately: real-time factor over time scale."""
        sim = self.sim
        return sim.real_time_factor / max(sim.time_scale, 1e-9)

    def live_rates(self, shown: Shown) -> HudFacts:
        """``shown``'s HUD facts with the real-time factor and steps per second as measured now. A state
        stepped ahead carries the readings of when it was stepped: the first 1.5 s after X, stepped
        while the scene was held, read 0 (the factor is the speed the window's states are shown at)."""
        sim, facts = self.sim, shown.hud
        if shown.generation != sim.generation or facts is None:
            return facts
        return replace(facts, real_time_factor=sim.real_time_factor, steps_per_second=sim.steps_per_second)

    def child_cpu(self) -> float:
        """CPU seconds used by the ghosts' process, if any (benchmarks add it to the physics')."""
        host = self.sim.ghost_host
        return host.child_cpu() if host is not None else 0.0

    @property
    def alive(self) -> bool:
        return self._thread.is_alive()

    # ------------------------------------------------------------------ the physics side
    def _run(self) -> None:
        last = published = time.perf_counter()
        while not self._stopped:
            self._measure_busy()
            if not self._free:
                self._sleep(IDLE_WAIT)
                continue
            wait = IDLE_WAIT
            with self.lock:
                if not self._free or self._stopped:
                    continue
                try:
                    # a copy made in one C call (the window's thread appends meanwhile: iterating the
                    # deque itself would raise if an append came between two items)
                    rewound = self._rewind or any(rewind for _, _, rewind in tuple(self._commands))
                    if rewound:
                        self._rewind_to_shown()
                    commands = self._apply_commands()
                    if self._holding and not self.sim.held:
                        self._released()  # X: the states stepped while held are due from now
                    now = time.perf_counter()
                    if self._restart_clock:
                        self._restart_clock, last = False, now
                    ahead_wait = None
                    if self._may_hold(now):
                        self._start_hold()
                    if self._may_run_ahead():
                        if rewound and commands:
                            self._publish(force_hud=True)  # what the commands did, shown at once
                        ahead_wait = self._run_ahead()
                        last = published = now
                    else:
                        self._base = None
                        steps = self.sim.advance(now - last)
                        last = now
                        news = self.sim.timeline.take_ghost_news()  # a seek's ghosts came, say
                        if steps or commands or news or now - published >= IDLE_HANDOVER:  # else as before:
                            self._publish(force_hud=False)  # the window may keep the view it drew
                            published = now
                except Exception as exc:  # never let the thread die silently: say why in the HUD
                    self.crash = f"physics thread stopped: {type(exc).__name__}: {exc}"
                    self.sim.error = self.crash
                    self._publish(force_hud=True)
                    print(f"ballpit: {self.crash}", file=sys.stderr, flush=True)
                    return
                sim = self.sim
                if ahead_wait is not None:
                    wait = ahead_wait
                elif sim.phase is Phase.RUNNING:  # sleep until the next step is due, counting the
                    # time this batch took as passed: a batch slower than real time owes a step now
                    owed = max(sim.timestep - sim.accumulator, 0.0) / max(sim.time_scale, 1e-9)
                    wait = owed - (time.perf_counter() - last)
            if wait > 0.0:
                self._sleep(min(wait, IDLE_WAIT))

    def _leave_the_frame_first(self) -> None:
        """Before each step of a batch taken far ahead: unless the thread is busy, wait (by choice)
        until the window's thread has laid out its frame, GATE_WAIT at most."""
        if self.busy_fraction <= GATE_BUSY:
            self._after_the_frame()

    def _after_the_frame(self) -> None:
        """Before each step held past the lead (and far ahead, ``_leave_the_frame_first``): wait (by
        choice) until the window's thread has laid out its frame, GATE_WAIT at most."""
        if not self._window_free.is_set():
            self._idle(self._window_free, GATE_WAIT)

    def _sleep(self, seconds: float) -> None:
        """Wait until ``seconds`` pass or a command comes, counting the time as idle."""
        self._idle(self._wake, seconds)
        self._wake.clear()

    def _idle(self, event: threading.Event, seconds: float) -> None:
        """Wait for ``event`` at most ``seconds``, the time counted as slept by choice."""
        slept = time.perf_counter()
        event.wait(seconds)
        self.idle_seconds += time.perf_counter() - slept

    def _measure_busy(self) -> None:
        """Every ``BUSY_WINDOW`` seconds, the share of them the thread did not sleep by choice."""
        now = time.perf_counter()
        elapsed = now - self._busy_since
        if elapsed >= BUSY_WINDOW:
            idle = self.idle_seconds - self._busy_idle
            self.busy_fraction = min(max(1.0 - idle / elapsed, 0.0), 1.0)
            self._busy_since, self._busy_idle = now, self.idle_seconds

    def _apply_commands(self) -> int:
        """Run the commands sent so far; returns how many."""
        count = 0
        while self._commands:
            count += 1
            command, then, _ = self._commands.popleft()
            try:
                result = command(self.sim)
            except Exception as exc:  # a failed command is reported, the physics goes on
                result = exc
                self.sim.error = f"{type(exc).__name__}: {exc}"
                print(f"ballpit: {self.sim.error}", file=sys.stderr, flush=True)
            if then is not None:
                self._results.append((then, result))
        return count

    # ------------------------------------------------------------------ running ahead
    def _may_run_ahead(self) -> bool:
        """A live run plays (after X, not paused, not a replay): its steps may be taken ahead."""
        sim = self.sim
        timeline = sim.timeline
        return (
            self.lead > 0.0
            and (sim.phase is Phase.RUNNING or sim.held)
            and timeline.history is not None
            and timeline.replay is None
        )

    def _run_ahead(self) -> float:
        """Step one LEAD_FRAME of simulated time and queue the state, unless the run is ``lead`` seconds
        ahead of what the window shows already; returns how long to wait before the next batch."""
        sim = self.sim
        history = sim.timeline.history
        scale = max(sim.time_scale, 1e-9)
        now = time.perf_counter()
        held = sim.held  # nothing is due before X: the window shows the first state
        if self._base is None:  # the window shows the present: time what comes from here
            self._base = (math.inf if held else now, sim.world.time)
            self._counted = (now, sim.world.time)
            history.mark()
        wall0, sim0 = self._base
        # the simulated time shown now
        shown = sim0 if held else min(sim0 + (now - wall0) * scale, sim.world.time)
        ahead = (sim.world.time - shown) / scale
        if held and (ahead >= self._reach() or self._held_seconds >= HOLD_SECONDS):
            return IDLE_WAIT  # held as far as it goes: nothing is due until X
        if held and self._ghosts_behind():
            return IDLE_WAIT  # no further than the ghosts: each state queued has theirs
        if not held and ahead >= self.lead:
            self._count_shown(now, shown)
            return min(ahead - self.lead + 1e-3, IDLE_WAIT)
        if held:  # past the lead, the window's frame first: X may be far off
            first = self._after_the_frame if ahead >= self.lead else None
        else:  # far ahead, with time to spare: the window's frame first
            first = self._leave_the_frame_first if ahead >= self.gate_ahead else None
        waited = self.idle_seconds
        sim.lead(self._batch_steps(), first)
        waited = self.idle_seconds - waited  # for the window's frame, before steps
        state = self._capture(force_hud=False, ahead=True)
        done = time.perf_counter()
        due = wall0 + (state.time - sim0) / scale  # never, while held
        if due <= done:  # behind: the window waits for this state: shown now, the rest timed from it
            self._base, due = (done, state.time), done
        else:  # ahead: a command may come back to it
            history.mark()
        if held:
            self._held_seconds += done - now - waited
        else:
            wall0, sim0 = self._base
            self._count_shown(done, min(sim0 + (done - wall0) * scale, state.time))
        with self._handover_lock:
            self._ahead.append((due, state))
            step = self._take_due(done).step
        if step is not None:
            history.unmark_before(step)
        return 0.0

    # ------------------------------------------------------------------ held before X
    def _may_hold(self, now: float) -> bool:
        """A scene waits for X and nothing was asked for a while: its drop may be held (see "Held
        before X")."""
        sim = self.sim
        return (
            self.hold
            and self.lead > 0.0
            and sim.phase is Phase.WAITING
            and not sim.held
            and sim.timeline.replay is None
            and sim.ball_count <= HOLD_MAX_BALLS
            and not self._commands
            and now - self._asked_at >= HOLD_QUIET
        )

    def _reach(self) -> float:
        """How far ahead the hold steps: ``hold_reach``, less where the states it queues would take more
        than HOLD_MEMORY (pile10k.toml: 0.4 s, its 26 snapshots 150 MB) or the ghosts' frames kept would
        not cover them."""
        sim = self.sim
        queued = (QUEUED_BYTES + sim.ball_count * QUEUED_BYTES_PER_BALL) / LEAD_FRAME  # a simulated s
        reach = min(self.hold_reach, HOLD_MEMORY / queued)
        ghosts = sim.timeline.ghosts
        if ghosts is not None:
            reach = min(reach, ghosts.span * sim.timestep)
        return reach

    def _ghosts_behind(self) -> bool:
        """The ghosts, stepped in their own process, have not reached the step of the run's next batch."""
        ghosts, history = self.sim.timeline.ghosts, self.sim.timeline.history
        if ghosts is None or not ghosts.remote or history is None:  # stepped here, with the run
            return False
        reached = ghosts.reached
        return reached is None or reached < history.current + self._batch_steps()

    def _batch_steps(self) -> int:
        """The steps of one batch taken ahead: LEAD_FRAME of simulated time, one at least."""
        return max(1, round(LEAD_FRAME / self.sim.timestep))

    def _start_hold(self) -> None:
        """Hold the drop: the state shown now is its first (step 0 of the history it starts)."""
        if not self.sim.hold():
            return
        self._holding, self._held_seconds, self._base = True, 0.0, None
        self._hud_at = 0.0  # the states stepped now are shown running: read the HUD's facts afresh
        with self._handover_lock:
            if self._shown.generation == self.sim.generation:
                self._shown.step = 0  # it is: nothing changed the world since it was captured

    def _released(self) -> None:
        """X let the held run go (or a failed step ended the hold; anything else asked undoes it first,
        ``_rewind_to_shown``): the states stepped meanwhile are due from now, each at its simulated time
        from the first."""
        self._holding = False
        sim = self.sim
        if self._base is None or sim.phase is not Phase.RUNNING:
            self._base = None
            return
        now, sim0 = time.perf_counter(), self._base[1]
        scale = max(sim.time_scale, 1e-9)
        self._base = self._counted = (now, sim0)
        with self._handover_lock:
            self._ahead = deque((now + (state.time - sim0) / scale, state) for _, state in self._ahead)

    def _count_shown(self, now: float, shown: float) -> None:
        """The window's state had reached simulated time ``shown`` at wall time ``now``: the speed it is
        shown at, for the real-time factor (both read at the same instants, so they add up)."""
        wall, simulated = self._counted
        self.sim.count_shown(now - wall, shown - simulated)
        self._counted = (now, shown)

    def _rewind_to_shown(self) -> None:
        """Drop the states queued ahead of the one the window shows, and put the World back at it (the
        future is dropped, as resuming from the past does): a command acts on what the user sees."""
        asked, self._rewind = self._rewind, False
        self._base = None
        with self._handover_lock:
            shown = self._take_due(time.perf_counter())
            queued = len(self._ahead)
            self._ahead.clear()
        sim = self.sim
        history = sim.timeline.history
        step = shown.step if shown.generation == sim.generation else None
        if sim.held:  # before X: back to waiting at the first state
            sim.unhold()
            self._holding, asked = False, True
        elif queued and history is not None and step is not None and step < history.current:
            sim.timeline.seek(step)
            sim.resume_from_here()
            asked = True
        if asked:
            self._publish(force_hud=True)

    def _capture(self, force_hud: bool, ahead: bool = False) -> Shown:
        """A Shown of the state now. The HUD's facts are read afresh every HUD_INTERVAL of the time the
        window shows it in: wall time, or for a state ``ahead`` (queued), its simulated time."""
        now = time.perf_counter()
        needs = self.needs()
        hud = self._hud
        if ahead and hud is not None:  # due HUD_INTERVAL after the facts' state, or stepped back from it
            since = (self.sim.world.time - hud.time) / max(self.sim.time_scale, 1e-9)
            due = not 0.0 <= since < HUD_INTERVAL
        else:
            due = now >= self._hud_at
        if force_hud or hud is None or due or not needs.hud:
            hud = HudFacts.of(self.sim)
            self._hud, self._hud_at = hud, now + HUD_INTERVAL
        self.captures += 1
        shown = capture(self.sim, needs, hud=hud)
        if self.watch is not None:
            shown.watch = self.watch(self.sim)
        return shown

    def _publish(self, force_hud: bool) -> None:
        started = time.perf_counter()
        shown = self._capture(force_hud)
        self.capture_seconds += time.perf_counter() - started
        with self._handover_lock:
            self._ahead.clear()
            self._shown = shown
