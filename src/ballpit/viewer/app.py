"""The viewer window: pyglet event loop, input handling, camera flying, HUD, reload and screenshots.

``run`` is what ``ballpit`` / ``ballpit view`` call. ``Viewer`` is the window itself; tests drive it
frame by frame with ``Viewer.frame`` and real pyglet events dispatched into the real window.
"""

from __future__ import annotations

import sys
import time
from datetime import datetime
from pathlib import Path

from . import backend, controls
from .controls import Action
from .simulation import Simulation

TITLE_INTERVAL = 0.5  # seconds between FPS title updates
HUD_INTERVAL = 0.1  # seconds between HUD text updates
WATCH_INTERVAL = 0.5  # seconds between checks of the scene file's modification time
FRAME_INTERVAL = 1.0 / 120.0  # redraw rate asked of pyglet's loop (vsync may cap it lower)
SCREENSHOT_DIRECTORY = "screenshots"  # F12 saves here, under the current directory


def default_scene() -> Path:
    """The bundled slopes demo (``ballpit.scenes/slopes.toml``)."""
    from ballpit.scene import default_scene_path

    return default_scene_path()


def _is_no_display(exc: BaseException) -> bool:
    return type(exc).__name__ == "NoSuchDisplayException"


def title(scene_name: str, fps: float) -> str:
    """The window title; it always ends with the frame rate as ``<number> FPS``."""
    return f"ballpit — {scene_name} — {fps:.1f} FPS"


class Viewer:
    """One window on one Simulation: of ``world`` (a Scene, or a World built in code), else of the scene
    file ``scene_path`` (the bundled demo by default). ``samples``: the multisampling asked for (4×
    MSAA; 0 for none, as the window tests use to draw 4× less on a software rasteriser)."""

    def __init__(
        self,
        world: object | None = None,
        scene_path: Path | None = None,
        size: tuple[int, int] = (1280, 720),
        visible: bool = True,
        trajectory: object = None,
        record: Path | None = None,
        samples: int = 4,
    ) -> None:
        backend.use_window()
        import pyglet

        from .camera import Camera
        from .frame import FrameFeeder, OverlayFlags
        from .hud import Hud
        from .interaction import Interaction
        from .renderer import Renderer
        from .screen import ScreenOverlay

        if world is None:
            from ballpit.scene import read_scene

            scene_path = Path(scene_path) if scene_path is not None else default_scene()
            world = read_scene(scene_path)
        self.sim = Simulation(world, scene_path, trajectory=trajectory)
        self.interaction = Interaction(self.sim)
        self.recorder = None
        if record is not None:
            from .recording import Recorder

            self.recorder = Recorder(record, self.sim)
        if trajectory is not None:
            self.sim.start()  # a replay plays at once
        look = self.sim.appearance
        self.camera = Camera.looking_at(look.camera_position, look.camera_look_at)
        self.window = self._open_window(size, visible, samples)
        self.renderer = Renderer()
        self.feeder = FrameFeeder(self.renderer)
        self.flags = OverlayFlags()
        self.hud = Hud(self.window)
        self.screen = ScreenOverlay(self.window, self.sim)
        self.held: set[str] = set()
        self.mouse_captured = False
        self._quit_armed_until = 0.0  # a second Esc before this time quits
        self.closed = False
        self._window_closed = False
        self.screenshot_requested = False
        self.last_screenshot: Path | None = None
        self.last_save: Path | None = None
        self.physics_seconds = 0.0
        self.fps = 0.0
        self.frames = 0
        now = time.perf_counter()
        self._last_frame = now
        self._fps_since, self._fps_frames = now, 0
        self._hud_at = 0.0
        self._watch_at = now + WATCH_INTERVAL
        self._shown_message = ""
        self.window.set_caption(title(look.name, 0.0))
        self.window.push_handlers(self)
        self._pyglet = pyglet

    # ------------------------------------------------------------------ window
    def _open_window(self, size: tuple[int, int], visible: bool, samples: int):
        import pyglet
        from pyglet import gl

        base = dict(
            major_version=3, minor_version=3, forward_compatible=True, double_buffer=True, depth_size=24
        )
        attempts = [dict(base, sample_buffers=1, samples=samples), base] if samples else [base]
        for i, attrs in enumerate(attempts):
            try:
                window = pyglet.window.Window(
                    width=size[0], height=size[1], caption="ballpit", resizable=True, vsync=True,
                    visible=visible, config=gl.Config(**attrs),
                )  # fmt: skip
            except pyglet.window.NoSuchConfigException:
                if i == len(attempts) - 1:
                    raise
                continue
            self.multisample = bool(attrs.get("samples"))
            return window
        raise AssertionError("unreachable")

    # ------------------------------------------------------------------ actions
    def perform(self, action: Action) -> None:
        """Do what a key asks for."""
        sim = self.sim
        if action is Action.START:
            sim.start()
        elif action is Action.PAUSE:
            sim.toggle_pause()
        elif action is Action.STEP:
            sim.step_once()
        elif action is Action.RESET:
            sim.reset()
        elif action is Action.RELOAD:
            self.reload()
        elif action in controls.INTEGRATOR_ACTIONS:
            sim.set_integrator(controls.INTEGRATOR_ACTIONS[action])
        elif action is Action.FASTER:
            sim.faster()
        elif action is Action.SLOWER:
            sim.slower()
        elif action is Action.CAPTURE_MOUSE:
            self.capture_mouse(not self.mouse_captured)
        elif action is Action.ESCAPE:
            self.escape()
        elif action is Action.CONTACTS:
            self.flags.contacts = not self.flags.contacts
        elif action is Action.VELOCITIES:
            self.flags.velocities = not self.flags.velocities
        elif action is Action.TRAILS:
            self.flags.trails = not self.flags.trails
        elif action is Action.HUD:
            self.hud.show_hud = not self.hud.show_hud
        elif action is Action.PROFILE:
            self.hud.page = "stats" if self.hud.page == "profile" else "profile"
            self.hud.show_hud = True
        elif action is Action.HELP:
            self.hud.show_help = not self.hud.show_help
        elif action is Action.SCREENSHOT:
            self.screenshot_requested = True
        elif action in controls.TIME_ACTIONS:
            controls.TIME_ACTIONS[action](sim)
        elif action is Action.ENERGY_PLOT:
            self.screen.show_plot = not self.screen.show_plot
        elif action is Action.SHOOT:
            self.interaction.shoot(self.camera)
        elif action is Action.SHOT_SPEED:
            sim.message = f"shot speed {self.interaction.next_shot_speed():g} m/s"
        elif action is Action.HOME:
            self.camera.look_from(sim.appearance.camera_position, sim.appearance.camera_look_at)
        elif action is Action.SAVE:
            self.save_scene()
        self._hud_at = 0.0  # refresh the HUD on the next frame

    def escape(self) -> None:
        """Esc: release a captured mouse, else quit only on a second Esc within a couple of seconds;
        until then the HUD asks for it."""
        now = time.perf_counter()
        if not self.mouse_captured and self.interaction.deselect():
            self.hud.flash("plane deselected", now)
            return
        outcome = controls.escape_outcome(self.mouse_captured, armed=now < self._quit_armed_until)
        if outcome == "quit":
            self.close()
            return
        if outcome == "release":
            self.capture_mouse(False)
        self._quit_armed_until = now + controls.QUIT_CONFIRM_SECONDS
        self.hud.flash(controls.QUIT_HINT, now, seconds=controls.QUIT_CONFIRM_SECONDS)

    def reload(self) -> bool:
        ok = self.sim.reload()
        self.hud.set_error(self.sim.error)
        return ok

    def save_scene(self) -> Path | None:
        """Ctrl+S: write the scene as it stands to a new file beside the original; the HUD says where."""
        from .save import save_scene

        try:
            self.last_save = save_scene(self.sim, self.camera, self.interaction.own_motion())
        except OSError as exc:
            self.hud.flash(f"save failed: {exc}", time.perf_counter())
            return None
        shown = self.last_save
        if shown.is_relative_to(Path.cwd()):
            shown = shown.relative_to(Path.cwd())
        print(f"scene saved to {self.last_save}", flush=True)
        self.hud.flash(f"scene saved to {shown}", time.perf_counter())
        return self.last_save

    def capture_mouse(self, captured: bool) -> None:
        self.mouse_captured = captured
        self.window.set_exclusive_mouse(captured)

    def close(self) -> None:
        """Close the window. Outside pyglet's loop (``pump``) the close waits until the events being
        dispatched are done, since pyglet's xlib dispatch cannot continue on a closed window."""
        self.closed = True
        if self._pyglet.app.event_loop.is_running:
            self._close_window()

    def _close_window(self) -> None:
        self.finish_record()
        if not self._window_closed:
            self._window_closed = True
            self.window.close()

    def finish_record(self) -> None:
        """Write the ``--record`` file (once), when the window closes or the run is interrupted."""
        if self.recorder is not None and not self.recorder.finished:
            steps, path = self.recorder.steps, self.recorder.finish()
            print(f"recorded {steps} steps ({self.sim.ball_count} balls) to {path}", flush=True)

    # ------------------------------------------------------------------ pyglet events
    def on_key_press(self, symbol: int, modifiers: int) -> bool:
        from pyglet.window import key

        name = key.symbol_string(symbol)
        ctrl = bool(modifiers & key.MOD_ACCEL)
        if not (ctrl and name in controls.FLY_KEYS):  # Ctrl+S saves; it does not fly back
            self.held.add(name)
        if self.interaction.takes_key(name):  # arrows and PgUp/PgDn move a selected plane while held
            return True
        action = controls.action_for_key(name, ctrl=ctrl, shift=bool(modifiers & key.MOD_SHIFT))
        if action is not None:
            self.perform(action)
        return True  # handled: stops pyglet's default "Esc closes the window"

    def on_text(self, text: str) -> bool:
        action = controls.action_for_text(text)
        if action is not None:
            self.perform(action)
        return True

    def on_key_release(self, symbol: int, modifiers: int) -> bool:
        from pyglet.window import key

        self.held.discard(key.symbol_string(symbol))
        return True

    def on_deactivate(self) -> None:
        self.held.clear()

    def on_mouse_press(self, x: int, y: int, button: int, modifiers: int) -> None:
        from pyglet.window import mouse

        if button == mouse.LEFT and self.screen.press(x, y):  # on the timeline bar: scrub
            return
        from .picking import pointer_ray

        if button == mouse.LEFT and not self.mouse_captured:
            ray = pointer_ray(self.camera, x, y, self.window.width, self.window.height)
            self.sim.message = self.interaction.press(ray, x, y, self.camera.forward) or self.sim.message

    def on_mouse_release(self, x: int, y: int, button: int, modifiers: int) -> None:
        from pyglet.window import mouse

        self.screen.release()
        if button == mouse.LEFT:
            self.interaction.release()

    def on_mouse_drag(self, x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        from pyglet.window import mouse

        if buttons & mouse.LEFT and self.screen.drag(x, y):
            return
        if buttons & mouse.LEFT:
            self.interaction.move(x, y)
        if buttons & mouse.RIGHT or self.mouse_captured:
            self.camera.look(dx, dy)

    def on_mouse_motion(self, x: int, y: int, dx: int, dy: int) -> None:
        if self.mouse_captured:
            self.camera.look(dx, dy)

    def on_mouse_scroll(self, x: int, y: int, scroll_x: float, scroll_y: float) -> None:
        self.camera.speed = controls.scrolled_fly_speed(self.camera.speed, scroll_y)

    def on_resize(self, width: int, height: int) -> None:
        self.hud.layout()  # pyglet's own handler (viewport, HUD projection) runs after this one

    def on_close(self) -> None:
        self.closed = True
        self.finish_record()

    def on_draw(self) -> None:
        self.frame()

    # ------------------------------------------------------------------ the frame
    def frame(self, dt: float | None = None) -> None:
        """Advance the camera and physics by real time (or by ``dt``) and draw one frame."""
        now = time.perf_counter()
        elapsed = now - self._last_frame if dt is None else dt
        self._last_frame = now
        self.camera.fly(
            controls.fly_direction(self.held), min(elapsed, 0.1), controls.fly_speed_multiplier(self.held)
        )

        size = (self.window.width, self.window.height)
        self.interaction.update(self.camera, size, self.held, elapsed)
        started = time.perf_counter()
        self.sim.advance(elapsed)
        self.physics_seconds = time.perf_counter() - started
        if now >= self._watch_at:
            self._watch_at = now + WATCH_INTERVAL
            if self.sim.file_changed():
                self.reload()

        self.window.switch_to()
        selected = self.interaction.selected_plane
        self.renderer.selected_plane = -1 if selected is None else selected
        self.feeder.upload(self.sim, self.flags, self.camera.position, self.interaction.lines())
        self.screen.upload(self.renderer)
        width, height = self.window.get_framebuffer_size()
        self.renderer.draw(self.camera, width, height, multisample=self.multisample)
        self._draw_hud(now)
        self.screen.draw_labels()
        if self.screenshot_requested:
            self.screenshot_requested = False
            self.save_screenshot(width, height)
        self._count_frame(now)

    def _overlay_names(self) -> str:
        f = self.flags
        return " ".join(name for name, on in (("contacts", f.contacts), ("velocities", f.velocities),
                                              ("trails", f.trails)) if on)  # fmt: skip

    def _draw_hud(self, now: float) -> None:
        from .hud import hud_lines, profile_lines

        if self.hud.bottom != self.screen.bottom_clearance():
            self.hud.bottom = self.screen.bottom_clearance()
            self.hud.layout()
        if now >= self._hud_at:
            self._hud_at = now + HUD_INTERVAL
            if self.hud.page == "profile":
                self.hud.set_text(profile_lines(self.sim))
            else:
                extra, shot = self.interaction.hud_lines(), self.interaction.shot_speed
                self.hud.set_text(hud_lines(self.sim, self.camera.speed, self._overlay_names(), extra, shot))
            self.hud.set_error(self.sim.error)
        if self.sim.message != self._shown_message:
            self._shown_message = self.sim.message
            if self.sim.message:
                self.hud.flash(self.sim.message, now)
        self.hud.draw(now)

    def _count_frame(self, now: float) -> None:
        self.frames += 1
        self._fps_frames += 1
        if now - self._fps_since >= TITLE_INTERVAL:
            self.fps = self._fps_frames / (now - self._fps_since)
            self._fps_since, self._fps_frames = now, 0
            self.window.set_caption(title(self.sim.appearance.name, self.fps))

    def save_screenshot(self, width: int, height: int, directory: Path | None = None) -> Path:
        """Save the back buffer (what this frame drew, HUD included) as a PNG in ``directory``
        (``screenshots/`` in the current directory, created if need be); prints the path and shows it
        in the HUD."""
        import numpy as np
        from OpenGL import GL
        from PIL import Image

        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        GL.glReadBuffer(GL.GL_BACK)
        data = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        image = np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3)[::-1]
        directory = Path.cwd() / SCREENSHOT_DIRECTORY if directory is None else directory
        directory.mkdir(parents=True, exist_ok=True)
        stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
        path = directory / f"ballpit-{stamp}.png"
        n = 1
        while path.exists():
            n += 1
            path = directory / f"ballpit-{stamp}-{n}.png"
        Image.fromarray(image).save(path)
        self.last_screenshot = path.resolve()
        print(f"screenshot saved to {self.last_screenshot}", flush=True)
        shown = self.last_screenshot
        if shown.is_relative_to(Path.cwd()):
            shown = shown.relative_to(Path.cwd())
        self.hud.flash(f"screenshot saved to {shown}", time.perf_counter())
        return self.last_screenshot

    def pump(self, dt: float | None = None) -> None:
        """One turn of the event loop by hand: deliver queued window events, draw a frame, flip.
        (pyglet queues events dispatched before its loop runs; this is what tests drive.)"""
        if self.closed:
            self._close_window()
            return
        self.window.switch_to()
        self.window.dispatch_events()
        if self.closed:
            self._close_window()
            return
        self.frame(dt)
        self.window.flip()

    def run(self) -> None:
        """pyglet's event loop until the window closes."""
        self._pyglet.app.run(FRAME_INTERVAL)


def run(scene_path: Path | None = None, trajectory: object = None, record: Path | None = None) -> int:
    """Open the viewer on a scene file (the bundled slopes demo by default); returns the exit status.
    With ``record``, the timeline it showed is written there when the window closes (or on Ctrl+C).

    With no display it prints one line saying how to render offscreen instead and returns 1. With a
    ``trajectory`` (``replay.read_trajectory``) the window plays it instead of running the physics.
    """
    problem = backend.display_problem()
    if problem is not None:
        print(backend.no_display_message(problem), file=sys.stderr)
        return 1
    try:
        viewer = Viewer(scene_path=scene_path, trajectory=trajectory, record=record)
    except Exception as exc:
        if _is_no_display(exc):
            print(backend.no_display_message(str(exc) or "cannot connect"), file=sys.stderr)
            return 1
        raise
    try:
        viewer.run()
    finally:
        viewer.finish_record()
    return 0
