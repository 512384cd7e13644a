"""The HUD's and the help's text breaks only where the text says (no wrapping mid-phrase), and the
error sits on a dark box so its red reads on the grey ground."""

from __future__ import annotations

import pytest


def line_height(label) -> float:
    """The height of a line of ``label``'s text, at its font size (the HUD's text scales with its
    window, hud.font_size; the help's may be smaller still, to fit beside the panel)."""
    import pyglet

    from ballpit.viewer.hud import FONT

    size = label.font_size
    one = pyglet.text.Label("Xg", font_name=FONT, font_size=size, multiline=True, width=4000)
    two = pyglet.text.Label("Xg\nXg", font_name=FONT, font_size=size, multiline=True, width=4000)
    return two.content_height - one.content_height


@pytest.fixture
def hud(offscreen):
    from ballpit.viewer.hud import Hud

    return Hud(offscreen.window)


def test_the_help_is_laid_out_one_row_per_binding(hud):
    from ballpit.viewer.hud import help_text

    rows = help_text().count("\n") + 1
    step = line_height(hud.help_label)
    assert hud.help_label.content_height == pytest.approx(rows * step, abs=step * 0.6)
    assert hud.help_label.width >= hud.help_label.content_width  # its lines fit: none is broken


def test_a_long_hud_line_stays_one_line(hud):
    lines = ["slopes.toml", "history     12.500 s in the past; Space resumes", "x" * 90]
    hud.set_text(lines)
    step = line_height(hud.label)
    assert hud.label.content_height == pytest.approx(len(lines) * step, abs=step * 0.6)
    assert hud.panel.width >= hud.label.content_width  # the panel grows to fit the line


def test_the_error_is_drawn_on_a_dark_box_that_covers_it(hud):
    from ballpit.viewer.hud import ERROR_BACK, ERROR_COLOR

    hud.set_error("reload of live.toml failed: sphere #1: radius must be positive, got -0.3")
    label, box = hud.error_label, hud.error_back
    assert box.x <= label.x and box.x + box.width >= label.x + label.content_width
    assert box.y <= label.y and box.y + box.height >= label.y + label.content_height
    assert sum(ERROR_BACK[:3]) < 60 and ERROR_BACK[3] >= 200  # dark and nearly opaque

    # WCAG contrast of the red on the box: well above the 4.5 asked of body text
    def luminance(rgb):
        c = [v / 255 for v in rgb]
        c = [v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4 for v in c]
        return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]

    ratio = (luminance(ERROR_COLOR[:3]) + 0.05) / (luminance(ERROR_BACK[:3]) + 0.05)
    assert ratio > 4.5


def test_the_help_legend_gives_the_restitution_each_plane_colour_stands_for():
    """The help names each stop of the colour ramp with its restitution, as a number, so a scene whose
    planes all lie between stops (the demo's: 0.55 to 0.95) still reads: no slope there is blue."""
    import colorsys

    from ballpit.scene.colours import RESTITUTION_COLORS, RESTITUTION_STOPS
    from ballpit.viewer.hud import PLANE_LEGEND, help_text

    assert PLANE_LEGEND in help_text()
    named = {"slate blue": (200, 240), "green": (90, 160), "orange": (15, 45)}  # hue ranges, degrees
    for stop, color in zip(RESTITUTION_STOPS, RESTITUTION_COLORS, strict=True):
        found = [name for name in named if f"{stop:g} {name}" in PLANE_LEGEND]
        assert len(found) == 1, (stop, PLANE_LEGEND)
        low, high = named[found[0]]
        assert low <= colorsys.rgb_to_hsv(*color)[0] * 360 <= high


def test_the_hud_text_scales_with_the_window_within_readable_bounds():
    from ballpit.viewer.hud import FONT_SIZE, FONT_SIZE_RANGE, font_size

    assert font_size(1280, 720) == FONT_SIZE
    assert font_size(800, 450) == pytest.approx(FONT_SIZE * 450 / 720, abs=0.25)  # the side that shrank
    assert font_size(800, 720) == pytest.approx(FONT_SIZE * 800 / 1280, abs=0.25)
    assert font_size(2560, 1440) == 2 * FONT_SIZE
    assert font_size(200, 100) == FONT_SIZE_RANGE[0] and font_size(8000, 8000) == FONT_SIZE_RANGE[1]


def test_a_new_hud_text_lays_out_again_only_the_lines_that_changed(hud):
    """pyglet lays a label's whole text out again when it changes: the HUD is a label per line, so a
    new sim time re-lays that line and leaves the others' layouts as they were."""
    lines = ["slopes.toml", "sim time        1.000 s", "balls               5", "F1 help"]
    hud.set_text(lines)
    laid_out = [0] * len(lines)
    for index, label in enumerate(hud.label.labels):  # count each label's layouts (pyglet's _update)

        def counted(update=label._update, index=index):
            laid_out[index] += 1
            update()

        label._update = counted
    hud.set_text([lines[0], "sim time        1.250 s", *lines[2:]])
    assert [count > 0 for count in laid_out] == [False, True, False, False]
    assert hud.text == hud.label.text == "\n".join([lines[0], "sim time        1.250 s", *lines[2:]])
    hud.set_text(lines[:2])  # fewer lines: the rest go
    assert len(hud.label.labels) == 2 and hud.label.content_height == pytest.approx(
        2 * line_height(hud.label)
    )
