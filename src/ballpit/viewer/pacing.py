"""How often the window draws: 60 frames a second, fewer while the physics needs the CPU they cost.

On a machine with few cores and a CPU rasteriser (two cores and llvmpipe here) every frame is CPU the
physics thread does not get: a frame of pile.toml at 800x450 costs about 9 ms of CPU between the
window's thread and llvmpipe's, so 60 frames a second take about half a core. Drawing at 33 instead
gave the physics beside it about a quarter more steps while the pile lands (benchmarks/
viewer_window_fps.py, docs/benchmarks.md). So the window draws at ``FAST_FPS`` while the physics
thread has time to spare, steps down to ``SLOW_FPS`` (above the 30 FPS the viewer promises) while it
is busy nearly all the time, that is behind real time or about to be, unless it is so far behind that
the CPU given back could not bring it near; and it goes back up once the physics has slack again.
Each pair of thresholds is apart so the rate does not flip every time they are measured. A GPU draws
a frame in a fraction of a millisecond of CPU; there the physics rarely needs the slower rate.

The panel is built with ImGui at most ``PANEL_HZ`` times a second, ``PANEL_BUSY_HZ`` while the
physics is busy, and at once when input comes; in between, its last build is drawn again from the GL
buffers that hold it. Its live values and plots move at that rate, which reads as smooth, and the frames
between do not pay the Python that lays ImGui's widgets out (0.6-0.8 ms of the window's thread on this
machine): CPU that, on two cores, the ghosts' process and the physics need. While the physics is busy
the HUD's text and the timeline bar's label are also laid out again only every ``HUD_BUSY_INTERVAL``
(pyglet lays the whole text out again whenever it changes: a few ms of the window's thread). The frames
themselves are as many as before. Frames stepped by hand (lockstep: tests, the offscreen renderer) build
the panel every frame unless the physics is busy.

No GL here: the window asks ``FramePacer.interval`` with the physics thread's busy share and pace.
"""

from __future__ import annotations

from dataclasses import dataclass

FAST_FPS = 60.0  # frames a second while the physics has time to spare (a usual display's rate)
SLOW_FPS = 33.0  # while it needs the CPU: just above the 30 FPS floor, with room for late frames
BUSY_SLOW = 0.9  # the physics spent at least this share of its last measured stretch stepping: slow
BUSY_FAST = 0.7  # at most this share: the full rate again
# The share of the asked speed (real-time factor over time scale) the physics must reach for the slower
# drawing to be worth it: the CPU it gives back buys about a quarter more steps, which brings a pile at
# 0.6-0.8 of real time to it, but leaves a scene at a tenth of it (pile10k.toml landing) in slow motion
# anyway, where the frames are worth more. Apart for the same reason as the busy thresholds.
PACE_SLOW = 0.25
PACE_FAST = 0.2
HUD_INTERVAL = 0.1  # s between HUD text updates
HUD_BUSY_INTERVAL = 0.25  # while the physics needs the CPU
PANEL_HZ = 20.0  # panel builds a second at most, with no input
PANEL_BUSY_HZ = 10.0  # panel builds a second at most while the physics needs the CPU


@dataclass
class FramePacer:
    """Chooses the time between frames from the physics thread's busy share and pace."""

    slow: bool = False
    thrifty: bool = True  # the panel (and while slow the HUD's text) built less often than drawn
    _panel_at: float = 0.0

    def interval(self, busy: float, pace: float = 1.0) -> float:
        """Seconds between frames, given the share of the latest stretch the physics spent stepping
        (``busy``, 0 to 1) and the share of the asked speed it reached (``pace``: its real-time factor
        over the time scale)."""
        if busy >= BUSY_SLOW and pace >= PACE_SLOW:
            self.slow = True
        elif busy <= BUSY_FAST or pace < PACE_FAST:
            self.slow = False
        return 1.0 / (SLOW_FPS if self.slow else FAST_FPS)

    def hud_interval(self) -> float:
        """Seconds until the HUD's text is laid out again."""
        return HUD_BUSY_INTERVAL if self.slow and self.thrifty else HUD_INTERVAL

    def build_panel(self, now: float, free: bool = True) -> bool:
        """Whether the panel is built this frame (else its last build is drawn again). Not ``free``
        (frames stepped by hand, lockstep), only the busy rate applies."""
        if not (self.slow or free):
            return True
        step = 1.0 / (PANEL_BUSY_HZ if self.slow else PANEL_HZ)
        if not self.thrifty or now >= self._panel_at:
            late = now - self._panel_at
            self._panel_at = (self._panel_at if late < step else now) + step  # from when it was due
            return True
        return False

    def describe(self) -> str:
        """For the profile page: the rate chosen and why."""
        if self.slow:
            return f"{SLOW_FPS:g} FPS at most: the physics needs the CPU"
        return f"{FAST_FPS:g} FPS at most"
