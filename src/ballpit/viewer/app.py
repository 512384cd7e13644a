"""The viewer window: its parts put together, the frame, reload and save, the HUD's text, and the exit.

``run`` is what ``ballpit`` / ``ballpit view`` call. ``Viewer`` is the window itself; tests drive it
frame by frame with ``Viewer.frame`` and real pyglet events dispatched into the real window. Its parts
live beside it: the input (input.py: keys, pointer, files), the actions every key and panel button run
(actions.py), the camera (view_control.py, orbit.py, framing.py), the panel (panel.py), the HUD
(hud.py), recording (recording.py) and screenshots (screenshot.py).

The physics runs beside the window on a thread of its own (stepper.py): the window draws the latest
state it handed over and sends it what the keys and the mouse ask as commands, applied between steps.
In pyglet's loop (``frame()`` without ``dt``) the physics runs free on the wall clock; a frame given a
``dt`` advances it by exactly that much first (lockstep), which is what tests and scripts use.
pyglet's loop draws at the rate pacing.py chooses: 60 FPS, or 33 while the physics needs the CPU.
"""

from __future__ import annotations

import copy
import os
import sys
import time
from collections import deque
from pathlib import Path

from . import backend
from .controls import Action
from .handover import Needs, Shown
from .pacing import FramePacer
from .simulation import Phase, Simulation

TITLE_INTERVAL = 0.5  # seconds between FPS title updates
WATCH_INTERVAL = 0.5  # seconds between checks of the scene file's modification time


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
    file ``scene_path`` (the bundled demo by default). ``quality``: ``auto``, ``low`` or ``high``
    (quality.py; auto is low on a software rasteriser such as llvmpipe, as in the window tests).
    ``panel``: whether the panel is shown at first (F4 shows and hides it)."""

    def __init__(
        self,
        world: object | None = None,
        scene_path: Path | None = None,
        size: tuple[int, int] = (1280, 720),
        visible: bool = True,
        trajectory: object = None,
        record: Path | None = None,
        quality: str = "auto",
        panel: bool = True,
    ) -> None:
        backend.use_window()
        import pyglet

        from .camera import Camera
        from .frame import FrameFeeder, OverlayFlags
        from .hud import Hud
        from .input import WindowInput
        from .interaction import Interaction
        from .panel import Panel
        from .renderer import Renderer
        from .screen import ScreenOverlay
        from .stepper import PhysicsThread, tuning_from
        from .video import VideoRecorder
        from .view_control import ViewControl
        from .watch import Traces

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
        self.view = ViewControl(self, self.camera)
        self.orbit = self.view.orbit
        self.window = self._open_window(size, visible)
        self.renderer = Renderer()
        self.renderer_name = _gl_renderer()
        self.view_target = None  # the framebuffer the 3-D view is drawn into (quality.py)
        self.set_quality(quality)
        self.feeder = FrameFeeder(self.renderer)
        self.flags = OverlayFlags()
        self.hud = Hud(self.window)
        self.traces = Traces()
        self.sim.after_step.append(lambda: self.traces.sample(self.sim))
        self.sim.after_reset.append(lambda: self.traces.follow(None))
        self.sim.after_resume_from_past.append(lambda step: self.traces.cut(self.sim.world.time))
        tuning = tuning_from(os.environ)  # the one place the environment is read for it
        self.physics = PhysicsThread(self.sim, needs=self._needs, watch=self._watch, **tuning)
        self.panel = Panel(self)
        self.panel.shown = panel
        self.view.scene_view(self.shown)
        # how often pyglet's loop draws (``run``): fewer while the physics is busy, and cheaper
        self.pacer = FramePacer(thrifty=os.environ.get("BALLPIT_THRIFT", "1") != "0")
        self._interval: float | None = None  # the redraw interval scheduled now (None: not in the loop)
        self._due: float | None = None  # when the next frame of pyglet's loop is due (``_redraw``)
        self.screen = ScreenOverlay(self.window, self.physics)
        flash = lambda message: self.hud.flash(message, time.perf_counter())  # noqa: E731
        self.video = VideoRecorder(self.window, flash, left=lambda: self.panel.width)  # right of the panel
        self._interaction_seconds: deque[float] = deque()
        self._interaction_input: tuple = ()
        self._interaction_queued = False
        self._drawn_key: tuple | None = None
        self._drawn_shown: Shown | None = None  # keeps the object whose id is in the key alive
        self.views_drawn = 0  # how many frames drew the 3-D view (others showed the last one again)
        self.input = WindowInput(self)
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
        self.window.push_handlers(self.input)
        self._pyglet = pyglet

    # ------------------------------------------------------------------ window
    def _open_window(self, size: tuple[int, int], visible: bool):
        """A single-sampled window: the 3-D view is drawn into a framebuffer of its own (multisampled or
        smaller, as the quality says) and copied in, and the HUD is drawn over it at full size."""
        import pyglet
        from pyglet import gl

        config = gl.Config(
            major_version=3, minor_version=3, forward_compatible=True, double_buffer=True, depth_size=24
        )
        return pyglet.window.Window(
            width=size[0], height=size[1], caption="ballpit", resizable=True, vsync=True,
            visible=visible, config=config, file_drops=True,
        )  # fmt: skip

    def set_quality(self, option: str) -> None:
        """``auto``, ``low`` or ``high`` (quality.py): MSAA, shadows and the view's resolution."""
        from .framebuffer import WindowView
        from .quality import choose

        self.quality = q = choose(option, self.renderer_name)
        self.renderer.shadows = q.shadow_limit > 0
        self.renderer.shadow_limit = max(q.shadow_limit, 1)
        if self.view_target is not None:
            self.window.switch_to()
            self.view_target.delete()
        self.view_target = WindowView(q.samples, q.scale)

    @property
    def multisample(self) -> bool:
        return self.quality.samples > 0

    def _needs(self) -> Needs:
        """What the physics should copy for the window (asked at every hand-over)."""
        f = self.flags
        return Needs(f.contacts, f.velocities, f.trails)

    def _watch(self, sim: Simulation) -> object:
        """The panel's copy of the run (physics side, at each hand-over): settings, the selection,
        and the traces while the plots are open."""
        from .watch import watch

        it = self.interaction
        self.traces.follow(it.selected_ball)
        selected = None
        if it.selected_ball is not None:
            selected = ("ball", it.selected_ball)
        elif it.selected_plane is not None:
            selected = ("plane", it.selected_plane)
        return watch(sim, selected, self.traces if self.panel_plots else None)

    @property
    def panel_plots(self) -> bool:
        panel = getattr(self, "panel", None)
        return panel is not None and panel.wants_plots

    def select(self, ball: int | None) -> None:
        """Select ``ball`` in the inspector (None: nothing)."""

        def choose(sim: Simulation) -> None:
            self.interaction.deselect()
            self.interaction.selected_ball = ball

        self.command(choose)

    def scene_opened(self) -> None:
        """Another scene was opened: the camera goes to its view."""
        self.physics.sync()  # its first hand-over, to frame it from
        self.orbit.stop()
        self.view.scene_view(self.shown)
        self.window.set_caption(title(self.shown.appearance.name, self.fps))

    # the input's state, read by the HUD, the actions and the tests
    @property
    def held(self) -> set[str]:
        return self.input.held

    @property
    def mouse_captured(self) -> bool:
        return self.input.mouse_captured

    @property
    def shown(self) -> Shown:
        """The latest state the physics handed over."""
        return self.physics.shown

    def command(self, fn, then=None, rewind: bool = True) -> None:
        """Ask the physics side to run ``fn(sim)`` between steps (``then(result)`` back here after; see
        ``PhysicsThread.submit`` for ``rewind``)."""
        self.physics.submit(fn, then, rewind)

    # ------------------------------------------------------------------ actions
    def perform(self, action: Action) -> None:
        """Do what a key asks for. What changes the World goes to the physics side as a command."""
        needs = self._needs()
        self._perform(action)
        if self._needs() != needs:  # an overlay on or off: the states captured ahead lack it
            self.physics.show_again()

    def _perform(self, action: Action) -> None:
        from .actions import perform

        perform(self, action)
        self._hud_at = 0.0  # refresh the HUD on the next frame
        self.physics.refresh_hud()

    def _watched(self, result: tuple[bool, str | None]) -> None:
        """The file watch's answer: the HUD's error, and a reload when the file changed."""
        changed, error = result
        self.hud.set_error(error)
        if changed:
            self.reload()

    def reload(self) -> None:
        """Ctrl+R / F5: the physics side loads the file again between steps; a failed reload keeps the
        last good scene and the HUD shows the error."""
        self.command(lambda sim: (sim.reload(), sim.error)[1], self.hud.set_error)

    def save_scene(self, path: Path | None = None) -> None:
        """Ctrl+S: write the scene as it stands to a new file beside the original (a bundled scene: in
        the current directory, save.py), or to ``path`` (the panel's Save as); the HUD says where."""
        camera = copy.deepcopy(self.camera)

        def save(sim: Simulation) -> Path | OSError:
            from .save import save_scene, save_scene_as

            try:
                if path is not None:
                    return save_scene_as(sim, camera, path, self.interaction.own_motion())
                return save_scene(sim, camera, self.interaction.own_motion())
            except OSError as exc:
                return exc

        self.command(save, self._saved)

    def _saved(self, result: Path | OSError) -> None:
        if isinstance(result, Exception):
            self.hud.flash(f"save failed: {result}", time.perf_counter())
            return
        self.last_save = result
        print(f"scene saved to {self.last_save}", flush=True)
        self.hud.flash(f"scene saved to {_near(self.last_save)}", time.perf_counter())

    def close(self) -> None:
        """Close the window. Outside pyglet's loop (``pump``) the close waits until the events being
        dispatched are done, since pyglet's xlib dispatch cannot continue on a closed window."""
        self.closed = True
        self.physics.stop()  # at once: a step in progress is not waited for
        if self._pyglet.app.event_loop.is_running:
            self._close_window()

    def _close_window(self) -> None:
        self.finish_record()
        if not self._window_closed:
            self._window_closed = True
            self.window.switch_to()
            self.panel.backend.shutdown()
            self.window.close()

    def finish_record(self) -> None:
        """Write the ``--record`` file (once), when the window closes or the run is interrupted: the
        steps finished by then, up to the one shown (a step still in progress on the physics thread, or
        taken ahead of what the window shows, is left out). A video being recorded is finished too."""
        self.video.stop()
        if self.recorder is not None and not self.recorder.finished:
            shown, sim = self.physics.shown, self.sim
            ahead = sim.phase is Phase.RUNNING and shown.generation == sim.generation  # may have run ahead
            # held before X: the steps taken meanwhile were never shown
            finished = self.recorder.finish(0 if sim.held else shown.step if ahead else None)
            if finished is not None:
                path, steps, balls = finished
                print(f"recorded {steps} steps ({balls} balls) to {path}", flush=True)

    def on_resize(self, width: int, height: int) -> None:
        self.panel.backend.resize()
        self.hud.layout()  # pyglet's own handler (viewport, HUD projection) runs after this one

    def on_close(self) -> None:
        self.closed = True
        self.physics.stop()
        self.finish_record()
        self.window.switch_to()
        self.panel.backend.shutdown()  # before pyglet closes the window and its GL context

    def on_draw(self) -> None:
        self.frame()

    # ------------------------------------------------------------------ the frame
    def frame(self, dt: float | None = None) -> None:
        """Fly the camera by real time (or by ``dt``), let the physics run (free, or lockstep by ``dt``)
        and draw the latest state it handed over."""
        now = time.perf_counter()
        elapsed = now - self._last_frame if dt is None else dt
        self._last_frame = now
        self.physics.window_drawing(True)  # a physics thread far ahead leaves the GIL to the frame
        try:
            self._frame(now, elapsed, dt)
        finally:
            self.physics.window_drawing(False)

    def _frame(self, now: float, elapsed: float, dt: float | None) -> None:
        """``frame``'s work, with ``now`` and the ``elapsed`` real time it measured."""
        self.view.move(self.held, elapsed)
        self._queue_interaction((self.window.width, self.window.height), elapsed)
        if now >= self._watch_at:
            self._watch_at = now + WATCH_INTERVAL
            # reads the file's signature and the error alone: the steps taken ahead stay (stepper.py)
            self.physics.submit(lambda sim: (sim.file_changed(), sim.error), self._watched, rewind=False)
        self.camera.inset = self.panel.width / max(self.window.width, 1)
        self.screen.left = self.panel.width
        self.screen.label_interval = self.pacer.hud_interval()  # the bar's time is text as the HUD's
        started = time.perf_counter()
        if dt is None:
            self.physics.run_free()
        else:
            self.physics.advance(elapsed)
        self.physics_seconds = time.perf_counter() - started  # lockstep only: free, it is 0
        self.physics.deliver()
        shown = self.physics.shown
        shown.resolve_ghosts()

        self.window.switch_to()
        width, height = self.window.get_framebuffer_size()
        view = self.view_target
        covered = round(self.panel.width * width / max(self.window.width, 1))  # framebuffer pixels
        view.strip_color = self.panel.background
        drawn = view.begin(width, height, left=covered)
        key = self._view_key(shown, width, height)
        if not (view.keeps_image and key is not None and key == self._drawn_key):
            selected = self.interaction.selected_plane
            self.renderer.selected_plane = -1 if selected is None else selected
            self.feeder.upload(shown, self.flags, self.camera.position, self.interaction.lines())
            self.screen.upload(self.renderer)
            self.renderer.draw(self.camera, *drawn, multisample=view.multisample)
            self._drawn_key, self._drawn_shown = key, shown
            self.views_drawn += 1
        # the HUD's text and the panel are laid out while the rasteriser draws the view (renderer.draw
        # flushes it), then stretched into the window, with the HUD, the labels and the panel over it
        self._update_hud(now, shown)
        self.panel.build(shown, rebuild=self.pacer.build_panel(now, free=dt is None))
        view.finish(width, height)
        self.hud.draw(now)
        self.screen.draw_labels()
        self.panel.render()
        if self.screenshot_requested:
            self.screenshot_requested = False
            self.save_screenshot(width, height)
        self.video.frame(shown.time, shown.hud is None or shown.hud.running, width, height)
        self._count_frame(now, shown)

    def _view_key(self, shown: Shown, width: int, height: int) -> tuple | None:
        """Everything the 3-D view (and the bar and plot drawn with it) depends on: while it stays the
        same (paused, waiting for X, nothing moving) the view drawn last is shown again, not redrawn.
        None while a ball is held (its throw arrow follows the pointer)."""
        if self.interaction.held_ball is not None:
            return None
        c = self.camera
        return (id(shown), shown.ghost_step, tuple(c.position), c.yaw, c.pitch, c.fov_y_degrees, c.inset,
                width, height, self.flags.contacts, self.flags.velocities, self.flags.trails,
                self.panel.width, self.interaction.selected_plane, id(self.view_target))  # fmt: skip

    def _queue_interaction(self, size: tuple[int, int], seconds: float) -> None:
        """A held ball follows the pointer and a selected plane the held keys: the physics side does it
        between steps, with this frame's camera and keys (frames that pass meanwhile add their time)."""
        self._interaction_seconds.append(seconds)
        it = self.interaction
        if it.held_ball is None and it.selected_plane is None:
            self._interaction_seconds.clear()
            return
        self._interaction_input = (copy.deepcopy(self.camera), size, frozenset(self.held))
        if not self._interaction_queued:
            self._interaction_queued = True
            self.command(self._update_interaction)

    def _update_interaction(self, sim: Simulation) -> None:
        self._interaction_queued = False
        camera, size, held = self._interaction_input
        seconds = 0.0
        while self._interaction_seconds:
            seconds += self._interaction_seconds.popleft()
        self.interaction.update(camera, size, held, seconds)

    def _overlay_names(self) -> str:
        f = self.flags
        return " ".join(name for name, on in (("contacts", f.contacts), ("velocities", f.velocities),
                                              ("trails", f.trails)) if on)  # fmt: skip

    def _update_hud(self, now: float, shown: Shown) -> None:
        """The HUD's place and text for this frame (drawn after the view: ``Hud.draw``)."""
        from .hud import hud_lines, profile_lines

        if self.hud.bottom != self.screen.bottom_clearance() or self.hud.left != self.panel.width:
            self.hud.bottom = self.screen.bottom_clearance()
            self.hud.left = self.panel.width
            self.hud.layout()
        if now >= self._hud_at and shown.hud is not None:
            self._hud_at = now + self.pacer.hud_interval()
            facts = self.physics.live_rates(shown)
            if self.hud.page == "profile":
                drawn = [f"renderer    {self.renderer_name}", f"quality     {self.quality.describe()} (F3)",
                         f"drawing     {self.pacer.describe()}"]  # fmt: skip
                self.hud.set_text(profile_lines(facts, drawn))
            else:
                extra, shot = self.interaction.hud_lines(), self.interaction.shot_speed
                self.hud.set_text(hud_lines(facts, self.camera.speed, self._overlay_names(), extra, shot))
            self.hud.set_error(shown.error)
        if shown.message != self._shown_message:
            self._shown_message = shown.message
            if shown.message:
                self.hud.flash(shown.message, now)

    def _count_frame(self, now: float, shown: Shown) -> None:
        self.frames += 1
        self._fps_frames += 1
        if now - self._fps_since >= TITLE_INTERVAL:
            self.fps = self._fps_frames / (now - self._fps_since)
            self._fps_since, self._fps_frames = now, 0
            self.window.set_caption(title(shown.appearance.name, self.fps))

    def save_screenshot(self, width: int, height: int, directory: Path | None = None) -> Path:
        """Save the back buffer (what this frame drew, panel and HUD included) as a PNG (screenshot.py);
        prints the path and shows it in the HUD."""
        from .screenshot import save_screenshot

        self.last_screenshot = save_screenshot(width, height, directory)
        print(f"screenshot saved to {self.last_screenshot}", flush=True)
        self.hud.flash(f"screenshot saved to {_near(self.last_screenshot)}", time.perf_counter())
        return self.last_screenshot

    def sync(self) -> None:
        """Apply the commands sent so far now (waiting for a step in progress): for tests and scripts."""
        self.physics.sync()

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
        """pyglet's event loop until the window closes, drawing at the pacer's rate (pacing.py)."""
        self._due = None
        self._pyglet.clock.schedule_once(self._redraw, 0.0)
        self._pyglet.app.run(None)  # None: the window schedules its own redraws

    def _redraw(self, dt: float) -> None:
        """One frame of pyglet's loop (draw and flip, ``Window.draw``), then the next one scheduled at
        the pacer's interval after this one was due, not after it came: a frame the loop ran late (the
        machine busy) is followed by an earlier one, so the rate drawn is the rate asked. pyglet's own
        ``schedule_interval`` counts from each late call, so every delay lowers the rate."""
        if self.closed or self._window_closed:
            return
        self.window.draw(dt)
        clock = self._pyglet.clock.get_default()
        now = clock.time()
        self._interval = interval = self.pacer.interval(self.physics.busy_fraction, self.physics.pace)
        due = (now if self._due is None else self._due) + interval
        self._due = due if due > now else now  # more than a frame late: do not try to catch up more
        # schedule_once counts from the loop's tick (clock.last_ts) unless that is 0.2 s old
        base = now if clock.last_ts is None or now - clock.last_ts > 0.2 else clock.last_ts
        clock.schedule_once(self._redraw, max(self._due - base, 0.0))


def _near(path: Path) -> Path:
    """``path`` relative to the current directory when it is under it (as the HUD says it)."""
    return path.relative_to(Path.cwd()) if path.is_relative_to(Path.cwd()) else path


def _gl_renderer() -> str:
    """GL_RENDERER of the current context, e.g. "llvmpipe (LLVM 15.0.7, 256 bits)"."""
    from OpenGL import GL

    name = GL.glGetString(GL.GL_RENDERER)
    return name.decode(errors="replace") if name else "unknown"


def run(
    scene_path: Path | None = None,
    trajectory: object = None,
    record: Path | None = None,
    quality: str = "auto",
) -> int:
    """Open the viewer on a scene file (the bundled slopes demo by default); returns the exit status.
    With ``record``, the timeline it showed is written there when the window closes (or on Ctrl+C).

    With no display it prints one line saying how to render offscreen instead and returns 1. With a
    ``trajectory`` (``ballpit.cli.trajectory.read_trajectory``) the window plays it instead of running
    the physics.
    """
    problem = backend.display_problem()
    if problem is not None:
        print(backend.no_display_message(problem), file=sys.stderr)
        return 1
    try:
        viewer = Viewer(scene_path=scene_path, trajectory=trajectory, record=record, quality=quality)
    except Exception as exc:
        if _is_no_display(exc):
            print(backend.no_display_message(str(exc) or "cannot connect"), file=sys.stderr)
            return 1
        raise
    try:
        viewer.run()
    finally:
        viewer.finish_record()
    if viewer.physics.alive:
        _end_mid_step()
    return 0


def _end_mid_step() -> None:
    """End the process now, the window closed and its record written, while the physics thread is still
    inside a step. Python 3.11 ends a daemon thread that wants the GIL back after finalisation began with
    ``pthread_exit``, and the forced unwind aborts the process ("terminate called without an active
    exception", SIGABRT) when it passes a C++ frame of NumPy's that released the GIL (``np.unique``'s
    hashing does: 2 aborts in 20 exits in a probe). Nothing is left to write, so skip the finalisation."""
    import os

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(0)
