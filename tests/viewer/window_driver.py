"""Drives a real viewer window (pyglet + GLX under Xvfb) through one scenario and prints what it saw.

Run as ``python window_driver.py SCENARIO WORKDIR`` with DISPLAY set (test_window.py does this). Input
goes in as real pyglet events dispatched into the real window and delivered by pyglet's event queue;
the window, GL context, shaders and physics are all real. The last stdout line is ``RESULT <json>``.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import ballpit
from ballpit.viewer.app import Viewer

FRAME = 1.0 / 60.0

GOOD_SCENE = """
[camera]
position = [0, 3, 10]
look_at = [0, 1, 0]

[[plane]]
position = [0, 0, 0]

[[sphere]]
position = [0, 3, 0]
radius = 0.3
color = "#e0482f"
"""


OPENED: list[Viewer] = []


def open_viewer(size: tuple[int, int] = (320, 180), panel: bool = False, **kwargs: object) -> Viewer:
    """A viewer window without multisampling (no scenario looks at anti-aliased edges; the renderer
    tests do), at ``size``; the panel hidden unless asked for (the scenarios here reach the 3-D view,
    which at these sizes it would cover)."""
    viewer = Viewer(size=size, panel=panel, **kwargs)
    viewer.sim.step_budget = math.inf  # exact simulated time per frame even on a loaded machine
    OPENED.append(viewer)
    return viewer


def balls_world() -> ballpit.World:
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_plane(position=(0, 2, 0), rotation=(0, 0, 20), size=4.0, restitution=0.6)
    world.add_spheres([[-2, 6, 0], [-1, 6, 0], [0, 6, 0], [1, 6, 0], [2, 6, 0]], radius=0.3)
    return world


def press(viewer: Viewer, name: str, modifiers: int = 0, frames: int = 1) -> None:
    """Press and release a key (by pyglet name) through the window's event queue."""
    from pyglet.window import key

    symbol = getattr(key, name)
    viewer.window.dispatch_event("on_key_press", symbol, modifiers)
    viewer.window.dispatch_event("on_key_release", symbol, modifiers)
    pump(viewer, frames)


def type_text(viewer: Viewer, text: str, frames: int = 1) -> None:
    """Type text (what pyglet's ``on_text`` delivers) through the window's event queue."""
    viewer.window.dispatch_event("on_text", text)
    pump(viewer, frames)


def hold(viewer: Viewer, names: list[str], frames: int) -> None:
    """Hold keys down for ``frames`` frames of 1/60 s, then release them."""
    from pyglet.window import key

    for name in names:
        viewer.window.dispatch_event("on_key_press", getattr(key, name), 0)
    pump(viewer, frames)
    for name in names:
        viewer.window.dispatch_event("on_key_release", getattr(key, name), 0)
    pump(viewer, 1, dt=0.0)


def pump(viewer: Viewer, frames: int, dt: float | None = FRAME) -> None:
    for _ in range(frames):
        viewer.pump(dt)


def pump_for(viewer: Viewer, seconds: float) -> None:
    """Run in real time (wall-clock frame times) for a while."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end and not viewer.closed:
        viewer.pump()


def pump_until(viewer: Viewer, condition, timeout: float = 10.0) -> None:
    """Run in real time until ``condition()`` holds (or the timeout passes)."""
    end = time.perf_counter() + timeout
    while not condition() and time.perf_counter() < end and not viewer.closed:
        viewer.pump()


def xdotool(*args: str) -> str:
    """Real X input: xdotool sends key and pointer events through the X server (XTEST)."""
    out = subprocess.run(["xdotool", *args], capture_output=True, text=True, timeout=20, env=os.environ)
    return out.stdout.strip()


def settle(viewer: Viewer, frames: int = 6) -> None:
    """Let the X server deliver what xdotool sent: pump frames with short pauses."""
    for _ in range(frames):
        time.sleep(0.03)
        viewer.pump(FRAME)


def point_at(viewer: Viewer) -> None:
    """Put the pointer over the window: with no window manager, key input goes where the pointer is."""
    viewer.window.activate()
    settle(viewer)
    xdotool("mousemove", "--window", str(viewer.window._window), "20", "20")
    settle(viewer)


def positions(viewer: Viewer) -> list:
    return np.asarray(viewer.sim.world.spheres.positions).tolist()


# ---------------------------------------------------------------------- scenarios
def title(workdir: Path) -> dict:
    viewer = open_viewer(world=balls_world())
    first = viewer.window.caption
    pump_for(viewer, 1.2)
    return {"first": first, "caption": viewer.window.caption, "fps": viewer.fps, "frames": viewer.frames}


def drop(workdir: Path) -> dict:
    viewer = open_viewer(world=balls_world())
    start = positions(viewer)
    pump(viewer, 30)
    waited = positions(viewer)
    time_waited = viewer.sim.world.time
    press(viewer, "X", frames=30)
    return {"start": start, "waited": waited, "time_waited": time_waited, "after": positions(viewer),
            "time_after": viewer.sim.world.time, "phase": viewer.sim.phase.name}  # fmt: skip


def fly(workdir: Path) -> dict:
    viewer = open_viewer(world=balls_world())
    cam = viewer.camera
    out = {"speed": cam.speed, "forward": cam.forward.tolist(), "right": cam.right.tolist(), "moves": {}}
    for keys in (["W"], ["S"], ["A"], ["D"], ["Q"], ["E"], ["LSHIFT", "W"]):
        before = cam.position.copy()
        hold(viewer, keys, 30)  # 0.5 s
        out["moves"]["+".join(keys)] = (cam.position - before).tolist()
    before = cam.yaw
    from pyglet.window import mouse

    viewer.window.dispatch_event("on_mouse_drag", 100, 100, 40, 0, mouse.RIGHT, 0)
    pump(viewer, 1)
    out["yaw_change_right_drag"] = cam.yaw - before
    speed = cam.speed
    viewer.window.dispatch_event("on_mouse_scroll", 100, 100, 0, 2)
    pump(viewer, 1)
    out["scroll_speed_ratio"] = cam.speed / speed
    return out


def pause_step_reset(workdir: Path) -> dict:
    viewer = open_viewer(world=balls_world())
    sim = viewer.sim
    initial = positions(viewer)
    press(viewer, "X", frames=10)
    press(viewer, "SPACE")
    paused_time, paused_positions = sim.world.time, positions(viewer)
    pump(viewer, 20)
    still_time, still_positions = sim.world.time, positions(viewer)
    press(viewer, "N")
    after_n = sim.world.time
    press(viewer, "RIGHT")
    after_right = sim.world.time
    press(viewer, "SPACE", frames=10)
    resumed_time = sim.world.time
    press(viewer, "R", frames=5)
    return {
        "dt": sim.timestep, "initial": initial, "paused_time": paused_time,
        "paused_positions": paused_positions, "still_time": still_time, "still_positions": still_positions,
        "after_n": after_n,
        "after_right": after_right, "resumed_time": resumed_time, "reset_positions": positions(viewer),
        "reset_time": sim.world.time, "reset_phase": sim.phase.name, "hud": viewer.hud.text,
    }  # fmt: skip


def touch_later(path: Path, text: str) -> None:
    """Rewrite the file and make sure its modification time changes visibly."""
    path.write_text(text)
    stat = path.stat()
    import os

    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 2_000_000_000))


def broken_reload(workdir: Path) -> dict:
    from pyglet.window import key

    from ballpit.viewer.hud import ERROR_COLOR

    scene = workdir / "live.toml"
    scene.write_text(GOOD_SCENE)
    viewer = open_viewer(scene_path=scene)
    sim = viewer.sim
    press(viewer, "X", frames=10)
    world = sim.world
    out: dict = {"title": viewer.window.caption}

    touch_later(scene, GOOD_SCENE.replace("radius = 0.3", "radius = -0.3"))
    press(viewer, "F5", frames=5)
    out["f5_error"] = viewer.hud.error
    out["f5_same_world"] = sim.world is world
    t = sim.world.time
    pump(viewer, 10)
    out["still_running"] = sim.world.time > t and not viewer.closed

    press(viewer, "F12", frames=1)  # the error is on screen: look for its colour in the screenshot
    from PIL import Image

    shot = np.asarray(Image.open(viewer.last_screenshot).convert("RGB")).astype(int)
    out["error_pixels"] = int((np.abs(shot - np.array(ERROR_COLOR[:3])).max(axis=-1) < 40).sum())

    touch_later(scene, "[[sphere]\nposition = [0, 3, 0]\n")  # a TOML syntax error, saved
    started = time.perf_counter()
    pump_until(viewer, lambda: "syntax" in viewer.hud.error.lower())  # no key: the file watcher notices
    out["auto_seconds"] = time.perf_counter() - started
    out["auto_error"] = viewer.hud.error
    out["auto_same_world"] = sim.world is world

    press(viewer, "R", modifiers=key.MOD_CTRL, frames=2)
    out["ctrl_r_error"] = viewer.hud.error

    touch_later(scene, GOOD_SCENE + "\n[[sphere]]\nposition = [1, 3, 0]\nradius = 0.2\n")
    pump_until(viewer, lambda: viewer.sim.ball_count == 2)
    pump(viewer, 2)  # the physics thread reloaded it: the window hears back on its next frames
    out["fixed_error"] = viewer.hud.error
    out["fixed_balls"] = sim.ball_count
    out["fixed_phase"] = sim.phase.name
    out["alive"] = not viewer.closed
    return out


def keys(workdir: Path) -> dict:
    viewer = open_viewer(world=balls_world())
    sim = viewer.sim
    out: dict = {}
    for name in ("_1", "_2", "_3"):
        press(viewer, name)
        out[f"integrator{name}"] = sim.world.integrator
    type_text(viewer, "+")
    out["faster"] = sim.time_scale
    type_text(viewer, "-")
    type_text(viewer, "-")
    out["slower"] = sim.time_scale
    press(viewer, "X", frames=20)
    for name in ("C", "V", "T"):
        press(viewer, name, frames=2)
    out["overlays"] = [viewer.flags.contacts, viewer.flags.velocities, viewer.flags.trails]
    out["draw_labels"] = [c.label for c in viewer.renderer.draws.calls]
    press(viewer, "H")
    out["hud_hidden"] = not viewer.hud.show_hud
    press(viewer, "F1")
    out["help_shown"] = viewer.hud.show_help
    press(viewer, "F12")
    out["screenshot"] = str(viewer.last_screenshot)
    out["screenshot_message"] = shown_message(viewer)
    press(viewer, "TAB")
    out["captured"] = viewer.mouse_captured
    press(viewer, "ESCAPE")
    out["after_first_escape"] = {"captured": viewer.mouse_captured, "closed": viewer.closed,
                                 "message": shown_message(viewer)}  # fmt: skip
    press(viewer, "ESCAPE")  # the Esc that released the mouse did not arm the quit: this one asks
    out["after_second_escape"] = {"closed": viewer.closed, "message": shown_message(viewer)}
    press(viewer, "ESCAPE")
    out["after_third_escape"] = {"closed": viewer.closed}
    return out


def plus_minus_x_keys(workdir: Path) -> dict:
    """+ typed as a real user does: Shift down, = down, Shift up first, = up; three times, then − twice
    and the keypad's + and −."""
    viewer = open_viewer(world=balls_world())
    pump(viewer, 3)
    point_at(viewer)
    scales = []
    for _ in range(3):
        for args in (("keydown", "shift"), ("keydown", "equal"), ("keyup", "shift"), ("keyup", "equal")):
            xdotool(*args)
        settle(viewer)
        scales.append(viewer.sim.time_scale)
    for name in ("minus", "minus", "KP_Add", "KP_Subtract", "KP_Subtract"):
        xdotool("key", name)
        settle(viewer)
        scales.append(viewer.sim.time_scale)
    return {"scales": scales}


def screenshot(viewer: Viewer) -> str:
    """F12, then the path of the PNG it wrote: the window's real pixels, HUD included (the test reads
    the file: a 1280×720 image as a JSON list costs seconds to write, read and move)."""
    press(viewer, "F12")
    return str(viewer.last_screenshot)


def hud_rectangle(viewer: Viewer) -> list[float]:
    """The HUD panel as (left, top, right, bottom) in pixels from the window's top-left corner."""
    panel, height = viewer.hud.panel, viewer.window.height
    return [panel.x, height - panel.y - panel.height, panel.x + panel.width, height - panel.y]


def slopes_framing(workdir: Path) -> dict:
    """The bundled demo in a default-sized window: where its balls are drawn over the whole run, at every
    physics step (the frames are drawn a quarter of a second apart: what is checked is where the camera
    puts each state, and each state is projected with the camera of the frame that showed it)."""
    viewer = open_viewer(size=(1280, 720))  # no scene: the bundled slopes demo
    pump(viewer, 2)
    out: dict = {"size": [viewer.window.width, viewer.window.height], "scene": viewer.sim.appearance.name}
    out["hud"] = hud_rectangle(viewer)
    out["first_frame"] = screenshot(viewer)
    press(viewer, "X")
    radii = np.asarray(viewer.sim.world.spheres.radii)
    stepped: list[np.ndarray] = []
    viewer.sim.before_step.append(lambda: stepped.append(viewer.sim.world.spheres.positions.copy()))
    track = []
    for _ in range(40):  # 10 s of simulated time
        pump(viewer, 1, dt=0.25)
        scale = (out["size"][1] / 2) / math.tan(math.radians(viewer.camera.fov_y_degrees / 2))
        for positions in stepped:
            pixels, depth = viewer.camera.project(positions, *out["size"])
            track.append(np.column_stack([pixels, radii / depth * scale]).tolist())
        stepped.clear()
    out["track"] = track  # per physics step, per ball: (x, y, radius) in pixels
    out["hud_after"] = hud_rectangle(viewer)
    out["bar_top"] = out["size"][1] - viewer.screen.bottom_clearance()  # the timeline bar and its label
    return out


def panel_rectangle(viewer: Viewer, panel: object) -> list[float]:
    """A pyglet rectangle as (left, top, right, bottom) in pixels from the window's top-left corner."""
    height = viewer.window.height
    return [panel.x, height - panel.y - panel.height, panel.x + panel.width, height - panel.y]


def help_beside_hud(workdir: Path) -> dict:
    """F1 in windows of several sizes, with the HUD shown, and two with the ImGui panel shown too:
    where the HUD's and the help's panels are drawn."""
    out: dict = {}
    sizes = [(size, False) for size in ((1280, 720), (900, 700), (700, 420), (600, 300))]
    for size, shown in [*sizes, ((1280, 720), True), ((800, 450), True)]:
        viewer = open_viewer(size=size, world=balls_world(), panel=shown)
        pump(viewer, 2)
        press(viewer, "F1", frames=2)
        hud = viewer.hud
        out[f"{size[0]}x{size[1]}" + (" panel" if shown else "")] = {
            "size": [viewer.window.width, viewer.window.height],
            "left": viewer.panel.width,
            "help_shown": hud.show_help,
            "hud_drawn": hud.show_hud and not getattr(hud, "help_hides_hud", False),
            "hud": panel_rectangle(viewer, hud.panel),
            "help": panel_rectangle(viewer, hud.help_panel),
            "help_text": [
                hud.help_label.x - hud.help_label.content_width / 2,
                viewer.window.height - hud.help_label.y - hud.help_label.content_height / 2,
                hud.help_label.x + hud.help_label.content_width / 2,
                viewer.window.height - hud.help_label.y + hud.help_label.content_height / 2,
            ],
            "pixels": screenshot(viewer) if size == (1280, 720) and not shown else None,
        }
        viewer.close()
        viewer.pump()
    return out


def grab(viewer: Viewer) -> np.ndarray:
    """Draw a frame (no time passes) and read the window's pixels back before showing it, without F12
    (which would flash its own message). (H, W, 3), top row first."""
    from OpenGL import GL

    viewer.window.switch_to()
    viewer.frame(0.0)
    width, height = viewer.window.get_framebuffer_size()
    GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
    GL.glReadBuffer(GL.GL_BACK)
    data = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
    viewer.window.flip()
    return np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3)[::-1].astype(int)


def shown_message(viewer: Viewer) -> str:
    """The HUD's transient message if it is being drawn now, else ""."""
    hud = viewer.hud
    return hud.message if hud.message and time.perf_counter() < hud._message_until else ""


def double_escape(workdir: Path) -> dict:
    """Esc with nothing captured: the first asks for a second (in the HUD, for a while), the second
    quits; once the hint has gone, one Esc asks again."""
    from ballpit.viewer.hud import MARGIN

    viewer = open_viewer(size=(640, 360), world=balls_world())
    pump(viewer, 2)

    def message_strip() -> np.ndarray:  # where the HUD's messages are drawn: along the bottom left
        return grab(viewer)[-MARGIN - 30 :, :320]

    out: dict = {"strip_before": message_strip().tolist()}
    press(viewer, "ESCAPE")
    out["first"] = {"closed": viewer.closed, "message": shown_message(viewer)}
    out["strip_first"] = message_strip().tolist()
    pump_for(viewer, 2.3)
    out["later"] = {"closed": viewer.closed, "message": shown_message(viewer)}
    out["strip_later"] = message_strip().tolist()
    press(viewer, "ESCAPE")
    out["again"] = {"closed": viewer.closed, "message": shown_message(viewer)}
    press(viewer, "ESCAPE")
    out["twice"] = {"closed": viewer.closed}
    return out


def profile_page(workdir: Path) -> dict:
    """F2 shows where the step's time goes, stage by stage; F2 again goes back to the HUD."""
    viewer = open_viewer(world=balls_world())
    press(viewer, "X")
    pump(viewer, 90)  # the balls land on the slope and the floor
    press(viewer, "F2")
    pump_until(viewer, lambda: "step profile," in viewer.hud.text)
    profile = viewer.hud.text
    quality = viewer.quality.name
    press(viewer, "F3", frames=2)  # drawing quality, live: the other level, said in the HUD
    switched = {"quality": viewer.quality.name, "message": shown_message(viewer), "before": quality,
                "scale": viewer.view_target.size[0] / viewer.window.width}  # fmt: skip
    press(viewer, "F2")
    pump_until(viewer, lambda: "sim time" in viewer.hud.text)
    return {"profile": profile, "back": viewer.hud.text, "page": viewer.hud.page,
            "renderer": viewer.renderer_name, "switched": switched}  # fmt: skip


def _bundled_viewer(name: str) -> Viewer:
    """The bundled scene ``name`` in a default-sized window, its physics running free as in the app."""
    from ballpit.scene import default_scene_path

    viewer = Viewer(size=(1280, 720), scene_path=default_scene_path().with_name(name))
    OPENED.append(viewer)
    return viewer


def _drop_and_land(viewer: Viewer, seconds: float) -> dict:
    """X, then wait for the first step, then count frames drawn and steps taken for ``seconds``."""
    from pyglet.window import key

    pump_for(viewer, 0.5)
    viewer.window.dispatch_event("on_key_press", key.X, 0)
    pump_until(viewer, lambda: viewer.sim.steps_total > 0, timeout=30)
    pump_for(viewer, 1.0)  # into the landing: the balls reach the floor
    frames, steps, started = viewer.frames, viewer.sim.steps_total, time.perf_counter()
    pump_for(viewer, seconds - 1.0)
    sim_time, last_second = viewer.sim.world.time, time.perf_counter()
    pump_for(viewer, 1.0)
    now = time.perf_counter()
    wall = now - started
    steps_per_second = (viewer.sim.steps_total - steps) / wall
    return {"fps": (viewer.frames - frames) / wall, "steps_per_second": steps_per_second,
            "last_second_factor": (viewer.sim.world.time - sim_time) / (now - last_second),
            "caption": viewer.window.caption, "hud": viewer.hud.text}  # fmt: skip


def pile_landing(workdir: Path) -> dict:
    """pile.toml (1,200 balls) landing in real time: frames drawn against physics steps taken."""
    return _drop_and_land(_bundled_viewer("pile.toml"), 4.0)


def held_drop(workdir: Path) -> dict:
    """slopes.toml waiting for X until its drop is held (its first second stepped), then X: what the
    window showed before, and the HUD's real-time factor and the state shown 0.4 s after."""
    import re

    from pyglet.window import key

    viewer = _bundled_viewer("slopes.toml")
    physics, sim = viewer.physics, viewer.sim
    first = np.array(sim.world.spheres.positions)
    pump_until(viewer, lambda: sim.held and sim.world.time >= physics.lead - 1e-9, timeout=30)
    pump_for(viewer, 0.2)
    before = {"held": sim.held, "stepped": sim.world.time, "shown": physics.shown.time,
              "moved": float(np.abs(physics.shown.positions - first).max()),
              "hud": viewer.hud.text, "prompt": physics.shown.watch.world.phase.name}  # fmt: skip
    viewer.window.dispatch_event("on_key_press", key.X, 0)
    pump_for(viewer, 0.4)
    shown = physics.shown
    factor = float(re.search(r"real-time factor (\d\.\d\d)", viewer.hud.text).group(1))
    hud_time = float(re.search(r"sim time +(\d+\.\d+) s", viewer.hud.text).group(1))
    after = {"shown": shown.time, "factor": factor, "stepped_factor": shown.hud.real_time_factor,
             "hud_time": hud_time,
             "hud": viewer.hud.text, "phase": sim.phase.name}  # fmt: skip
    return {"before": before, "after": after}


def view_reuse(workdir: Path) -> dict:
    """Waiting for X with nothing moving, then flying: frames shown against 3-D views drawn."""
    viewer = open_viewer(world=balls_world())
    pump_for(viewer, 0.3)
    frames, views = viewer.frames, viewer.views_drawn
    pump_for(viewer, 1.5)
    still = {"frames": viewer.frames - frames, "views": viewer.views_drawn - views}
    from pyglet.window import key

    viewer.window.dispatch_event("on_key_press", key.W, 0)
    frames, views = viewer.frames, viewer.views_drawn
    pump_for(viewer, 0.5)
    flying = {"frames": viewer.frames - frames, "views": viewer.views_drawn - views}
    viewer.window.dispatch_event("on_key_release", key.W, 0)
    return {"still": still, "flying": flying, "quality": viewer.quality.name}


def escape_mid_step(workdir: Path) -> dict:
    """pile10k.toml landing in real time; Esc, Esc while a step runs: how long until the window closes."""
    from pyglet.window import key

    viewer = _bundled_viewer("pile10k.toml")
    out = _drop_and_land(viewer, 1.0)
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    pump(viewer, 2, dt=None)
    pump_until(viewer, lambda: viewer.physics.lock.locked(), timeout=10)  # a step is in progress
    out["stepping_at_escape"] = viewer.physics.lock.locked()
    pressed = time.perf_counter()
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    while not viewer.closed and time.perf_counter() - pressed < 10:
        viewer.pump()
    viewer.pump()  # outside pyglet's loop the window closes on the next pump
    out["quit_seconds"] = time.perf_counter() - pressed
    out["closed"] = viewer.closed
    return out


def pacing(workdir: Path) -> dict:
    """pyglet's own loop (``Viewer.run``, as ``ballpit view``) on balls in 1/60 s steps that each take
    30 ms of wall time (about half real time), then paused: the redraw interval the window schedules
    and the frames it draws in a second each way; while running, the times between changes of the
    timeline bar's label."""
    import pyglet
    from pyglet.window import key

    from ballpit.scene import Scene, default_appearance

    world = balls_world()
    viewer = Viewer(
        size=(320, 180), world=Scene(world, default_appearance(world), timestep=1.0 / 60.0), panel=False
    )
    OPENED.append(viewer)
    viewer.sim.before_step.append(lambda: time.sleep(0.03))
    out: dict = {}
    marks: dict = {}
    started = time.perf_counter()

    def tap(symbol: int) -> None:
        viewer.window.dispatch_event("on_key_press", symbol, 0)
        viewer.window.dispatch_event("on_key_release", symbol, 0)

    labels: list = []  # when the timeline bar's label changed, while running

    def seen(name: str) -> None:
        frames, at = marks.pop(name)
        out[name] = {"interval": viewer._interval, "busy": viewer.physics.busy_fraction,
                     "pace": viewer.physics.pace,
                     "fps": (viewer.frames - frames) / (time.perf_counter() - at)}  # fmt: skip

    def script(_dt: float) -> None:
        t = time.perf_counter() - started
        changed = viewer.screen.label_changed
        if "running" in marks and (not labels or labels[-1] != changed):
            labels.append(changed)
        if t > 0.4 and "waiting" not in out:
            out["waiting"] = {"interval": viewer._interval}
            tap(key.X)
        elif t > 2.5 and "running" not in out and "running" not in marks:
            marks["running"] = (viewer.frames, time.perf_counter())
        elif t > 3.5 and "running" in marks:
            seen("running")
            out["running"]["label_gaps"] = [b - a for a, b in itertools.pairwise(labels)]
            tap(key.SPACE)
        elif t > 5.0 and "paused" not in out and "paused" not in marks:
            marks["paused"] = (viewer.frames, time.perf_counter())
        elif t > 6.0 and "paused" in marks:
            seen("paused")
            pyglet.clock.unschedule(script)
            viewer.close()
        elif t > 30:
            viewer.close()

    pyglet.clock.schedule_interval(script, 0.02)
    viewer.run()
    return out


def rasteriser_threads(workdir: Path) -> dict:
    """A drawn frame, then the threads of this process: how many are llvmpipe's rasterisers."""
    viewer = open_viewer(world=balls_world())
    pump(viewer, 3)
    names = []
    for tid in os.listdir("/proc/self/task"):
        with open(f"/proc/self/task/{tid}/comm") as f:
            names.append(f.read().strip())
    return {"renderer": viewer.renderer_name, "cores": len(os.sched_getaffinity(0)),
            "rasterisers": sum(name.startswith("llvmpipe") for name in names),
            "variable": os.environ.get("LP_NUM_THREADS")}  # fmt: skip


SCENARIOS = {
    f.__name__: f
    for f in (
        title,
        drop,
        held_drop,
        fly,
        pause_step_reset,
        broken_reload,
        keys,
        plus_minus_x_keys,
        slopes_framing,
        help_beside_hud,
        double_escape,
        profile_page,
        pile_landing,
        escape_mid_step,
        view_reuse,
        pacing,
        rasteriser_threads,
    )
}


def main(scenarios: dict | None = None) -> None:
    """``python DRIVER NAME[,NAME...] WORKDIR [EXTRA...]``: run the scenarios one after another in this
    process, each in a window of its own and in a folder of its own (``WORKDIR/NAME``; WORKDIR itself
    for a single one), and print ``RESULT NAME <json>`` (or ``FAILED NAME <traceback as json>``) for each."""
    import traceback

    scenarios = SCENARIOS if scenarios is None else scenarios
    names, workdir = sys.argv[1].split(","), Path(sys.argv[2])
    for name in names:
        folder = workdir if len(names) == 1 else workdir / name
        folder.mkdir(parents=True, exist_ok=True)
        os.chdir(folder)  # where a scenario's screenshots and saves go
        OPENED.clear()
        try:
            line = f"RESULT {name} " + json.dumps(scenarios[name](folder))
        except Exception:
            line = f"FAILED {name} " + json.dumps(traceback.format_exc())
        for viewer in OPENED:
            viewer.close()
            viewer.pump()  # outside pyglet's loop the window closes on the next pump
        print(line, flush=True)
    # a physics thread may still be inside a step (escape_mid_step): end as the viewer's run() does
    from ballpit.viewer.app import _end_mid_step

    _end_mid_step()


if __name__ == "__main__":
    main()
