"""Drives the panel of a real viewer window (pyglet + GLX under Xvfb) with real clicks and typing.

Run as ``python panel_driver.py SCENARIO WORKDIR`` with DISPLAY set (test_panel.py does this). The
pointer and the keyboard are real X input from xdotool, sent to the widgets' places as the panel laid
them out in the last frame (``Panel.rects``); a dropped file is pyglet's ``on_file_drop`` dispatched into
the real window. The last stdout line per scenario is ``RESULT <name> <json>``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image
from window_driver import grab, open_viewer, point_at, press, pump, settle, xdotool
from window_driver import main as window_main

from ballpit.scene import default_scene_path
from ballpit.viewer.app import Viewer

SIZE = (1280, 720)

BOUNCE_SCENE = """# one ball over an elastic floor
[world]
timestep = 0.004166667

[camera]
position = [0, 1.5, 7]
look_at = [0, 1, 0]

[[plane]]
normal = [0, 1, 0]
restitution = 1.0
friction = 0.0

[[sphere]]
position = [0, 2.25, 0]
radius = 0.25
restitution = 1.0
friction = 0.0
color = "#e0482f"
"""

BROKEN_SCENE = """[[sphere]]
position = [0, 1, 0]
radius = -1
"""


def panel_viewer(workdir: Path, text: str | None = None, name: str = "scene.toml") -> Viewer:
    path = default_scene_path()
    if text is not None:
        path = workdir / name
        path.write_text(text)
    viewer = open_viewer(size=SIZE, scene_path=path, panel=True)
    pump(viewer, 3)
    point_at(viewer)
    return viewer


def click(viewer: Viewer, key: str, frames: int = 4) -> None:
    """A real left click (xdotool) at the middle of the widget ``key`` as the panel drew it last."""
    x, y, w, h = viewer.panel.rects[key]
    click_at(viewer, x + w / 2, y + h / 2, frames)


def click_at(viewer: Viewer, x: float, y: float, frames: int = 4) -> None:
    """A real left click at window pixel (x, y), y down from the top."""
    wid = str(viewer.window._window)
    xdotool("mousemove", "--window", wid, str(int(x)), str(int(y)))
    settle(viewer, 2)
    xdotool("click", "1")
    settle(viewer, frames)


def type_into(viewer: Viewer, key: str, text: str) -> None:
    """Click into the field ``key`` (ImGui selects its text), type ``text`` and press Enter."""
    click(viewer, key, frames=3)
    xdotool("type", "--delay", "30", text)
    settle(viewer, 3)
    xdotool("key", "Return")
    settle(viewer, 4)


def collapse(viewer: Viewer, *sections: str) -> None:
    for name in sections:
        if viewer.panel.sections.get(name):
            click(viewer, f"section {name}", frames=3)


def red_pixels(image: np.ndarray, rect: tuple) -> int:
    """How many pixels of the panel's error red are inside ``rect`` (x, y, w, h, y down)."""
    x, y, w, h = (int(v) for v in rect)
    region = image[y : y + h, x : x + w]
    return int(((region[..., 0] > 200) & (region[..., 1] < 150) & (region[..., 2] < 140)).sum())


def wait_for(viewer: Viewer, condition, frames: int = 120) -> bool:
    for _ in range(frames):
        if condition():
            return True
        settle(viewer, 1)
    return bool(condition())


# ---------------------------------------------------------------------- scenarios
def scene_list(workdir: Path) -> dict:
    """Click a bundled scene in the list: it loads, and the camera goes to its view; the panel is opaque,
    in ImGui's window colour; then F4 hides the panel, the view fills the strip and the HUD moves to the
    window's edge."""
    viewer = panel_viewer(workdir)
    out: dict = {"before": viewer.sim.appearance.name, "panel_width": viewer.panel.width}
    out["hud_x_shown"] = viewer.hud.panel.x
    click(viewer, "scene cradle")
    wait_for(viewer, lambda: viewer.sim.path.stem == "cradle")
    pump(viewer, 2)
    sim = viewer.sim
    look = sim.appearance
    out |= {
        "after": look.name,
        "balls": sim.ball_count,
        "phase": sim.phase.name,
        "camera": viewer.camera.position.tolist(),
        "scene_camera": look.camera_position.tolist(),
        "look_at": look.camera_look_at.tolist(),
        "forward": viewer.camera.forward.tolist(),
        "title": viewer.window.caption,
        "recent": [p.name for p in viewer.panel.recent],
    }
    background = np.round(np.array(viewer.panel.background) * 255)
    width = int(viewer.panel.width)

    def background_share() -> float:
        """The share of the strip the panel covers (when shown) that is its background colour."""
        strip = grab(viewer)[:, :width].astype(float)
        return float((np.abs(strip - background) <= 1).all(axis=-1).mean())

    out["panel_background_share"] = background_share()
    out["background"] = background.tolist()
    press(viewer, "F4", frames=3)
    out["strip_background_share_hidden"] = background_share()
    out["panel_after_f4"] = viewer.panel.shown
    out["hud_x_hidden"] = viewer.hud.panel.x
    out["inset_hidden"] = viewer.camera.inset
    return out


def drop_buttons(workdir: Path) -> dict:
    """The Drop button does what X does; Pause, Step and Reset do what Space, N and R do."""
    viewer = panel_viewer(workdir, BOUNCE_SCENE)
    sim = viewer.sim
    out: dict = {"prompt": "prompt" in viewer.panel.rects}
    image = grab(viewer)
    x, y, w, h = viewer.panel.rects["prompt"]
    out["prompt_white"] = int((image[int(y) : int(y + h), int(x) : int(x + w)] > 240).all(axis=-1).sum())
    click(viewer, "Drop")
    out["after_drop"] = sim.phase.name
    pump(viewer, 6)
    out["fell"] = 2.25 - float(sim.world.spheres[0].position[1])
    viewer.panel.rects.pop("prompt", None)
    pump(viewer, 1)
    out["prompt_after"] = "prompt" in viewer.panel.rects
    click(viewer, "Pause")
    out["after_pause"] = sim.phase.name
    t = sim.world.time
    click(viewer, "Step")
    out["stepped"] = sim.world.time - t
    click(viewer, "Reset")
    out["after_reset"] = [sim.phase.name, float(sim.world.time), float(sim.world.spheres[0].position[1])]
    return out


def restitution_edit(workdir: Path) -> dict:
    """Select the ball by clicking it, drop it, and while it falls type a new restitution into the
    inspector: its next bounce reaches e²·h. Then a NaN typed into the radius is refused beside the
    field, the radius stays, and the run goes on."""
    viewer = panel_viewer(workdir, BOUNCE_SCENE)
    sim = viewer.sim
    collapse(viewer, "Scenes", "Simulation")
    ball = sim.world.spheres[0]
    pixels, _ = viewer.camera.project(np.array(ball.position)[None, :], *SIZE)
    click_at(viewer, *pixels[0])  # select it (before the drop: nothing moves)
    wait_for(viewer, lambda: "ball.restitution" in viewer.panel.rects)
    out: dict = {"selected": viewer.interaction.selected_ball, "start": ball.position.tolist()}
    heights: list[tuple[float, float]] = []
    sim.after_step.append(lambda: heights.append((sim.world.time, float(sim.world.spheres[0].position[1]))))
    press(viewer, "X", frames=12)  # 0.2 s of the 0.64 s fall
    type_into(viewer, "ball.restitution", "0.6")
    out["restitution"] = sim.world.spheres[0].restitution
    out["edited_at"] = sim.world.time
    out["errors"] = dict(viewer.panel.edits.errors)
    pump(viewer, 90)  # the bounce and the flight up to the apex and down again
    out["heights"] = heights
    # a NaN typed into the radius: refused beside the field, the radius and the run go on
    t = sim.world.time
    type_into(viewer, "ball.radius", "nan")
    wait_for(viewer, lambda: "ball.radius" in viewer.panel.edits.errors)
    pump(viewer, 2)
    out["radius_error"] = viewer.panel.edits.errors.get("ball.radius")
    out["radius"] = sim.world.spheres[0].radius
    out["ran_on"] = sim.world.time - t
    out["phase"] = sim.phase.name
    image = grab(viewer)
    out["error_red"] = red_pixels(image, viewer.panel.rects["error ball.radius"])
    type_into(viewer, "ball.mass", "1.5")  # "1" is Euler's key: typed into a field, it is only text
    out["integrator_after_typing"] = sim.world.integrator
    out["mass"] = sim.world.spheres[0].mass
    press(viewer, "P", frames=10)  # the plots: the energy, and the selected ball's height and speed
    out["plots"] = [key for key in ("plot area energy", "plot area ball") if key in viewer.panel.rects]
    image = grab(viewer)
    x, y, w, h = viewer.panel.rects["plot area ball"]
    region = image[int(y) : int(y + h), int(x) : int(x + w)]
    out["apex_marker"] = int(((region[..., 1] > 150) & (region[..., 0] < 120) & (region[..., 2] < 120)).sum())
    return out


def file_drop(workdir: Path) -> dict:
    """A .toml dropped on the window opens; one that is not a valid scene keeps the current scene and
    its error shows in the panel, in red."""
    viewer = panel_viewer(workdir)
    good = workdir / "bounce.toml"
    good.write_text(BOUNCE_SCENE)
    bad = workdir / "broken.toml"
    bad.write_text(BROKEN_SCENE)
    viewer.window.dispatch_event("on_file_drop", 700, 300, [str(good)])
    wait_for(viewer, lambda: viewer.sim.path.stem == "bounce")
    out: dict = {"after_good": viewer.sim.appearance.name, "balls": viewer.sim.ball_count}
    viewer.window.dispatch_event("on_file_drop", 700, 300, [str(bad)])
    wait_for(viewer, lambda: "scene" in viewer.panel.edits.errors)
    pump(viewer, 2)
    out["after_bad"] = viewer.sim.appearance.name
    out["error"] = viewer.panel.edits.errors.get("scene")
    image = grab(viewer)
    out["error_red"] = red_pixels(image, viewer.panel.rects["error scene"])
    press(viewer, "X", frames=30)
    out["still_runs"] = float(viewer.sim.world.time)
    return out


def add_ball(workdir: Path) -> dict:
    """Tick "add a ball where I click", click the floor: a ball appears there, resting on it; the same
    click again would put one inside it, and the World's refusal shows in the panel."""
    viewer = panel_viewer(workdir, BOUNCE_SCENE)
    sim = viewer.sim
    collapse(viewer, "Scenes", "Simulation")
    click(viewer, "add ball")
    out: dict = {"adding": viewer.panel.adding_ball}
    floor = np.array([1.5, 0.0, 0.5])
    pixels, _ = viewer.camera.project(floor[None, :], *SIZE)
    click_at(viewer, *pixels[0])
    wait_for(viewer, lambda: sim.ball_count == 2)
    out["count"] = sim.ball_count
    out["new"] = sim.world.spheres[1].position.tolist() if sim.ball_count == 2 else None
    out["radius"] = sim.world.spheres[1].radius if sim.ball_count == 2 else None
    click_at(viewer, *pixels[0])
    wait_for(viewer, lambda: "add" in viewer.panel.edits.errors)
    out["count_again"] = sim.ball_count
    out["error"] = viewer.panel.edits.errors.get("add")
    return out


def orbit(workdir: Path) -> dict:
    """Double-click the ball: the camera orbits it; the wheel zooms towards it; a right drag turns
    about it; Home goes back to the scene's view, flying free."""
    viewer = panel_viewer(workdir, BOUNCE_SCENE)
    sim = viewer.sim
    centre = np.array(sim.world.spheres[0].position)
    pixels, _ = viewer.camera.project(centre[None, :], *SIZE)
    wid = str(viewer.window._window)
    xdotool("mousemove", "--window", wid, str(int(pixels[0, 0])), str(int(pixels[0, 1])))
    settle(viewer, 2)
    xdotool("click", "--repeat", "2", "--delay", "60", "1")
    wait_for(viewer, lambda: viewer.orbit.active, frames=60)
    out: dict = {
        "active": viewer.orbit.active,
        "centre": centre.tolist(),
        "position": sim.world.spheres[0].position.tolist(),
    }
    out["target"] = viewer.orbit.target.tolist() if viewer.orbit.active else None
    out["distance"] = viewer.orbit.distance(viewer.camera)
    xdotool("click", "4")  # the wheel, one notch up
    settle(viewer, 4)
    out["zoomed"] = viewer.orbit.distance(viewer.camera)
    yaw = viewer.camera.yaw
    xdotool("mousedown", "3")
    for k in range(1, 6):
        xdotool("mousemove", "--window", wid, str(int(pixels[0, 0]) + 20 * k), str(int(pixels[0, 1])))
        settle(viewer, 1)
    xdotool("mouseup", "3")
    settle(viewer, 3)
    out["turned"] = viewer.camera.yaw - yaw
    out["looks_at_target"] = float(
        np.linalg.norm(
            viewer.camera.position
            + viewer.camera.forward * viewer.orbit.distance(viewer.camera)
            - viewer.orbit.target
        )
    )
    press(viewer, "HOME", frames=2)
    out["after_home"] = [
        viewer.orbit.active,
        viewer.camera.position.tolist(),
        sim.appearance.camera_position.tolist(),
    ]
    return out


def energy_legend(workdir: Path) -> dict:
    """Ghosts on (G), the energy plot open (P), the drop (X): where ImPlot put the plot's legend, and
    how many of its pixels are in each curve's colour."""
    from ballpit.viewer.energyplot import KINETIC_COLOR, POTENTIAL_COLOR
    from ballpit.viewer.ghosts import TINTS

    viewer = panel_viewer(workdir)
    press(viewer, "G", frames=2)
    press(viewer, "P", frames=2)
    press(viewer, "X", frames=40)
    image = grab(viewer)
    rects = viewer.panel.rects
    out: dict = {"frame": rects["frame energy"], "legend": rects["legend energy"]}
    x, y, w, h = (round(v) for v in rects["legend energy"])
    region = image[y : y + h, x : x + w]
    colors = {"kinetic": KINETIC_COLOR, "potential": POTENTIAL_COLOR} | {
        name: (*rgb, 1.0) for name, rgb in TINTS.items()
    }
    out["swatches"] = {
        name: int((np.abs(region - np.round(np.array(c[:3]) * 255)).max(axis=-1) < 12).sum())
        for name, c in colors.items()
    }
    out["ghosts"] = len(viewer.shown.ghosts or ())
    return out


# How many frames the record scenario waits for the video to catch up with the window (it takes one
# or two): recording that failed never does.
RECORD_WAIT_FRAMES = 120


def _open_record_section(viewer: Viewer) -> None:
    """Fold the sections above it and open "Record video", so its button is on screen."""
    collapse(viewer, "Scenes", "Simulation", "Inspector")
    click(viewer, "section Record video", frames=3)
    wait_for(viewer, lambda: "Record MP4" in viewer.panel.rects)


def record_button(workdir: Path) -> dict:
    """X, then a click on Record MP4, a second of the run, and a click again: the MP4 it wrote, the
    panel's state while it recorded and after, and the window's pixels at a state the video holds."""
    viewer = panel_viewer(workdir)
    _open_record_section(viewer)
    press(viewer, "X", frames=3)
    click(viewer, "Record MP4")
    video = viewer.video
    out: dict = {"recording": video.is_recording, "panel_width": viewer.panel.width}
    pump(viewer, 60)
    pump(viewer, 1)
    for _ in range(RECORD_WAIT_FRAMES):  # until the state shown now is one the video holds
        if video.clock.last == viewer.shown.time:
            break
        pump(viewer, 1)
    else:
        raise AssertionError(
            f"no frame of the video holds the state shown after {RECORD_WAIT_FRAMES} more frames "
            f"(recording: {video.is_recording}, video frames: {video.clock.frames}): did recording fail?"
        )
    image = grab(viewer)
    out["window"] = str(workdir / "window.png")
    Image.fromarray(image.astype(np.uint8)).save(out["window"])
    out["grabbed_frame"] = video.clock.frames - 1  # the index of the frame that state went to
    out["rec_red"] = red_pixels(image, viewer.panel.rects["recording"])  # "● REC 1.0 s" in the panel
    out["seconds_shown"] = video.seconds
    click(viewer, "Record MP4")
    out["after_second_click"] = video.is_recording
    finished = video.last_video
    out["video"] = {"path": str(finished.path), "frames": finished.frames, "seconds": finished.seconds}
    out["covered"] = video.clock.last - video.started_at  # simulated s from the first frame to the last
    out["fps"] = video.fps
    pump(viewer, 2)
    out["saved_line"] = "video saved" in viewer.panel.rects
    out["still_runs"] = viewer.sim.phase.name
    return out


def record_without_pyav(workdir: Path) -> dict:
    """PyAV cannot be imported (a minimal install): Record MP4 shows why in the panel, in red, on its
    own, and the run goes on."""
    import sys

    sys.modules["av"] = None  # type: ignore[assignment]  # import av now raises ImportError
    viewer = panel_viewer(workdir)
    _open_record_section(viewer)
    press(viewer, "X", frames=3)
    click(viewer, "Record MP4")
    pump(viewer, 2)
    t = viewer.sim.world.time
    pump(viewer, 30)
    image = grab(viewer)
    out: dict = {"recording": viewer.video.is_recording, "error": viewer.video.error}
    out["error_red"] = red_pixels(image, viewer.panel.rects["error video"])
    out["error_height"] = viewer.panel.rects["error video"][3]
    out["ran_on"] = viewer.sim.world.time - t
    out["videos"] = (workdir / "videos").exists()
    return out


def busy_panel(workdir: Path) -> dict:
    """The physics busy (the pacer slow): frames in quick succession draw the panel's last build again,
    the same pixels; a real pointer move over the panel builds it on the next frame; with the physics
    at ease again every frame builds it."""
    from ballpit.viewer import pacing

    viewer = panel_viewer(workdir)
    backend = viewer.panel.backend
    width = int(viewer.panel.width)
    settle(viewer, 6)  # the X events of the pointer placed as it opened are delivered
    viewer.pacer.slow = True
    pacing.PANEL_BUSY_HZ = 0.1  # once in ten seconds: what follows is within that, however loaded
    first = grab(viewer)[:, :width]  # built: the first frame while busy
    built = backend.builds, backend.redraws
    uploads = backend.renderer.uploads
    same = []
    for _ in range(4):  # (a stray X event, the window's own, may make one of them build)
        same.append(bool(np.array_equal(grab(viewer)[:, :width], first)))
    out: dict = {"quick": [backend.builds - built[0], backend.redraws - built[1]]}
    out["uploads"] = backend.renderer.uploads - uploads  # ImGui's triangles sent to GL in those frames
    out["same_pixels"] = all(same)
    out["panel_pixels"] = int((first.max(axis=-1) > 0).sum())
    x, y, w, h = viewer.panel.rects["section Scenes"]
    builds = backend.builds
    xdotool("mousemove", "--window", str(viewer.window._window), str(int(x + w / 2)), str(int(y + h / 2)))
    settle(viewer, 4)
    out["after_pointer"] = backend.builds - builds
    viewer.pacer.slow = False
    builds = backend.builds
    pump(viewer, 3)
    out["at_ease"] = backend.builds - builds
    return out


SCENARIOS = {
    f.__name__: f
    for f in (
        busy_panel,
        scene_list,
        drop_buttons,
        restitution_edit,
        file_drop,
        add_ball,
        orbit,
        energy_legend,
        record_button,
        record_without_pyav,
    )
}


if __name__ == "__main__":
    window_main(SCENARIOS)
