"""The viewer's actions, each declared once: what it does (here), its keys and help (controls.py).

A key press and the panel's button for the same action both call ``Viewer.perform(action)``, which
runs the handler below; what changes the World is sent to the physics side as a command
(``Viewer.command``). The panel writes each button's keys beside it from the same bindings
(``controls.keys_for``), so a key, its button and the help cannot disagree.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from enum import Enum
from typing import TYPE_CHECKING

from . import controls
from .controls import Action

if TYPE_CHECKING:
    from .app import Viewer

Handler = Callable[["Viewer"], None]


def _command(fn: Callable, rewind: bool = True) -> Handler:
    """An action that is one command to the physics side: ``fn(sim)``."""
    return lambda v: v.command(fn, rewind=rewind)


def _flip_flag(name: str) -> Handler:
    def flip(v: Viewer) -> None:
        setattr(v.flags, name, not getattr(v.flags, name))

    return flip


def _hud(v: Viewer) -> None:
    v.hud.show_hud = not v.hud.show_hud


def _profile(v: Viewer) -> None:
    """F2: the HUD's profile page, and the panel's time-per-stage plot."""
    v.hud.page = "stats" if v.hud.page == "profile" else "profile"
    v.hud.show_hud = True
    v.panel.open_plot("stages", v.hud.page == "profile")


def _help(v: Viewer) -> None:
    v.hud.show_help = not v.hud.show_help


def _screenshot(v: Viewer) -> None:
    v.screenshot_requested = True


def _quality(v: Viewer) -> None:
    from .quality import other

    v.set_quality(other(v.quality).name)
    v.hud.flash(f"quality {v.quality.describe()}", time.perf_counter())


def _energy_plot(v: Viewer) -> None:
    """P: the panel's energy plot (the panel is shown if it was hidden)."""
    v.panel.open_plot("energy", not v.panel.plot_open("energy"))


def _shoot(v: Viewer) -> None:
    camera = copy.deepcopy(v.camera)
    v.command(lambda sim: v.interaction.shoot(camera))


def _shot_speed(v: Viewer) -> None:
    v.hud.flash(f"shot speed {v.interaction.next_shot_speed():g} m/s", time.perf_counter())


def _home(v: Viewer) -> None:
    v.view.home()


def _panel(v: Viewer) -> None:
    v.panel.shown = not v.panel.shown


HANDLERS: dict[Enum, Handler] = {
    # X reads nothing the steps change: it lets a run held before X go on (stepper.py) instead of undoing it
    Action.START: _command(lambda sim: sim.start(), rewind=False),
    Action.PAUSE: _command(lambda sim: sim.toggle_pause()),
    Action.STEP: _command(lambda sim: sim.step_once()),
    Action.RESET: _command(lambda sim: sim.reset()),
    Action.RELOAD: lambda v: v.reload(),
    Action.FASTER: _command(lambda sim: sim.faster()),
    Action.SLOWER: _command(lambda sim: sim.slower()),
    Action.CAPTURE_MOUSE: lambda v: v.input.capture_mouse(not v.input.mouse_captured),
    Action.ESCAPE: lambda v: v.input.escape(),
    Action.CONTACTS: _flip_flag("contacts"),
    Action.VELOCITIES: _flip_flag("velocities"),
    Action.TRAILS: _flip_flag("trails"),
    Action.HUD: _hud,
    Action.PROFILE: _profile,
    Action.HELP: _help,
    Action.SCREENSHOT: _screenshot,
    Action.QUALITY: _quality,
    Action.ENERGY_PLOT: _energy_plot,
    Action.SHOOT: _shoot,
    Action.SHOT_SPEED: _shot_speed,
    Action.HOME: _home,
    Action.SAVE: lambda v: v.save_scene(),
    Action.RECORD_VIDEO: lambda v: v.video.toggle(),
    Action.PANEL: _panel,
    **{action: _command(fn) for action, fn in controls.TIME_ACTIONS.items()},
    **{
        action: _command(lambda sim, name=name: sim.set_integrator(name))
        for action, name in controls.INTEGRATOR_ACTIONS.items()
    },
}


def perform(viewer: Viewer, action: Enum) -> None:
    """Run ``action``'s handler (every action has one: the tests check it)."""
    HANDLERS[action](viewer)


def label(action: Enum, text: str) -> str:
    """A panel button's label: ``text`` and its keys ("Drop (X)")."""
    keys = controls.keys_for(action)
    return f"{text} ({keys})" if keys else text
