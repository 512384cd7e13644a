"""Screen-space parts of the window: the timeline bar along the bottom (drag on it to scrub) and the
energy plot (P) in the top-right corner, drawn by the renderer's overlay pass, with pyglet labels.

``timeline_bar`` and ``plot_rect`` are pure geometry (window pixels, y up), so tests can find where to
point; ``ScreenOverlay`` owns the labels and turns pointer events on the bar into ``Simulation.scrub``.
"""

from __future__ import annotations

import time

import numpy as np
import pyglet

from .energyplot import legend as plot_legend
from .energyplot import legend_layout, plot_shapes
from .hud import FONT, TEXT_COLOR
from .overlays import VERTEX_WIDTH
from .stepper import PhysicsThread

BAR_MARGIN = 10  # px from the window's sides and bottom
BAR_HEIGHT = 14
BAR_LABEL_GAP = 4
PLOT_SIZE = (380, 170)
BAR_BACK = (0.04, 0.05, 0.07, 0.75)
BAR_KEPT = (0.3, 0.42, 0.6, 0.9)
BAR_DONE = (0.45, 0.7, 1.0, 0.95)
BAR_CURSOR = (1.0, 1.0, 1.0, 1.0)
FONT_SIZE = 10
LABEL_INTERVAL = 0.1  # s: the bar's label is laid out again at most this often (as the HUD's text);
# at every frame its time, new each frame, cost about 1 ms of the window's thread (pyglet's layout)


def timeline_bar(width: int) -> tuple[float, float, float, float]:
    """The bar's (x, y, width, height) in window pixels, y up."""
    return (BAR_MARGIN, BAR_MARGIN, max(width - 2 * BAR_MARGIN, 10), BAR_HEIGHT)


def plot_rect(width: int, height: int) -> tuple[float, float, float, float]:
    """The energy plot's (x, y, width, height) in window pixels: the top-right corner."""
    w = min(PLOT_SIZE[0], max(width // 2, 120))
    h = min(PLOT_SIZE[1], max(height // 3, 60))
    return (width - BAR_MARGIN - w, height - BAR_MARGIN - h - 18, w, h)


def _rect(x: float, y: float, w: float, h: float, color: tuple) -> np.ndarray:
    out = np.zeros((6, VERTEX_WIDTH), dtype=np.float32)
    out[:, :2] = [[x, y], [x + w, y], [x + w, y + h], [x, y], [x + w, y + h], [x, y + h]]
    out[:, 3:] = color
    return out


def bar_shapes(width: int, fraction: float) -> np.ndarray:
    """Triangles of the bar: the span kept, the part up to the present and a cursor there."""
    x, y, w, h = timeline_bar(width)
    cursor = x + fraction * w
    return np.concatenate([
        _rect(x - 2, y - 2, w + 4, h + 4, BAR_BACK),
        _rect(x, y, w, h, BAR_KEPT),
        _rect(x, y + 3, fraction * w, h - 6, BAR_DONE),
        _rect(cursor - 2, y - 3, 4, h + 6, BAR_CURSOR),
    ])  # fmt: skip


class ScreenOverlay:
    """The timeline bar and the energy plot of one viewer window."""

    def __init__(self, window: pyglet.window.Window, physics: PhysicsThread) -> None:
        self.window = window
        self.physics = physics  # the bar and plot draw what it handed over; scrubbing is a command to it
        self.show_plot = False
        self.scrubbing = False
        self.bar_label = pyglet.text.Label(
            "", font_name=FONT, font_size=FONT_SIZE, color=TEXT_COLOR, anchor_x="right", anchor_y="bottom"
        )
        self._label_at = 0.0  # when the bar's label may change next
        self.plot_labels: list[pyglet.text.Label] = []
        self.plot_batch = pyglet.graphics.Batch()

    @property
    def bar_shown(self) -> bool:
        return self.physics.shown.bar is not None

    def bottom_clearance(self) -> int:
        """Pixels the bar and its label take at the bottom (the HUD puts its messages above them)."""
        return BAR_HEIGHT + BAR_MARGIN + 20 if self.bar_shown else 0

    # ------------------------------------------------------------------ pointer
    def _fraction_at(self, x: float) -> float:
        bx, _, bw, _ = timeline_bar(self.window.width)
        return float(np.clip((x - bx) / bw, 0.0, 1.0))

    def on_bar(self, x: float, y: float) -> bool:
        bx, by, bw, bh = timeline_bar(self.window.width)
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
        """Build this frame's bar and plot geometry and hand it to the renderer."""
        width, height = self.window.width, self.window.height
        triangles, lines = [], []
        shown = self.physics.shown
        bar = shown.bar
        if bar is not None:
            triangles.append(bar_shapes(width, bar.fraction))
            text = f"{bar.kind}  {bar.now:.3f} s of {bar.oldest:.2f}–{bar.newest:.2f} s  (drag to scrub)"
            now = time.perf_counter()
            if self.bar_label.text != text and now >= self._label_at:
                self.bar_label.text = text
                self._label_at = now + LABEL_INTERVAL
            self.bar_label.x = width - BAR_MARGIN
            self.bar_label.y = BAR_MARGIN + BAR_HEIGHT + BAR_LABEL_GAP
        if self.show_plot and shown.energy is not None:
            rect = plot_rect(width, height)
            ghosts = bool(shown.ghosts)
            panel, curves, (low, high) = plot_shapes(shown.energy, rect, ghosts)
            triangles.append(panel)
            lines.append(curves)
            legend = plot_legend(shown.energy.series(), ghosts)
            self._plot_labels(rect, low, high, legend, shown.energy.window)
        empty = np.zeros((0, VERTEX_WIDTH), dtype=np.float32)
        renderer.upload_screen(  # type: ignore[attr-defined]
            np.concatenate(triangles) if triangles else empty,
            np.concatenate(lines) if lines else empty,
            (width, height),
        )

    def _plot_labels(
        self, rect: tuple, low: float, high: float, items: list[tuple[str, tuple]], window: float
    ) -> None:
        x, y, _, h = rect
        texts = [(f"energy, last {window:g} s   {low:.3g} … {high:.3g} J",
                  TEXT_COLOR, x, y + h + 4)]  # fmt: skip
        for text, color in items:
            texts.append((text, tuple(round(c * 255) for c in color[:3]) + (255,), 0, y + 4))
        while len(self.plot_labels) < len(texts):
            self.plot_labels.append(pyglet.text.Label(
                "", font_name=FONT, font_size=FONT_SIZE, anchor_y="bottom", batch=self.plot_batch
            ))  # fmt: skip
        for label, (text, color, lx, ly) in zip(self.plot_labels, texts, strict=False):
            if label.text != text:
                label.text = text
            label.color, label.x, label.y = color, lx, ly
        legend = self.plot_labels[1 : len(texts)]  # along the bottom of the plot, in rows that fit it
        places = legend_layout([lb.content_width for lb in legend], rect, legend[0].content_height if legend
                               else 0.0)  # fmt: skip
        for label, (lx, ly) in zip(legend, places, strict=True):
            label.x, label.y = lx, ly
        for label in self.plot_labels[len(texts) :]:
            label.text = ""

    def draw_labels(self) -> None:
        if self.bar_shown:
            self.bar_label.draw()
        if self.show_plot:
            self.plot_batch.draw()
