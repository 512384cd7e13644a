"""Screen-space parts of the window: the timeline bar along the bottom (drag on it to scrub), drawn by
the renderer's overlay pass, with a pyglet label. (The energy plot, P, is the panel's, with ImPlot.)

``timeline_bar`` is pure geometry (window pixels, y up), so tests can find where to point;
``ScreenOverlay`` owns the label and turns pointer events on the bar into ``Simulation.scrub``.
"""

from __future__ import annotations

import time

import numpy as np
import pyglet

from .hud import FONT, TEXT_COLOR
from .overlays import VERTEX_WIDTH
from .stepper import PhysicsThread

BAR_MARGIN = 10  # px from the window's sides and bottom
BAR_HEIGHT = 14
BAR_LABEL_GAP = 4
BAR_BACK = (0.04, 0.05, 0.07, 0.75)
BAR_KEPT = (0.3, 0.42, 0.6, 0.9)
BAR_DONE = (0.45, 0.7, 1.0, 0.95)
BAR_CURSOR = (1.0, 1.0, 1.0, 1.0)
FONT_SIZE = 10
LABEL_INTERVAL = 0.1  # s: the bar's label is laid out again at most this often (as the HUD's text);
# at every frame its time, new each frame, cost about 1 ms of the window's thread (pyglet's layout)


def timeline_bar(width: int, left: int = 0) -> tuple[float, float, float, float]:
    """The bar's (x, y, width, height) in window pixels, y up, right of the ``left`` pixels the panel
    covers."""
    return (left + BAR_MARGIN, BAR_MARGIN, max(width - left - 2 * BAR_MARGIN, 10), BAR_HEIGHT)


def _rect(x: float, y: float, w: float, h: float, color: tuple) -> np.ndarray:
    out = np.zeros((6, VERTEX_WIDTH), dtype=np.float32)
    out[:, :2] = [[x, y], [x + w, y], [x + w, y + h], [x, y], [x + w, y + h], [x, y + h]]
    out[:, 3:] = color
    return out


def bar_shapes(width: int, fraction: float, left: int = 0) -> np.ndarray:
    """Triangles of the bar: the span kept, the part up to the present and a cursor there."""
    x, y, w, h = timeline_bar(width, left)
    cursor = x + fraction * w
    return np.concatenate([
        _rect(x - 2, y - 2, w + 4, h + 4, BAR_BACK),
        _rect(x, y, w, h, BAR_KEPT),
        _rect(x, y + 3, fraction * w, h - 6, BAR_DONE),
        _rect(cursor - 2, y - 3, 4, h + 6, BAR_CURSOR),
    ])  # fmt: skip


class ScreenOverlay:
    """The timeline bar of one viewer window."""

    def __init__(self, window: pyglet.window.Window, physics: PhysicsThread) -> None:
        self.window = window
        self.physics = physics  # the bar draws what it handed over; scrubbing is a command to it
        self.left = 0  # pixels the panel covers at the left: the bar runs right of them
        self.scrubbing = False
        self.bar_label = pyglet.text.Label(
            "", font_name=FONT, font_size=FONT_SIZE, color=TEXT_COLOR, anchor_x="right", anchor_y="bottom"
        )
        self._label_at = 0.0  # when the bar's label may change next
        self.label_changed = 0.0  # when it changed last (perf_counter)
        self.label_interval = LABEL_INTERVAL  # the window sets it as the HUD's (longer while busy)

    @property
    def bar_shown(self) -> bool:
        return self.physics.shown.bar is not None

    def bottom_clearance(self) -> int:
        """Pixels the bar and its label take at the bottom (the HUD puts its messages above them)."""
        return BAR_HEIGHT + BAR_MARGIN + 20 if self.bar_shown else 0

    # ------------------------------------------------------------------ pointer
    def _fraction_at(self, x: float) -> float:
        bx, _, bw, _ = timeline_bar(self.window.width, self.left)
        return float(np.clip((x - bx) / bw, 0.0, 1.0))

    def on_bar(self, x: float, y: float) -> bool:
        bx, by, bw, bh = timeline_bar(self.window.width, self.left)
        return self.bar_shown and bx - 4 <= x <= bx + bw + 4 and by - 6 <= y <= by + bh + 6

    def press(self, x: float, y: float) -> bool:
        """A left press: on the bar it starts scrubbing (True: the event is taken)."""
        if not self.on_bar(x, y):
            return False
        self.scrubbing = True
        self._scrub(self._fraction_at(x))
        return True

    def drag(self, x: float, y: float) -> bool:
        if not self.scrubbing:
            return False
        self._scrub(self._fraction_at(x))
        return True

    def _scrub(self, fraction: float) -> None:
        self.physics.submit(lambda sim: sim.scrub(fraction))

    def release(self) -> bool:
        was, self.scrubbing = self.scrubbing, False
        return was

    # ------------------------------------------------------------------ drawing
    def upload(self, renderer: object) -> None:
        """Build this frame's bar geometry and hand it to the renderer."""
        width, height = self.window.width, self.window.height
        triangles, lines = [], []
        shown = self.physics.shown
        bar = shown.bar
        if bar is not None:
            triangles.append(bar_shapes(width, bar.fraction, self.left))
            text = f"{bar.kind}  {bar.now:.3f} s of {bar.oldest:.2f}–{bar.newest:.2f} s  (drag to scrub)"
            now = time.perf_counter()
            if self.bar_label.text != text and now >= self._label_at:
                self.bar_label.text = text
                self._label_at, self.label_changed = now + self.label_interval, now
            self.bar_label.x = width - BAR_MARGIN
            self.bar_label.y = BAR_MARGIN + BAR_HEIGHT + BAR_LABEL_GAP
        empty = np.zeros((0, VERTEX_WIDTH), dtype=np.float32)
        renderer.upload_screen(  # type: ignore[attr-defined]
            np.concatenate(triangles) if triangles else empty,
            np.concatenate(lines) if lines else empty,
            (width, height),
        )

    def draw_labels(self) -> None:
        if self.bar_shown:
            self.bar_label.draw()
