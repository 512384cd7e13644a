"""Recording the window to MP4 (F9, or the panel's button): one frame per 1/fps of simulated time.

``FrameClock`` decides, from the simulated time of the state each window frame shows, how many video
frames that picture stands for; ``VideoRecorder`` reads the window's pixels when it stands for one or
more and hands them to the MP4 writer (mp4.py), whose encoder runs on a thread of its own. So the video
plays at the physics' real speed however fast the window draws: a window drawing 60 frames a second
gives every other picture to a 30 fps video, and one drawing 20 holds some pictures for two video
frames (the motion is as fast, only less smooth).

Time that does not run adds nothing: before X, while paused, and a step, a scrub or a jump while paused
are cuts, not stills. Going back (R, stepping back, a reload) is a cut too. The time scale (+ / −) is
simulated time too, so a run slowed to ×0.5 plays at its real speed in the video, twice as fast as it
was shown. The files go to ``videos/`` in the current directory, named by the time they started.

The video is the 3-D view with what is drawn over it (the HUD, the timeline bar), not the panel: the
pixels are read once the frame is drawn, panel and all, but only from the part of the window right of
the panel (``view_crop``). The panel is the recording user's tool; whoever watches the video wants the
scene, as MuJoCo's recordings hold the scene and not its UI. So the video keeps its size and its
framing when the panel is shown or hidden while it records (F4): the view is cut, or bordered in
black, round its centre.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

from .mp4 import MISSING_AV, Mp4Writer, even_size, have_av

VIDEO_DIRECTORY = "videos"  # under the current directory, as screenshots/
VIDEO_FPS = 30
SAME_TIME = 1e-9  # s: a state this close to a frame's time is on it (times are sums of steps)
REC_FONT_SIZE = 12
REC_COLOR = (255, 80, 70, 255)
REC_MARGIN = 10  # px from the window's top-right corner to the "● REC" mark


class FrameClock:
    """Which video frames a shown state stands for. Frame k shows simulated time ``origin + k/fps``;
    the first state shown after ``start`` is frame 0. No GL, so it is tested on its own."""

    def __init__(self, fps: float) -> None:
        self.fps = float(fps)
        self.frames = 0  # frames given out so far
        self.origin: float | None = None  # None: the next running state starts a new stretch (a cut)
        self.last = -math.inf  # simulated time of the latest state given a frame

    def due(self, sim_time: float, running: bool) -> int:
        """How many frames the state at ``sim_time`` stands for now (0: none is due). Only a running
        state gets frames; the first after a pause, or one earlier than the last recorded, starts a new
        stretch where it is."""
        if not running:
            self.origin = None
            return 0
        if self.origin is None or sim_time < self.last - SAME_TIME:
            self.origin = sim_time - self.frames / self.fps
        # the frames whose time has come: k with origin + k/fps <= sim_time
        reached = math.floor((sim_time - self.origin) * self.fps + SAME_TIME * self.fps) + 1
        count = max(reached - self.frames, 0)
        if count:
            self.frames += count
            self.last = sim_time
        return count


@dataclass(frozen=True)
class Finished:
    """A recording written: where, how many frames and how long it plays."""

    path: Path
    frames: int
    seconds: float


def video_path(directory: Path, now: datetime | None = None) -> Path:
    """A new ``ballpit-<date>-<time>[-n].mp4`` in ``directory``."""
    stamp = (now or datetime.now()).strftime("%Y%m%d-%H%M%S")
    path, n = directory / f"ballpit-{stamp}.mp4", 1
    while path.exists():
        n += 1
        path = directory / f"ballpit-{stamp}-{n}.mp4"
    return path


class VideoRecorder:
    """The video of one window: ``start``, ``stop``, ``toggle`` and ``is_recording`` (F9 and the panel's
    button), and ``frame`` after every drawn frame. ``say`` shows a message (the HUD's); ``left`` gives
    the window pixels at the left that the video leaves out (the panel's width: 0 while it is hidden)."""

    def __init__(
        self,
        window: object,
        say: Callable[[str], None],
        fps: float = VIDEO_FPS,
        directory: Path | None = None,
        left: Callable[[], int] = lambda: 0,
    ) -> None:
        import pyglet

        from .hud import FONT

        self.window = window
        self.say = say
        self.fps = fps
        self.directory = directory
        self.writer: Mp4Writer | None = None
        self.clock = FrameClock(fps)
        self.started_at: float | None = None  # simulated time of the first frame
        self.last_video: Finished | None = None
        self.error: str | None = None  # why the last start or recording failed (the panel shows it)
        self.left = left
        self.read_seconds = 0.0  # wall s spent reading pixels back (benchmarks read it)
        self.label = pyglet.text.Label(
            "", font_name=FONT, font_size=REC_FONT_SIZE, color=REC_COLOR, anchor_x="right", anchor_y="top"
        )

    @property
    def is_recording(self) -> bool:
        return self.writer is not None

    @property
    def seconds(self) -> float:
        """Seconds of video recorded so far (0 when not recording)."""
        return self.writer.duration if self.writer is not None else 0.0

    def _left_pixels(self, width: int) -> int:
        """The framebuffer columns the panel covers, in a framebuffer ``width`` wide (the window's
        pixels scaled, on a display whose framebuffer is denser than its window coordinates)."""
        scale = width / max(self.window.width, 1)  # type: ignore[attr-defined]
        return min(max(round(self.left() * scale), 0), max(width - 2, 0))

    def toggle(self) -> None:
        if self.is_recording:
            self.stop()
        else:
            self.start()

    def start(self) -> Path | None:
        """Start recording the window (its framebuffer's size now; an odd side loses its last row or
        column); returns the file it will be, or None, said in the HUD, without PyAV."""
        if self.writer is not None:
            return self.writer.path
        if not have_av():
            self._say(f"recording video {MISSING_AV}", error=True)
            return None
        directory = Path.cwd() / VIDEO_DIRECTORY if self.directory is None else self.directory
        try:
            directory.mkdir(parents=True, exist_ok=True)
            width, height = self.window.get_framebuffer_size()  # type: ignore[attr-defined]
            size = even_size(width - self._left_pixels(width), height)
            self.writer = Mp4Writer(video_path(directory), size, self.fps, kind="live")
        except (OSError, ValueError) as exc:
            self._say(f"cannot record video: {exc}", error=True)
            return None
        self.clock = FrameClock(self.fps)
        self.started_at = None
        self.error = None
        self._say(f"recording video to {_short(self.writer.path)} (F9 stops)")
        return self.writer.path

    def stop(self) -> Finished | None:
        """Finish the file (waiting for the encoder) and say where it went; None if nothing was being
        recorded. A recording in which no simulated time ran is removed (0 frames)."""
        writer, self.writer = self.writer, None
        if writer is None:
            return None
        try:
            if writer.frames == 0:
                writer.abort()
                finished = Finished(writer.path, 0, 0.0)
            else:
                finished = Finished(writer.close(), writer.frames, writer.duration)
        except OSError as exc:
            self._say(f"video failed: {exc}", error=True)
            return None
        self.last_video = finished
        if finished.frames == 0:
            self._say("video stopped: no simulated time ran, nothing written")
        else:
            self._say(f"video saved to {_short(finished.path)} ({finished.frames} frames, "
                      f"{finished.seconds:.2f} s)")  # fmt: skip
        return finished

    def frame(self, sim_time: float, running: bool, width: int, height: int) -> int:
        """After a frame is drawn, before the flip: read it back if it stands for any video frames and
        queue it for them, then mark the window as recording (after the read: the mark is not in the
        video). Returns how many video frames it stood for."""
        if self.writer is None:
            return 0
        count = self.clock.due(sim_time, running)
        if count:
            if self.started_at is None:
                self.started_at = sim_time
            started = time.perf_counter()
            image = read_back_buffer(width, height, self.writer.size, self._left_pixels(width))
            self.read_seconds += time.perf_counter() - started
            try:
                self.writer.write(image, repeat=count)
            except OSError as exc:
                self.writer.abort()
                self.writer = None
                self._say(f"video failed: {exc}", error=True)
                return 0
        self.label.text = f"● REC {self.writer.duration:5.1f} s"
        # the top-right corner: the HUD is at the top left, the help in the middle, the bar at the bottom
        self.label.x = self.window.width - REC_MARGIN  # type: ignore[attr-defined]
        self.label.y = self.window.height - REC_MARGIN  # type: ignore[attr-defined]
        self.label.draw()
        return count

    def _say(self, message: str, error: bool = False) -> None:
        """Show ``message`` in the window and print it (an error on stderr)."""
        if error:
            self.error = message
            print(f"ballpit: {message}", file=sys.stderr, flush=True)
        else:
            print(message, flush=True)
        self.say(message)


def _short(path: Path) -> Path:
    """``path`` relative to the current directory when it is under it."""
    return path.relative_to(Path.cwd()) if path.is_relative_to(Path.cwd()) else path


def view_crop(
    width: int, height: int, left: int, size: tuple[int, int]
) -> tuple[tuple[int, int, int, int], tuple[int, int]]:
    """Where a video frame of ``size`` comes from in a ``width`` x ``height`` back buffer whose ``left``
    columns are the panel's: the rectangle (x, y, w, h; GL's rows, from the bottom) of at most ``size``
    centred on the 3-D view right of the panel, and the (column, row from the top) of the frame it goes
    to, centred too: a view smaller than the video (the panel shown, the window shrunk since the
    video started) is bordered in black, a larger one cut, round the same centre."""
    view = width - left
    w, h = min(view, size[0]), min(height, size[1])
    return (left + (view - w) // 2, (height - h) // 2, w, h), ((size[0] - w) // 2, (size[1] - h) // 2)


def read_back_buffer(width: int, height: int, size: tuple[int, int], left: int = 0) -> np.ndarray:
    """The back buffer's 3-D view (right of the ``left`` columns) as an (H, W, 3) RGB frame of ``size``,
    top row first (``view_crop``)."""
    from OpenGL import GL

    (x, y, w, h), (column, row) = view_crop(width, height, left, size)
    pixels = np.zeros((size[1], size[0], 3), dtype=np.uint8)
    GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
    GL.glReadBuffer(GL.GL_BACK)
    data = GL.glReadPixels(x, y, w, h, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
    pixels[row : row + h, column : column + w] = np.frombuffer(data, dtype=np.uint8).reshape(h, w, 3)[::-1]
    return pixels
