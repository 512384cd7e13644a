"""The ghosts' worlds in a process of their own, beside the window's physics thread.

With the ghosts on, the slopes demo steps four worlds; on one physics thread they took most of a core
and the window, waiting on it for the GIL and a core, drew a third of its frames. Here the three ghost
worlds are stepped in a child process (``python -m ballpit.viewer.ghostproc``, a fresh interpreter
that imports the physics and this module, never pyglet or GL, talking over a socket pair with
``multiprocessing``'s pickling ``Connection``), so the main run's thread steps one world and the child
the rest, on the other core.

The ghosts depend on nothing the main run does after their origin except the edits made to it and the
moves in time, so the child does not wait to be told each step: it steps on by itself, up to ``AHEAD``
seconds of simulated time past the main run's latest step (``to``), and sends back each step's total
energies and, every ``frame_every`` steps, the balls' poses. The main run's side (``RemoteGhosts``)
keeps what came back by step; the window draws the ghosts of the step it shows, the HUD and the energy
plot read their energies. Every move in time (``seek``) and every edit (``edited``, carrying the step it
was made at) is a new epoch: the child goes back to that step, the frames of the old epoch still on
their way are ignored, and those after the step are forgotten.

The child dies with the main process: it sees the pipe close (``EOFError``) at its next message or
send, and ``close`` also terminates it, never waiting for it. No GL here.
"""

from __future__ import annotations

import bisect
import os
import pickle
import signal
import socket
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any

from .ghosts import GhostFrame, GhostRun, Ghosts, GhostSpec

# s of simulated time the child steps past the main run's latest step, at most: no further than half
# the span of the frames kept on the main side (``reach``). Far ahead, its work for the first seconds
# is done while the scene waits for X (the drop is held: stepper.py), not beside the window as it
# lands: slopes.toml's ghosts took 0.54-0.57 of a core while it landed 1 s ahead, 0.39-0.41 at 5 s
# (the resting balls' steps before they sleep are done by then), and the landing was drawn at 55-58
# FPS against 48-55 in three alternated pairs (docs/benchmarks.md)
AHEAD = 5.0
REAP_WAIT = 5.0  # s a closed child has to end before it is killed
TELL_EVERY = 1 / 32  # of the child's reach: how far the main run gets on between two "to" messages
BATCH = 4  # steps taken between looks at the pipe (one message back for them)
BODY_BUDGET = 400  # balls × ghosts sent with every step; beyond it, poses every 4 steps
# frames kept on the main side (about 17 s at 240 steps a second): the ones the window shows, those
# up to the main run's latest step (stepper.HOLD_REACH ahead of them before X) and AHEAD past it
KEEP_FRAMES = 4096
BODY_MEMORY = 64 << 20  # bytes of balls' poses kept at most on the main side (64 a ball per ghost)
# The child's niceness: when the window, the main run and the ghosts want more than the cores, the
# window's frames and the main run's real time come first and the ghosts fall behind (drawn at the
# latest step they reached) rather than the other way round; with CPU to spare it changes nothing.
NICE = 5


def reach(spec: GhostSpec) -> tuple[int, int, int]:
    """How far the ghosts of ``spec`` go: (steps the child steps past the main run's latest step,
    steps between the frames sent with balls' poses, frames with poses kept on the main side)."""
    ball_ghosts = len(spec.reference.spheres) * len(spec.integrators)
    every = 1 if ball_ghosts <= BODY_BUDGET else 4
    keep = int(min(KEEP_FRAMES, max(16, BODY_MEMORY // (64 * max(ball_ghosts, 1)))))
    ahead = min(round(AHEAD / spec.timestep), keep * every // 2, KEEP_FRAMES // 2) if spec.live else 0
    return ahead, every, keep


def serve(conn: Any) -> None:
    """The child's loop: build the ghosts, step them ahead, answer moves in time and edits. A ghost
    world that fails (a step, an edit) stops the ghosts: the error goes back to be shown."""
    state: dict[str, Any] = {"epoch": 0}
    while True:
        try:
            _serve(conn, state)
            return
        except Exception as exc:  # the ghosts stop; the child waits for the next start
            try:
                conn.send(("error", state["epoch"], f"{type(exc).__name__}: {exc}"))
            except (BrokenPipeError, EOFError, OSError):
                return


def _serve(conn: Any, state: dict[str, Any]) -> None:
    ghosts: Ghosts | None = None
    epoch, target, ahead, every = state["epoch"], 0, 0, 1
    while True:
        idle = ghosts is None or ghosts.current >= target + ahead
        if idle or conn.poll():
            try:
                message = conn.recv()
            except (EOFError, OSError):
                return
            kind = message[0]
            if kind == "stop":
                return
            if kind == "to":
                target = message[1]
                continue
            if kind == "off":
                ghosts = None
                continue
            epoch = state["epoch"] = message[1]
            if kind == "start":
                spec: GhostSpec = message[2]
                ghosts = Ghosts(spec)
                target = spec.target
                ahead, every, _ = reach(spec)
            elif ghosts is not None and kind == "seek":  # the main run is at that step now
                ghosts.seek(target := message[2])
            elif ghosts is not None and kind == "edit":
                ghosts.edited(message[3], step=(target := message[2]))
            if ghosts is not None:
                _send(conn, epoch, [ghosts.frame()])
            continue
        frames = []
        for _ in range(BATCH):
            if ghosts.current < ghosts.latest:  # went back in time: the same steps again
                ghosts.seek(ghosts.current + 1)
            else:
                ghosts.stepped()
            frames.append(ghosts.frame(bodies=ghosts.current % every == 0))
            if ghosts.current >= target + ahead:
                break
        if not _send(conn, epoch, frames):
            return


def _send(conn: Any, epoch: int, frames: list[GhostFrame]) -> bool:
    try:
        conn.send(("frames", epoch, frames))
    except (BrokenPipeError, EOFError, OSError):
        return False
    return True


class Frames:
    """Frames by step, at most ``keep`` of them (the oldest go first), found by bisection."""

    def __init__(self, keep: int) -> None:
        self.keep = keep
        self._steps: list[int] = []
        self._frames: dict[int, GhostFrame] = {}

    def add(self, frame: GhostFrame) -> None:
        if frame.step not in self._frames:
            bisect.insort(self._steps, frame.step)
        self._frames[frame.step] = frame
        if len(self._steps) > self.keep:
            del self._frames[self._steps.pop(0)]

    def forget_after(self, step: int | None) -> None:
        """Forget the frames after ``step`` (all when None)."""
        cut = 0 if step is None else bisect.bisect_right(self._steps, step)
        for gone in self._steps[cut:]:
            del self._frames[gone]
        del self._steps[cut:]

    def get(self, step: int) -> GhostFrame | None:
        return self._frames.get(step)

    def at_or_before(self, step: int | None) -> GhostFrame | None:
        """The frame of the latest step at or before ``step`` (None: the latest of all)."""
        index = len(self._steps) if step is None else bisect.bisect_right(self._steps, step)
        return self._frames[self._steps[index - 1]] if index else None


class GhostHost:
    """The child process and what it sent back, shared by the ghost runs of one Simulation in turn."""

    def __init__(self) -> None:
        ours, theirs = socket.socketpair()
        self._process = subprocess.Popen(
            [sys.executable, "-m", __name__, str(theirs.fileno())], pass_fds=(theirs.fileno(),)
        )
        theirs.close()
        self.pid = self._process.pid
        self._conn = Connection(ours.detach())
        self._send_lock = threading.Lock()
        self._lock = threading.Condition()
        self._epochs = 0
        self.epoch = 0  # frames of other epochs are ignored
        self._frames = Frames(KEEP_FRAMES)  # with balls
        self._totals = Frames(KEEP_FRAMES)  # every frame (the energies)
        self._news: deque[GhostFrame] = deque()
        self.received = 0  # frames received (benchmarks and tests read it)
        self.dead = False
        self.error: str | None = None  # what stopped the child's ghosts, as it said
        self._receiver = threading.Thread(target=self._receive, name="ballpit ghosts in", daemon=True)
        self._receiver.start()

    def child_cpu(self) -> float:
        """CPU seconds the child has used (Linux; 0 elsewhere): benchmarks add it to the physics'."""
        try:
            with open(f"/proc/{self.pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        except (OSError, IndexError, ValueError):
            return 0.0

    # ------------------------------------------------------------------ to the child
    def send(self, message: tuple) -> None:
        with self._send_lock:
            if self.dead:
                return
            try:
                self._conn.send(message)
            except (BrokenPipeError, EOFError, OSError):
                self.dead = True

    def start(self, spec: GhostSpec) -> None:
        """New ghosts from ``spec`` in place of any before (a new epoch, every frame forgotten)."""
        with self._lock:
            self._frames.keep = reach(spec)[2]
            self.error = None
        self.send(("start", self.new_epoch(None), spec))

    def new_epoch(self, keep_until: int | None) -> int:
        """Start an epoch: the frames after step ``keep_until`` are forgotten (all when None)."""
        with self._lock:
            self._epochs += 1
            self.epoch = self._epochs
            self._frames.forget_after(keep_until)
            self._totals.forget_after(keep_until)
            self._news.clear()
            return self.epoch

    # ------------------------------------------------------------------ from the child
    def _receive(self) -> None:
        while True:
            try:
                kind, epoch, frames = self._conn.recv()
            except (EOFError, OSError, TypeError, ValueError):
                with self._lock:
                    self.dead = True
                    self._lock.notify_all()
                return
            with self._lock:
                if epoch != self.epoch:
                    continue
                if kind == "error":
                    self.error = frames
                else:
                    for frame in frames:
                        self._totals.add(frame)
                        if frame.bodies is not None:
                            self._frames.add(frame)
                        self._news.append(frame)
                    self.received += len(frames)
                self._lock.notify_all()

    def frame_at(self, step: int | None, wait: float = 0.0) -> GhostFrame | None:
        """See ``GhostRun.frame_at``: waiting, until the child has reached ``step`` (any step when None)."""
        deadline = time.perf_counter() + wait
        with self._lock:
            while True:
                reached = self._totals.at_or_before(None) if step is None else self._totals.get(step)
                if reached is not None or wait <= 0.0:
                    return self._frames.at_or_before(step)
                left = deadline - time.perf_counter()
                if self.error is not None:
                    raise RuntimeError(f"the ghosts stopped: {self.error}")
                if self.dead or left <= 0.0:
                    raise RuntimeError("the ghosts' process stopped" if self.dead else
                                       "the ghosts' process did not answer")  # fmt: skip
                self._lock.wait(left)

    @property
    def reached(self) -> int | None:
        """The latest step of the main run the child has sent the ghosts of (this epoch)."""
        with self._lock:
            frame = self._totals.at_or_before(None)
            return frame.step if frame is not None else None

    def totals_at(self, step: int | None) -> dict[str, float] | None:
        with self._lock:
            frame = self._totals.at_or_before(None) if step is None else self._totals.get(step)
            return frame.totals if frame is not None else None

    def news(self) -> list[GhostFrame]:
        with self._lock:
            out = list(self._news)
            self._news.clear()
            return out

    def close(self) -> None:
        """Stop the child at once (never waits for it): a daemon thread reaps it once it has ended, so it
        leaves no zombie behind for the viewer's life (killed if it has not ended in REAP_WAIT s)."""
        self.send(("stop",))
        self.dead = True
        try:
            self._process.terminate()
        except OSError:
            pass
        threading.Thread(target=self._reap, name="ballpit ghosts reaper", daemon=True).start()

    def _reap(self) -> None:
        try:
            self._process.wait(timeout=REAP_WAIT)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()


class RemoteGhosts(GhostRun):
    """The ghosts of one run stepped in ``host``'s child: the main run's side of them."""

    remote = True

    def __init__(self, host: GhostHost, spec: GhostSpec) -> None:
        super().__init__(spec)
        self.host = host
        self.target = spec.target  # the main run's latest step, as far as the child was told
        self.ahead, every, keep = reach(spec)  # steps the child steps past it, ...
        # the frames kept reach from the one shown to the child's latest, ``ahead`` past the main run's
        self.span = min(keep * every, KEEP_FRAMES) - self.ahead
        self._told = spec.target
        self._on = True
        host.start(spec)

    def stepped(self) -> None:
        """The main run took a live step (the child is told at the next ``flush``)."""
        self.target += 1

    def flush(self, soon: bool = False) -> None:
        """Tell the child how far the main run has got. ``soon`` (every frame's energy sample): only once
        it has got TELL_EVERY of the child's reach on since last told (0.13 s for slopes.toml), so the
        physics thread sends a few messages a second instead of 60 (each a write that lets go of the
        GIL and waits to have it back: 4 % of the thread's time), and the child keeps nearly all its
        reach. (At an eighth, the slopes' ghosts stepped half a second less ahead, more of it beside
        the landing: 0.23-0.34 of a core against 0.12-0.14.)"""
        told = self.target - self._told
        if told and (not soon or told >= max(round(self.ahead * TELL_EVERY), 1)):
            self._told = self.target
            self.host.send(("to", self.target))

    def edited(self, change: Callable[[Any], object], step: int | None = None) -> None:
        """The main run was changed by hand at ``step``: so is each ghost there (``change`` is pickled:
        a module-level function or a ``functools.partial`` of one, not a closure)."""
        try:
            pickle.dumps(change)
        except (pickle.PicklingError, AttributeError, TypeError) as exc:
            raise TypeError(f"an edit sent to the ghosts must pickle (no closures): {exc}") from exc
        self.flush()
        self.target = self._told = step if step is not None else self.target
        keep = None if step is None else step - 1
        self.host.send(("edit", self.host.new_epoch(keep), self.target, change))

    def seek(self, step: int) -> None:
        """The main run moved to ``step`` of its history: the ghosts follow."""
        self.target = self._told = step
        self.host.send(("seek", self.host.new_epoch(step), step))

    def frame_at(self, step: int | None, wait: float = 0.0) -> GhostFrame | None:
        return self.host.frame_at(step, wait)

    @property
    def reached(self) -> int | None:
        """The latest step of the main run the child has sent the ghosts of (None: none yet)."""
        return self.host.reached

    @property
    def error(self) -> str | None:
        return self.host.error

    def totals_at(self, step: int | None) -> dict[str, float] | None:
        return self.host.totals_at(step)

    def news(self) -> list[GhostFrame]:
        return self.host.news()

    def close(self) -> None:
        """These ghosts are off: the child lets their worlds go (the child itself stays for the next)."""
        if self._on:
            self._on = False
            self.host.send(("off",))
            self.host.new_epoch(None)


if __name__ == "__main__":
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl+C is the viewer's: the child ends with its pipe
    os.nice(int(os.environ.get("BALLPIT_GHOSTS_NICE", NICE)))
    serve(Connection(int(sys.argv[1])))
