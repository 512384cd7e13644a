"""The HUD (H), the key help (F1), transient messages and the scene error, drawn with pyglet text.

``hud_lines`` builds the HUD text from a Simulation without GL so it can be tested; ``Hud`` lays the
labels out: the HUD panel in the window's top-left corner, errors and messages along the bottom, and
the help centred where it does not cover the HUD panel (beside it, else below it; only a window too
small for both shows the help alone).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import pyglet

from .controls import HELP
from .handover import HudFacts
from .simulation import Simulation

FONT = ("DejaVu Sans Mono", "Menlo", "Consolas", "Courier New", "monospace")
FONT_SIZE = 11  # points in a window of REFERENCE_SIZE; the HUD's text scales with the window (font_size)
REFERENCE_SIZE = (1280, 720)
FONT_SIZE_RANGE = (7.0, 22.0)  # points: still readable when small, not a poster when huge
TEXT_COLOR = (235, 238, 245, 255)
ERROR_COLOR = (255, 110, 100, 255)
PANEL_COLOR = (10, 12, 18, 190)
ERROR_BACK = (10, 12, 18, 225)  # the dark box under the error text, so red reads on the grey ground
MARGIN = 10
HELP_PAD = (40, 30)  # px the help's panel adds round its text (width, height)
HELP_MIN_FONT_SIZE = 6.0  # points: the help shrinks to fit beside the panel, not below this
NO_WRAP = 4000  # px: labels wider than any window, so lines break only where the text says
MESSAGE_SECONDS = 3.0


def hud_lines(
    sim: Simulation | HudFacts,
    fly_speed: float,
    overlays: str,
    extra: Sequence[str] = (),
    shot_speed: float | None = None,
) -> list[str]:
    """The HUD's text: time, speed, integrator, step rate, counts, energy, fly (and shot) speed,
    ``extra`` lines and the run state. ``sim``: a Simulation, or the facts the physics handed over."""
    f = sim if isinstance(sim, HudFacts) else HudFacts.of(sim)
    return [
        f"{f.name}",
        f"sim time    {f.time:9.3f} s",
        f"time scale  ×{f.time_scale:g}   real-time factor {f.real_time_factor:.2f}",
        f"integrator  {f.integrator.upper():5s} dt {f.timestep * 1000:.2f} ms",
        f"steps/s     {f.steps_per_second:9.0f}",
        f"balls       {f.balls:9d}",
        f"contacts    {f.contacts:9d}",
        f"kinetic E   {f.kinetic_energy:9.3f} J",
        f"fly speed   {fly_speed:9.2f} m/s" + ("" if shot_speed is None else f"  shot {shot_speed:g} m/s"),
        f"overlays    {overlays or 'none'} (C V T)",
        *extra,
        f"state       {f.state}",
        *f.timeline,
        "F1 help  F2 profile  H hide",
    ]


def profile_lines(sim: Simulation | HudFacts, drawn: Sequence[str] = ()) -> list[str]:
    """The HUD's profile page (F2): the step's time by stage, then ``drawn`` (what draws the window:
    the GL renderer and the quality)."""
    f = sim if isinstance(sim, HudFacts) else HudFacts.of(sim)
    drawn = list(drawn)
    if not f.profile:
        return [f"{f.name}: step profile", "no steps yet (X drops)", *drawn, "F2 back  H hide"]
    return [f"{f.name}: step profile, {f.profile[0]}", *f.profile[1:], *drawn, "F2 back  H hide"]


def font_size(width: int, height: int) -> float:
    """The HUD's font size (points) in a ``width`` x ``height`` window: FONT_SIZE at REFERENCE_SIZE,
    scaled by the side that shrank most (so the HUD keeps its share of the window), within
    FONT_SIZE_RANGE, in half points (each size is laid out once, not at every pixel of a drag)."""
    scale = min(width / REFERENCE_SIZE[0], height / REFERENCE_SIZE[1])
    low, high = FONT_SIZE_RANGE
    return min(max(round(2.0 * FONT_SIZE * scale) / 2.0, low), high)


# What a finite plane's colour says (scene/colours.py's ramp): its restitution, at the ramp's three
# stops. Most scenes' planes lie between them (the demo's slopes 0.55-0.95: green to orange).
PLANE_LEGEND = "plane colour = restitution: 0 slate blue (dead), 0.5 green, 1 orange (bouncy)"


def help_text() -> str:
    width = max(len(keys) for keys, _ in HELP)
    rows = [f"{keys:<{width}}  {what}" for keys, what in HELP]
    return "\n".join(["ballpit controls", "", *rows, "", PLANE_LEGEND])


class LineBlock:
    """Lines of text drawn one under another as one pyglet label each, so changing the text lays out
    again only the lines that changed. pyglet lays a label's whole text out again (glyph by glyph, in
    Python) whenever any of it changes: as one multiline label the HUD's dozen lines took the window's
    thread several milliseconds ten times a second, while only three or four of them change. Reads like
    a multiline label: ``text``, ``font_size``, ``x``, ``y`` (its top left), ``content_width`` and
    ``content_height``."""

    def __init__(self, batch: pyglet.graphics.Batch, font_size: float, color: tuple[int, ...]) -> None:
        self.batch, self.color = batch, color
        self._font_size = font_size
        self._x = self._y = 0.0
        self.lines: list[str] = []
        self.labels: list[pyglet.text.Label] = []
        self._step = _line_step(font_size)

    @property
    def text(self) -> str:
        return "\n".join(self.lines)

    def set_lines(self, lines: Sequence[str]) -> None:
        """Show ``lines``: the labels of lines that changed get their new text, the rest stay laid out."""
        for index, line in enumerate(lines):
            if index == len(self.labels):
                self.labels.append(self._label(line, index))
            elif self.lines[index] != line:
                self.labels[index].text = line
        for label in self.labels[len(lines) :]:
            label.delete()
        del self.labels[len(lines) :]
        self.lines = list(lines)

    def _label(self, text: str, index: int) -> pyglet.text.Label:
        return pyglet.text.Label(
            text, font_name=FONT, font_size=self._font_size, color=self.color, anchor_y="top",
            x=self._x, y=self._y - index * self._step, batch=self.batch,
        )  # fmt: skip

    @property
    def font_size(self) -> float:
        return self._font_size

    @font_size.setter
    def font_size(self, size: float) -> None:
        self._font_size, self._step = size, _line_step(size)
        for label in self.labels:
            label.font_size = size
        self._place()

    @property
    def x(self) -> float:
        return self._x

    @x.setter
    def x(self, value: float) -> None:
        self._x = value
        self._place()

    @property
    def y(self) -> float:
        return self._y

    @y.setter
    def y(self, value: float) -> None:
        self._y = value
        self._place()

    def _place(self) -> None:
        for index, label in enumerate(self.labels):
            label.position = (self._x, self._y - index * self._step, label.z)

    @property
    def content_width(self) -> float:
        return max((label.content_width for label in self.labels), default=0)

    @property
    def content_height(self) -> float:
        """As a multiline label's: a line's height for each line."""
        return len(self.labels) * self._step


_steps: dict[float, float] = {}


def _line_step(size: float) -> float:
    """The distance between the lines of a multiline label in the HUD's font at ``size`` points."""
    if size not in _steps:
        one = pyglet.text.Label("Xg", font_name=FONT, font_size=size, multiline=True, width=NO_WRAP)
        two = pyglet.text.Label("Xg\nXg", font_name=FONT, font_size=size, multiline=True, width=NO_WRAP)
        _steps[size] = two.content_height - one.content_height
        one.delete()
        two.delete()
    return _steps[size]


class Hud:
    """pyglet labels for the HUD panel, the help overlay, a transient message and the scene error."""

    def __init__(self, window: pyglet.window.Window) -> None:
        self.window = window
        self.batch = pyglet.graphics.Batch()
        self.help_batch = pyglet.graphics.Batch()
        self.show_hud = True
        self.page = "stats"  # or "profile" (F2)
        self.show_help = False
        self.text = ""
        self.error = ""
        self.message = ""
        self._message_until = 0.0
        self.help_hides_hud = False  # the window has no room for both: the help is drawn alone
        self.bottom = 0  # pixels kept clear at the bottom (the timeline bar): messages go above them
        self.left = 0  # pixels kept clear at the left (the panel): everything is drawn right of them
        self._help_layout_key: tuple = ()
        self.panel = pyglet.shapes.Rectangle(0, 0, 10, 10, color=PANEL_COLOR, batch=self.batch)
        self.label = LineBlock(self.batch, FONT_SIZE, TEXT_COLOR)
        self.error_back = pyglet.shapes.Rectangle(0, 0, 10, 10, color=ERROR_BACK)
        self.error_label = pyglet.text.Label(
            "", font_name=FONT, font_size=FONT_SIZE, color=ERROR_COLOR, multiline=True, width=900,
            anchor_y="bottom",
        )  # fmt: skip
        self.message_label = pyglet.text.Label(
            "", font_name=FONT, font_size=FONT_SIZE, color=TEXT_COLOR, anchor_y="bottom"
        )
        self.help_panel = pyglet.shapes.Rectangle(0, 0, 10, 10, color=PANEL_COLOR, batch=self.help_batch)
        self.help_label = pyglet.text.Label(
            help_text(), font_name=FONT, font_size=FONT_SIZE, color=TEXT_COLOR, multiline=True, width=NO_WRAP,
            anchor_x="center", anchor_y="center", batch=self.help_batch,
        )  # fmt: skip
        self.help_label.width = self.help_label.content_width + 2  # centred on its own lines, unwrapped
        self.layout()

    def layout(self) -> None:
        """Place the labels for the window's current size, their text scaled to it (``font_size``)."""
        w, h = self.window.width, self.window.height
        size = font_size(w, h)
        for label in (self.label, self.error_label, self.message_label):
            if label.font_size != size:
                label.font_size = size
        self._size_help(size, w - self.left - 2 * MARGIN - HELP_PAD[0])
        left = self.left + MARGIN
        self.label.x, self.label.y = left + 6, h - MARGIN - 4
        self.error_label.width = max(w - self.left - 2 * MARGIN, 100)
        self.error_label.x, self.error_label.y = left, MARGIN + self.bottom
        label = self.error_label
        self.error_back.position = (label.x - 5, label.y - 3)
        self.error_back.width, self.error_back.height = label.content_width + 10, label.content_height + 6
        self.message_label.x = left
        self.message_label.y = (
            MARGIN + self.bottom + (self.error_label.content_height + 6 if self.error else 0)
        )
        self._fit_panel()

    def _size_help(self, size: float, room: float) -> None:
        """The help's text at the HUD's ``size``, smaller if its lines would be wider than the ``room``
        (px) right of the panel (down to HELP_MIN_FONT_SIZE)."""
        help_label = self.help_label
        if help_label.font_size != size:
            help_label.font_size = size
        if help_label.content_width > room:  # text widths scale with the font size
            smaller = math.floor(2.0 * size * room / help_label.content_width) / 2.0
            help_label.font_size = max(smaller, HELP_MIN_FONT_SIZE)
        if help_label.width != help_label.content_width + 2:
            help_label.width = help_label.content_width + 2
            self._help_layout_key = ()

    def _fit_panel(self) -> None:
        h = self.window.height
        pw, ph = self.label.content_width + 14, self.label.content_height + 10
        self.panel.position = (self.left + MARGIN, h - MARGIN - ph)
        self.panel.width, self.panel.height = pw, ph
        self._place_help()

    def _place_help(self) -> None:
        """Put the help panel where it does not cover the HUD panel: centred in the 3-D view (right of
        the ImGui panel) if it is clear of it there, else in the room right of it, else below it; if
        the window has room for none of these the help is drawn alone (``help_hides_hud``)."""
        w, h = self.window.width, self.window.height
        panel = self.panel
        key = (w, h, self.left, self.show_hud, panel.x, panel.y, panel.width, panel.height)
        if key == self._help_layout_key:
            return
        self._help_layout_key = key
        hw, hh = self.help_label.content_width + HELP_PAD[0], self.help_label.content_height + HELP_PAD[1]
        x = max(self.left + (w - self.left) // 2 - hw // 2, self.left + MARGIN)
        y = min(max(h // 2 - hh // 2, MARGIN), h - MARGIN - hh)  # centred, kept on screen if it fits
        hud_right, hud_bottom = panel.x + panel.width + MARGIN, panel.y - MARGIN
        self.help_hides_hud = False
        if self.show_hud and x < hud_right and y + hh > hud_bottom:  # centred, it would cover the HUD
            if hud_right + hw <= w - MARGIN:  # beside the HUD, centred in the room right of it
                x = hud_right + (w - MARGIN - hud_right - hw) // 2
            elif hh <= hud_bottom - MARGIN:  # below the HUD
                y = min(y, hud_bottom - hh)
            else:
                self.help_hides_hud = True
        self.help_panel.position = (x, y)
        self.help_panel.width, self.help_panel.height = hw, hh
        self.help_label.x, self.help_label.y = x + hw // 2, y + hh // 2

    def set_text(self, lines: list[str]) -> None:
        text = "\n".join(lines)
        if text != self.text:
            self.text = text
            self.label.set_lines(lines)
            self._fit_panel()

    def set_error(self, error: str | None) -> None:
        error = f"scene error: {error}" if error else ""
        if error != self.error:
            self.error = error
            self.error_label.text = error
            self.layout()

    def flash(self, message: str, now: float, seconds: float = MESSAGE_SECONDS) -> None:
        """Show ``message`` for a few seconds."""
        self.message = message
        self.message_label.text = message
        self._message_until = now + seconds

    def message_shown(self, now: float) -> str:
        """The transient message drawn at time ``now``, or ""."""
        return self.message if self.message and now < self._message_until else ""

    def draw(self, now: float) -> None:
        if self.show_help:
            self._place_help()  # H may have shown or hidden the HUD since
        if self.show_hud and not (self.show_help and self.help_hides_hud):
            self.batch.draw()
        if self.error:
            self.error_back.draw()
            self.error_label.draw()
        if self.message_shown(now):
            self.message_label.draw()
        if self.show_help:
            self.help_batch.draw()
