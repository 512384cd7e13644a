"""Input → action mapping for the viewer, kept free of pyglet and GL so it is unit-testable.

Keys are named as in ``pyglet.window.key`` (``key.symbol_string(symbol)``: "X", "SPACE", "_1", "F5",
...). + and − are read from the typed text instead (``TEXT_ACTIONS``): "+" is Shift+"=" on most layouts,
and when Shift is let go first X reports the release as EQUAL, so pyglet still believes PLUS is held and
swallows the next press; the text event arrives every time, from the main keys and the keypad alike.
The table follows the "Viewer controls" section of the README; ``HELP`` is the text of the F1 overlay
and is built from the same bindings. The number keys come from the integrator registry
(``physics/integrators.py``): one ``IntegratorAction`` per registered integrator, on its key.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from enum import Enum
from typing import Any

import numpy as np

from ..physics.dynamics.integrators import INTEGRATORS


class Action(Enum):
    """Everything a key press can ask the viewer to do."""

    START = "start the drop"
    PAUSE = "pause / resume"
    STEP = "single step while paused"
    RESET = "reset to the initial state"
    RELOAD = "reload the scene file"
    FASTER = "faster time"
    SLOWER = "slower time"
    CAPTURE_MOUSE = "capture / release the mouse for looking"
    ESCAPE = "release the mouse; twice to quit"
    CONTACTS = "show contact points and normals"
    VELOCITIES = "show velocity arrows"
    TRAILS = "show trails"
    HUD = "show / hide the HUD"
    PROFILE = "HUD page: where the step's time goes"
    HELP = "show / hide this help"
    SCREENSHOT = "save a screenshot PNG"
    QUALITY = "drawing quality: low / high"
    STEP_BACK = "one step back through the history while paused"
    JUMP_BACK = "a second back through the history while paused"
    JUMP_FORWARD = "a second forward through the history while paused"
    GHOSTS = "integrator ghosts and their energy drift"
    ENERGY_PLOT = "live energy plot"
    SHOOT = "shoot a ball along the view"
    SHOT_SPEED = "change the shot speed"
    HOME = "camera back to the scene's view"
    SAVE = "save the scene as it stands to a new file"
    RECORD_VIDEO = "record the 3-D view to MP4 / stop"
    PANEL = "show / hide the panel"


KEY_ACTIONS: dict[str, Action] = {
    "X": Action.START,
    "SPACE": Action.PAUSE,
    "N": Action.STEP,
    "RIGHT": Action.STEP,
    "R": Action.RESET,
    "F5": Action.RELOAD,
    "TAB": Action.CAPTURE_MOUSE,
    "ESCAPE": Action.ESCAPE,
    "C": Action.CONTACTS,
    "V": Action.VELOCITIES,
    "T": Action.TRAILS,
    "H": Action.HUD,
    "F1": Action.HELP,
    "F2": Action.PROFILE,
    "F3": Action.QUALITY,
    "F12": Action.SCREENSHOT,
    "F9": Action.RECORD_VIDEO,
    "LEFT": Action.STEP_BACK,
    "G": Action.GHOSTS,
    "P": Action.ENERGY_PLOT,
    "B": Action.SHOOT,
    "HOME": Action.HOME,
    "F4": Action.PANEL,
}

CTRL_KEY_ACTIONS: dict[str, Action] = {"R": Action.RELOAD, "S": Action.SAVE}
SHIFT_KEY_ACTIONS: dict[str, Action] = {
    "LEFT": Action.JUMP_BACK,
    "RIGHT": Action.JUMP_FORWARD,
    "B": Action.SHOT_SPEED,
}

# Typed text → action. "=" is the + key without Shift, "_" the − key with it.
TEXT_ACTIONS: dict[str, Action] = {
    "+": Action.FASTER,
    "=": Action.FASTER,
    "-": Action.SLOWER,
    "_": Action.SLOWER,
    "\u2212": Action.SLOWER,  # − (minus sign), as some layouts type it
}

# Switching integrator: one action per registered integrator (``IntegratorAction.RK4``, ...), bound to
# its number key on the main keys and the keypad.
IntegratorAction = Enum(  # type: ignore[misc]
    "IntegratorAction", {name.upper(): f"integrator: {i.label}" for name, i in INTEGRATORS.items()}
)
INTEGRATOR_ACTIONS: dict[Enum, str] = {IntegratorAction[name.upper()]: name for name in INTEGRATORS}
KEY_ACTIONS.update(
    {
        f"{row}{INTEGRATORS[name].key}": action
        for action, name in INTEGRATOR_ACTIONS.items()
        for row in ("_", "NUM_")
    }  # type: ignore[misc]
)

# Held keys that fly the camera, as (right, up, forward) components.
FLY_KEYS: dict[str, tuple[float, float, float]] = {
    "W": (0.0, 0.0, 1.0),
    "S": (0.0, 0.0, -1.0),
    "A": (-1.0, 0.0, 0.0),
    "D": (1.0, 0.0, 0.0),
    "Q": (0.0, -1.0, 0.0),
    "E": (0.0, 1.0, 0.0),
}
SHIFT_KEYS = frozenset({"LSHIFT", "RSHIFT"})
SHIFT_SPEEDUP = 4.0

# Fly speed (m/s) changes by this factor per scroll notch, within these bounds.
SCROLL_FACTOR = 1.25
FLY_SPEED_RANGE = (0.05, 500.0)

# A second Esc within this many seconds quits; the HUD asks for it as long.
QUIT_CONFIRM_SECONDS = 2.0
QUIT_HINT = "press Esc again to quit"
RELEASED_HINT = "mouse released (Tab captures it again)"

# Time scale (simulated seconds per real second) steps by a factor of 2 within these bounds.
TIME_SCALE_RANGE = (1.0 / 64.0, 8.0)

HELP: tuple[tuple[str, str], ...] = (
    ("X / Space, + / −", "start the drop / pause; time faster / slower"),
    ("N or →", "single step while paused"),
    ("← / Shift+← →", "paused: step back / jump 1 s; or drag the bottom bar"),
    ("R / Ctrl+R or F5", "reset (X drops again) / reload (also on save)"),
    ("/".join(i.key for i in INTEGRATORS.values()), "/".join(i.label for i in INTEGRATORS.values())),
    ("G", "ghosts of the others: ballpit view integrators"),
    ("W A S D, Q E", "fly; Shift faster; scroll sets the fly speed"),
    ("right drag or Tab", "look around (Tab captures the mouse)"),
    ("Esc", "release the mouse, drop a plane; twice quits"),
    ("C / V / T, P", "contacts, velocities, trails; energy plot"),
    ("H / F1 F2 F3 F4", "HUD, help, stage times, quality, panel"),
    ("F12 / Ctrl+S", "screenshot into screenshots/ / save the scene"),
    ("F9", "record MP4 into videos/ (F9 again stops)"),
    ("left-drag a ball", "pick it up and move it; let go to throw it"),
    ("B / Shift+B", "shoot a ball along the view / its speed"),
    ("click a plane", "select it: arrows tilt it, PgUp/PgDn lift it"),
    ("Home", "camera back to the scene's view"),
)


# How a key is written in the help and beside the panel's buttons.
KEY_NAMES = {
    "SPACE": "Space",
    "RIGHT": "Right",
    "LEFT": "Left",
    "ESCAPE": "Esc",
    "TAB": "Tab",
    "HOME": "Home",
}


def keys_for(action: Enum) -> str:
    """The keys bound to ``action``, as the panel writes them beside its button ("X", "Ctrl+R / F5")."""
    names = [f"Ctrl+{k}" for k, a in CTRL_KEY_ACTIONS.items() if a is action]
    names += [f"Shift+{KEY_NAMES.get(k, k)}" for k, a in SHIFT_KEY_ACTIONS.items() if a is action]
    names += [
        KEY_NAMES.get(k, k).lstrip("_")
        for k, a in KEY_ACTIONS.items()
        if a is action and not k.startswith("NUM_")
    ]
    names += [t for t, a in TEXT_ACTIONS.items() if a is action and t in "+-"]
    return " / ".join(names)


def action_for_key(name: str, ctrl: bool = False, shift: bool = False) -> Action | None:
    """The action bound to a key press, or None. ``name`` is pyglet's key symbol name."""
    if ctrl:
        return CTRL_KEY_ACTIONS.get(name)
    if shift and name in SHIFT_KEY_ACTIONS:
        return SHIFT_KEY_ACTIONS[name]
    return KEY_ACTIONS.get(name)


def action_for_text(text: str) -> Action | None:
    """The action bound to typed text (pyglet's ``on_text``), or None."""
    return TEXT_ACTIONS.get(text)


def fly_direction(held: Iterable[str]) -> np.ndarray:
    """The camera-relative (right, up, forward) direction the held keys ask for, of length 0 or 1."""
    move = np.zeros(3)
    for name in held:
        if name in FLY_KEYS:
            move += FLY_KEYS[name]
    length = np.linalg.norm(move)
    return move / length if length > 0 else move


def fly_speed_multiplier(held: Iterable[str]) -> float:
    """Shift (either side) flies faster."""
    return SHIFT_SPEEDUP if SHIFT_KEYS.intersection(held) else 1.0


def scrolled_fly_speed(speed: float, notches: float) -> float:
    """The fly speed after scrolling ``notches`` (positive: up, faster), kept within FLY_SPEED_RANGE."""
    low, high = FLY_SPEED_RANGE
    return float(np.clip(speed * SCROLL_FACTOR**notches, low, high))


def faster(scale: float) -> float:
    """The next time scale up (×2), capped."""
    return min(scale * 2.0, TIME_SCALE_RANGE[1])


def slower(scale: float) -> float:
    """The next time scale down (÷2), capped."""
    return max(scale / 2.0, TIME_SCALE_RANGE[0])


def escape_outcome(mouse_captured: bool, armed: bool = False) -> str:
    """What Esc does: release a captured mouse ("release"); with nothing captured, quit only if Esc was
    pressed in the last ``QUIT_CONFIRM_SECONDS`` (``armed``: "quit"), else ask for a second Esc ("arm").
    Releasing the mouse does nothing else: quitting still takes Esc, Esc after it."""
    if mouse_captured:
        return "release"
    return "quit" if armed else "arm"


# Moving in time and the ghosts: what each asks of the Simulation.
TIME_ACTIONS: dict[Action, Callable[[Any], None]] = {
    Action.STEP_BACK: lambda sim: sim.step_back(),
    Action.JUMP_BACK: lambda sim: sim.jump(-1.0),
    Action.JUMP_FORWARD: lambda sim: sim.jump(1.0),
    Action.GHOSTS: lambda sim: sim.toggle_ghosts(),
}
