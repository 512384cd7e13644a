"""The window's input: pyglet's key, text, pointer, scroll and file-drop events, turned into actions,
commands and camera moves.

Every event goes to the panel first (ImGui sees all input); what ImGui wants (typing into a field, a
click or a drag on the panel) stops there, and the rest goes on: keys to their actions (controls.py,
actions.py), the pointer to picking and the mouse joint (interaction.py, as commands to the physics
side), the timeline bar (screen.py) and the camera (free-fly or orbit).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

from . import controls

if TYPE_CHECKING:
    from .app import Viewer
    from .simulation import Simulation

DOUBLE_CLICK_SECONDS = 0.35  # a second left press within this time, at the same place, is a double-click


class WindowInput:
    """pyglet's event handlers for one Viewer's window (pushed onto it), and the state of the input."""

    def __init__(self, viewer: Viewer) -> None:
        self.viewer = viewer
        self.held: set[str] = set()  # the keys held down, by pyglet name
        self.mouse_captured = False
        self._quit_armed_until = 0.0  # a second Esc before this time quits
        self._last_press = (0.0, 0.0, 0.0)  # (time, x, y) of the last left press: a double-click orbits

    # ------------------------------------------------------------------ keys
    def on_key_press(self, symbol: int, modifiers: int) -> bool:
        from pyglet.window import key

        v = self.viewer
        v.panel.backend.key(symbol, True)
        if v.panel.wants_keyboard:  # typing into a field of the panel
            return True
        name = key.symbol_string(symbol)
        ctrl = bool(modifiers & key.MOD_ACCEL)
        if not (ctrl and name in controls.FLY_KEYS):  # Ctrl+S saves; it does not fly back
            self.held.add(name)
        if v.interaction.takes_key(name):  # arrows and PgUp/PgDn move a selected plane while held
            return True
        action = controls.action_for_key(name, ctrl=ctrl, shift=bool(modifiers & key.MOD_SHIFT))
        if action is not None:
            v.perform(action)
        return True  # handled: stops pyglet's default "Esc closes the window"

    def on_text(self, text: str) -> bool:
        v = self.viewer
        v.panel.backend.text(text)
        if v.panel.wants_keyboard:
            return True
        action = controls.action_for_text(text)
        if action is not None:
            v.perform(action)
        return True

    def on_key_release(self, symbol: int, modifiers: int) -> bool:
        from pyglet.window import key

        self.viewer.panel.backend.key(symbol, False)
        self.held.discard(key.symbol_string(symbol))
        return True

    def on_deactivate(self) -> None:
        self.held.clear()

    def escape(self) -> None:
        """Esc: release a captured mouse (and nothing else), else quit only on a second Esc within a
        couple of seconds; until then the HUD asks for it."""
        v = self.viewer
        now = time.perf_counter()
        if not self.mouse_captured and v.interaction.selected_plane is not None:
            v.command(lambda sim: v.interaction.deselect())
            v.hud.flash("plane deselected", now)
            return
        outcome = controls.escape_outcome(self.mouse_captured, armed=now < self._quit_armed_until)
        if outcome == "quit":
            v.close()
            return
        if outcome == "release":
            self.capture_mouse(False)
            v.hud.flash(controls.RELEASED_HINT, now)
            return
        self._quit_armed_until = now + controls.QUIT_CONFIRM_SECONDS
        v.hud.flash(controls.QUIT_HINT, now, seconds=controls.QUIT_CONFIRM_SECONDS)

    def capture_mouse(self, captured: bool) -> None:
        self.mouse_captured = captured
        self.viewer.window.set_exclusive_mouse(captured)

    # ------------------------------------------------------------------ files
    def on_file_drop(self, x: int, y: int, paths: list[str]) -> None:
        """A file dropped on the window: a scene opens (one that is not valid keeps the current one)."""
        if paths:
            self.viewer.panel.open_scene(Path(paths[0]))

    # ------------------------------------------------------------------ the pointer
    def on_mouse_press(self, x: int, y: int, button: int, modifiers: int) -> None:
        from pyglet.window import mouse

        from .picking import pointer_ray

        v = self.viewer
        v.panel.backend.mouse_button(x, y, button, True)
        if v.panel.covers(x, y):
            return
        if button == mouse.LEFT and v.screen.press(x, y):  # on the timeline bar: scrub
            return
        if button != mouse.LEFT or self.mouse_captured:
            return
        ray = pointer_ray(v.camera, x, y, v.window.width, v.window.height)
        facing = v.camera.forward
        now = time.perf_counter()
        t, px, py = self._last_press
        double = now - t < DOUBLE_CLICK_SECONDS and abs(x - px) + abs(y - py) < 6
        self._last_press = (0.0 if double else now, x, y)
        if v.panel.adding_ball:  # the inspector's "add a ball where I click"
            v.panel.edits.add_ball(ray, lambda index: v.select(index))
            return

        def press(sim: Simulation) -> None:
            sim.message = v.interaction.press(ray, x, y, facing) or sim.message

        v.command(press, (lambda _: self._orbit_clicked()) if double else None)

    def _orbit_clicked(self) -> None:
        """A double-click on a ball: orbit it (and follow it, if the View section asks)."""
        v = self.viewer
        ball = v.interaction.selected_ball
        if ball is None or ball >= v.shown.ball_count:
            return
        v.command(lambda sim: v.interaction.release())
        v.view.start_orbit(v.shown.positions[ball], ball)

    def on_mouse_release(self, x: int, y: int, button: int, modifiers: int) -> None:
        from pyglet.window import mouse

        v = self.viewer
        v.panel.backend.mouse_button(x, y, button, False)
        v.screen.release()
        if button == mouse.LEFT:
            v.command(lambda sim: v.interaction.release())

    def on_mouse_drag(self, x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        from pyglet.window import mouse

        v = self.viewer
        v.panel.backend.mouse_motion(x, y)
        if v.panel.backend.wants_mouse:  # a drag that started on the panel
            return
        if buttons & mouse.LEFT and v.screen.drag(x, y):
            return
        camera, orbit = v.camera, v.orbit
        if buttons & mouse.LEFT:
            v.interaction.move(x, y)
            if orbit.active and v.interaction.held_ball is None:
                orbit.turn(camera, dx, dy)
        if buttons & mouse.MIDDLE and orbit.active:
            orbit.pan(camera, dx, dy, v.window.height)
        if buttons & mouse.RIGHT or self.mouse_captured:
            if orbit.active:
                orbit.turn(camera, dx, dy)
            else:
                camera.look(dx, dy)

    def on_mouse_motion(self, x: int, y: int, dx: int, dy: int) -> None:
        v = self.viewer
        v.panel.backend.mouse_motion(x, y)
        if self.mouse_captured:
            v.camera.look(dx, dy)

    def on_mouse_scroll(self, x: int, y: int, scroll_x: float, scroll_y: float) -> None:
        """Scroll: the orbit camera zooms; the free-fly camera changes its fly speed."""
        v = self.viewer
        v.panel.backend.scroll(x, y, scroll_x, scroll_y)
        if v.panel.covers(x, y):
            return
        if v.orbit.active:
            v.orbit.zoom(v.camera, scroll_y)
        else:
            v.camera.speed = controls.scrolled_fly_speed(v.camera.speed, scroll_y)
