"""HUD text from a simulation, the help overlay text, the window title and the GL platform guard."""

from __future__ import annotations

import re
import sys

import pytest

from ballpit.viewer import backend
from ballpit.viewer.simulation import Simulation

from .conftest import line_of_balls


def test_hud_shows_time_speed_integrator_rates_counts_energy_and_state(offscreen):
    from ballpit.viewer.hud import hud_lines

    sim = Simulation(line_of_balls(7))
    text = "\n".join(hud_lines(sim, fly_speed=4.0, overlays="trails"))
    for needle in ("sim time", "real-time factor", "RK4", "steps/s", "balls               7", "contacts",
                   "kinetic E", "waiting: press X", "trails"):  # fmt: skip
        assert needle in text, needle
    sim.start()
    sim.toggle_pause()
    assert "paused" in "\n".join(hud_lines(sim, 4.0, ""))


def test_help_text_lists_the_controls(offscreen):
    from ballpit.viewer.hud import help_text

    text = help_text()
    for key in ("X", "Space", "Ctrl+R or F5", "W A S D", "Esc", "F12", "bouncy"):
        assert key in text


def test_the_title_ends_with_the_frame_rate():
    from ballpit.viewer.app import title

    assert re.search(r"\d+(\.\d+)? FPS$", title("slopes.toml", 59.84))
    assert title("slopes.toml", 59.84) == "ballpit — slopes.toml — 59.8 FPS"


def test_a_headless_process_refuses_to_open_windows(offscreen):
    assert backend.current_mode() == "headless"
    backend.use_headless()  # choosing the same mode again is fine
    with pytest.raises(backend.BackendError, match="separate processes"):
        backend.use_window()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 DISPLAY check")
def test_no_display_is_detected_without_importing_anything(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    assert backend.display_problem() == "DISPLAY is not set"
    message = backend.no_display_message("DISPLAY is not set")
    assert "\n" not in message and "ballpit render SCENE --out demo.gif" in message and "xvfb-run" in message
