"""Reaching into a real viewer window (pyglet + GLX under Xvfb): picking up and throwing balls,
shooting, selecting and moving planes, Home and Ctrl+S. Run as ``python reach_driver.py SCENARIO
WORKDIR`` with DISPLAY set (test_reach.py does this); the last stdout line is ``RESULT <json>``.

Input goes in as real pyglet events dispatched into the real window's queue, or as real X pointer and
key events from xdotool; the window, GL context, shaders and physics are all real.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from window_driver import grab, hold, open_viewer, point_at, press, pump, settle, xdotool
from window_driver import main as window_main

from ballpit.viewer.app import Viewer
from ballpit.viewer.picking import camera_basis

FRAME = 1.0 / 60.0

FLOOR_SCENE = """# a floor and one ball at rest on it
[world]
timestep = 0.004166667

[camera]
position = [0, 1.5, 8]
look_at = [0, 1, 0]

[[plane]]                   # the floor
normal = [0, 1, 0]
restitution = 0.5

[[sphere]]                  # the ball we pick up
position = [0, 0.3, 0]
radius = 0.3
color = "#e0482f"
"""

RAMP_SCENE = """# a ball resting on a square above the floor
[world]
timestep = 0.004166667

[camera]
position = [0, 4, 9]
look_at = [0, 1, 0]

[[plane]]                   # the floor
normal = [0, 1, 0]

[[plane]]                   # the square we tilt
position = [0, 1, 0]
size = 4
restitution = 0.3
friction = 0.6

[[sphere]]
position = [0, 1.25, 0]
radius = 0.25
"""


def scene_viewer(workdir: Path, text: str, name: str = "live.toml", size=(640, 360)) -> Viewer:
    path = workdir / name
    path.write_text(text)
    return open_viewer(size=size, scene_path=path)


def window_point(viewer: Viewer, point: object) -> tuple[float, float]:
    """Where a world point is drawn, in pyglet window coordinates (y up from the bottom)."""
    w, h = viewer.window.width, viewer.window.height
    pixels, _ = viewer.camera.project(np.asarray(point, dtype=float)[None, :], w, h)
    return float(pixels[0, 0]), float(h - pixels[0, 1])


def mouse(viewer: Viewer, event: str, *args: object) -> None:
    viewer.window.dispatch_event(event, *args)


def tap(viewer: Viewer, name: str, modifiers: int = 0) -> None:
    """Press and release a key and deliver it in a frame in which no time passes."""
    press(viewer, name, modifiers=modifiers, frames=0)
    pump(viewer, 1, dt=0.0)


def ball_state(viewer: Viewer, i: int) -> dict:
    b = viewer.sim.world.spheres[i]
    return {"position": b.position.tolist(), "velocity": b.velocity.tolist()}


# ---------------------------------------------------------------------- scenarios
def drag_throw(workdir: Path, paused: bool = False) -> dict:
    """Pick the resting ball up, drag it right and up at a steady pixel rate; running, hold the pointer
    still for 1.5 s (the spring settles the ball on it) and drag on; let go."""
    from pyglet.window import mouse as buttons

    viewer = scene_viewer(workdir, FLOOR_SCENE)
    sim = viewer.sim
    press(viewer, "X", frames=10)
    if paused:
        press(viewer, "SPACE")
    out: dict = {"g": sim.world.gravity.tolist(), "dt": sim.timestep, "frame": FRAME}
    right, up, forward = camera_basis(viewer.camera)
    start = np.array(sim.world.spheres[0].position)
    depth = float((start - viewer.camera.position) @ forward)
    out |= {"right": right.tolist(), "up": up.tolist(), "depth": depth, "height": viewer.window.height,
            "fov": viewer.camera.fov_y_degrees, "start": start.tolist()}  # fmt: skip
    x, y = window_point(viewer, start + np.array([0.05, 0.1, 0.0]))  # off centre: no jump when grabbed
    mouse(viewer, "on_mouse_press", x, y, buttons.LEFT, 0)
    pump(viewer, 1)
    out["grabbed"] = viewer.interaction.held_ball
    out["after_grab"] = ball_state(viewer, 0)["position"]
    step_x, step_y = 4, 3  # pixels per frame
    held, times = [], []

    def drag(frames: range) -> None:
        for k in frames:
            mouse(viewer, "on_mouse_drag", x + step_x * k, y + step_y * k, step_x, step_y, buttons.LEFT, 0)
            pump(viewer, 1)
            held.append(ball_state(viewer, 0))
            times.append(sim.world.time)

    drag(range(1, 21))
    out |= {"held": held[:], "held_times": times[:], "pixel_step": [step_x, step_y]}
    if not paused:  # the pointer stays put: the spring brings the ball to rest on it
        still = []
        for _ in range(90):
            pump(viewer, 1)
            still.append(ball_state(viewer, 0) | {"target": viewer.interaction.target.tolist()})
        out["still"] = still
        drag(range(21, 27))
    out["draws_while_held"] = [c.label for c in viewer.renderer.draws.calls]
    viewer._hud_at = 0.0
    pump(viewer, 1, dt=0.0)
    out["hud_while_held"] = viewer.hud.text
    out["before_release"] = ball_state(viewer, 0)
    end = 20 if paused else 26
    mouse(viewer, "on_mouse_release", x + step_x * end, y + step_y * end, buttons.LEFT, 0)
    pump(viewer, 1, dt=0.0)  # no time passes: the ball has just been let go
    out["released"] = ball_state(viewer, 0)
    out["held_after_release"] = viewer.interaction.held_ball
    out["draws_after_release"] = [c.label for c in viewer.renderer.draws.calls]
    out["time_at_release"] = sim.world.time
    if paused:
        pump(viewer, 10)
        out["paused_still"] = ball_state(viewer, 0)
        tap(viewer, "SPACE")
    pump(viewer, 12)  # 0.2 s of flight
    out["flight"] = ball_state(viewer, 0)
    out["flight_time"] = sim.world.time - out["time_at_release"]
    return out


def drag_throw_paused(workdir: Path) -> dict:
    return drag_throw(workdir, paused=True)


def spring_into_plane(workdir: Path) -> dict:
    """Grab the ball resting on the square and pull it hard down through the square, then sideways
    along it: after every step, the ball's height and its distance to the square (face, edge or
    corner)."""
    from pyglet.window import mouse as buttons

    viewer = scene_viewer(workdir, RAMP_SCENE)
    sim = viewer.sim
    press(viewer, "X", frames=30)  # resting on the square
    ball = sim.world.spheres[0]
    x, y = window_point(viewer, np.array(ball.position))
    mouse(viewer, "on_mouse_press", x, y, buttons.LEFT, 0)
    pump(viewer, 1)
    heights, gaps, targets = [], [], []
    square = sim.world.planes[1]

    def measure() -> None:
        centre = np.array(sim.world.spheres[0].position)
        heights.append(float(centre[1]))
        gaps.append(float(square.distance(centre)))

    sim.after_step.append(measure)
    for k in range(1, 91):  # 1.5 s: down 150 px (about 2 m below the square), then 1.5 m along it
        px, py = x + max(k - 30, 0), y - 5 * min(k, 30)
        mouse(viewer, "on_mouse_drag", px, py, 1 if k > 30 else 0, 0 if k > 30 else -5, buttons.LEFT, 0)
        pump(viewer, 1)
        targets.append(viewer.interaction.target.tolist())
    mouse(viewer, "on_mouse_release", x, y, buttons.LEFT, 0)
    pump(viewer, 1)
    return {
        "heights": heights,
        "gaps": gaps,
        "targets": targets,
        "radius": ball.radius,
        "square": 1.0,
        "final": ball_state(viewer, 0),
    }


def shoot(workdir: Path) -> dict:
    viewer = scene_viewer(workdir, FLOOR_SCENE)
    sim = viewer.sim
    out: dict = {"eye": viewer.camera.position.tolist(), "forward": viewer.camera.forward.tolist(),
                 "near": viewer.camera.near, "count_before": sim.ball_count}  # fmt: skip
    press(viewer, "X", frames=1)
    tap(viewer, "B")
    out["count_after"] = sim.ball_count
    out["shot"] = ball_state(viewer, 1) | {"radius": sim.world.spheres[1].radius}
    out["hud"] = viewer.hud.text
    from pyglet.window import key

    press(viewer, "B", modifiers=key.MOD_SHIFT, frames=1)
    out["speed_after_shift_b"] = viewer.interaction.shot_speed
    out["count_after_shift_b"] = sim.ball_count
    viewer._hud_at = 0.0
    pump(viewer, 1, dt=0.0)
    out["hud_after_shift_b"] = viewer.hud.text
    pump(viewer, 30)  # the first shot is well away
    t0 = sim.world.time
    tap(viewer, "B")
    out["second"] = ball_state(viewer, 2)
    pump(viewer, 6)
    out["second_later"] = ball_state(viewer, 2)
    out["second_flight_time"] = sim.world.time - t0
    out["colors"] = len(sim.appearance.sphere_colors)
    out["draw_instances"] = [c.instances for c in viewer.renderer.draws.calls if c.label == "balls"]
    return out


def amber(image: np.ndarray) -> int:
    """How many pixels have the selected rim's amber hue (not the floor's grey, the square's green or
    the ball's red)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((r - b > 60) & (g > 0.6 * r) & (g < 0.9 * r) & (b < 0.45 * r)).sum())


def gap(sim) -> list[float]:
    """[time, signed distance of ball 0's centre from the square's plane, distance from the square]."""
    plane, centre = sim.world.planes[1], sim.world.spheres[0].position
    return [sim.world.time, plane.signed_distance(centre), plane.distance(centre)]


def plane_tilt(workdir: Path) -> dict:
    """Click the square with the real pointer, hold → for a second: it tilts, the ball rolls off."""
    viewer = scene_viewer(workdir, RAMP_SCENE, size=(960, 540))
    sim = viewer.sim
    press(viewer, "H")  # the HUD panel would cover part of the square
    press(viewer, "X", frames=30)
    out: dict = {"rest": ball_state(viewer, 0)}
    before = grab(viewer)
    point_at(viewer)
    x, y = window_point(viewer, (1.5, 1.0, 1.2))  # on the square, clear of the ball
    window = str(viewer.window._window)
    xdotool("mousemove", "--window", window, str(round(x)), str(round(viewer.window.height - y)))
    settle(viewer, 3)
    xdotool("click", "1")
    settle(viewer, 6)
    out["selected"] = viewer.interaction.selected_plane
    after = grab(viewer)
    out["changed_pixels"] = int((np.abs(after - before).max(axis=-1) > 60).sum())
    out["amber_pixels"], out["amber_before"] = amber(after), amber(before)
    plane = sim.world.planes[1]
    t0 = sim.world.time
    track = []
    from pyglet.window import key

    viewer.window.dispatch_event("on_key_press", key.RIGHT, 0)
    for _ in range(60):  # 1 s
        pump(viewer, 1)
        track.append(gap(sim))
    out["spin_while_held"] = plane.angular_velocity.tolist()
    out["forward"] = viewer.camera.forward.tolist()
    viewer.window.dispatch_event("on_key_release", key.RIGHT, 0)
    pump(viewer, 1, dt=0.0)
    out["time_stepping"] = sim.phase.name
    out["held_seconds"] = sim.world.time - t0
    out["spin_after"] = plane.angular_velocity.tolist()
    out["normal"] = plane.normal.tolist()
    states = []
    for _ in range(15):  # 0.25 s on the still slope
        pump(viewer, 1)
        states.append([sim.world.time, *sim.world.spheres[0].velocity.tolist()])
        track.append(gap(sim))
    out["rolling"] = states
    for _ in range(180):  # 3 s: off the edge and onto the floor
        pump(viewer, 1)
        track.append(gap(sim))
    out["track"] = track
    out["end"] = ball_state(viewer, 0)
    out["radius"] = sim.world.spheres[0].radius
    press(viewer, "RIGHT")  # still selected: → tilts, it does not single-step
    out["phase_after_right"] = sim.phase.name
    press(viewer, "ESCAPE")
    out["after_escape"] = {"selected": viewer.interaction.selected_plane, "closed": viewer.closed,
                           "message": viewer.hud.message}  # fmt: skip
    out["spin_after_escape"] = plane.angular_velocity.tolist()
    # select again (at the square's centre), then a real click on the sky deselects
    cx, cy = window_point(viewer, plane.position)
    xdotool("mousemove", "--window", window, str(round(cx)), str(round(viewer.window.height - cy)))
    settle(viewer, 3)
    xdotool("click", "1")
    settle(viewer, 4)
    out["reselected"] = viewer.interaction.selected_plane
    xdotool("mousemove", "--window", window, "480", "5")
    settle(viewer, 3)
    xdotool("click", "1")
    settle(viewer, 4)
    out["after_sky_click"] = viewer.interaction.selected_plane
    return out


def plane_lift(workdir: Path) -> dict:
    """PgUp raises the selected square with the ball riding on it; PgDn lowers it again."""
    from pyglet.window import mouse as buttons

    viewer = scene_viewer(workdir, RAMP_SCENE)
    sim = viewer.sim
    press(viewer, "X", frames=30)
    x, y = window_point(viewer, (1.5, 1.0, 1.2))
    mouse(viewer, "on_mouse_press", x, y, buttons.LEFT, 0)
    mouse(viewer, "on_mouse_release", x, y, buttons.LEFT, 0)
    pump(viewer, 1)
    out: dict = {"selected": viewer.interaction.selected_plane}
    plane, ball = sim.world.planes[1], sim.world.spheres[0]
    gaps, heights = [], []
    from pyglet.window import key

    t0 = sim.world.time
    viewer.window.dispatch_event("on_key_press", key.PAGEUP, 0)
    for _ in range(30):
        pump(viewer, 1)
        gaps.append(float(ball.position[1] - plane.position[1]))
    out["velocity_while_held"] = plane.velocity.tolist()
    out["ball_velocity_while_held"] = ball.velocity.tolist()
    viewer.window.dispatch_event("on_key_release", key.PAGEUP, 0)
    pump(viewer, 1, dt=0.0)
    out["up_seconds"] = sim.world.time - t0
    heights.append(plane.position.tolist())
    out["velocity_after"] = plane.velocity.tolist()
    pump(viewer, 30)
    hold(viewer, ["PAGEDOWN"], 30)
    heights.append(plane.position.tolist())
    pump(viewer, 60)
    out |= {"gaps": gaps, "heights": heights, "end_gap": float(ball.position[1] - plane.position[1]),
            "radius": ball.radius}  # fmt: skip
    return out


def home(workdir: Path) -> dict:
    from pyglet.window import mouse as buttons

    viewer = scene_viewer(workdir, FLOOR_SCENE)
    cam = viewer.camera
    start = {"position": cam.position.tolist(), "yaw": cam.yaw, "pitch": cam.pitch}
    hold(viewer, ["W", "D"], 30)
    mouse(viewer, "on_mouse_drag", 100, 100, 60, 30, buttons.RIGHT, 0)
    pump(viewer, 1)
    moved = {"position": cam.position.tolist(), "yaw": cam.yaw, "pitch": cam.pitch}
    press(viewer, "HOME")
    back = {
        "position": viewer.camera.position.tolist(),
        "yaw": viewer.camera.yaw,
        "pitch": viewer.camera.pitch,
    }
    return {"start": start, "moved": moved, "back": back}


def save(workdir: Path) -> dict:
    """Tilt the square, shoot a ball, Ctrl+S twice; report the world as it was at each save."""
    from pyglet.window import key
    from pyglet.window import mouse as buttons

    viewer = scene_viewer(workdir, RAMP_SCENE)
    sim = viewer.sim
    press(viewer, "X", frames=10)
    x, y = window_point(viewer, (1.5, 1.0, 1.2))
    mouse(viewer, "on_mouse_press", x, y, buttons.LEFT, 0)
    mouse(viewer, "on_mouse_release", x, y, buttons.LEFT, 0)
    hold(viewer, ["UP"], 20)
    hold(viewer, ["PAGEUP"], 10)
    press(viewer, "B", frames=5)
    press(viewer, "SPACE")
    camera_before = viewer.camera.position.tolist()
    press(viewer, "S", modifiers=key.MOD_CTRL, frames=1)
    out: dict = {"first": str(viewer.last_save), "message": viewer.hud.message,
                 "camera_moved_by_ctrl_s": viewer.camera.position.tolist() != camera_before}  # fmt: skip
    w = sim.world
    out["world"] = {
        "positions": w.spheres.positions.tolist(), "velocities": w.spheres.velocities.tolist(),
        "angular_velocities": w.spheres.angular_velocities.tolist(),
        "orientations": w.spheres.orientations.tolist(), "radii": w.spheres.radii.tolist(),
        "plane_centers": w.planes.centers.tolist(), "plane_orientations": w.planes.orientations.tolist(),
    }  # fmt: skip
    press(viewer, "S", modifiers=key.MOD_CTRL, frames=1)
    out["second"] = str(viewer.last_save)
    return out


def record_close_button(workdir: Path) -> dict:
    """--record: drop, reset, drop again, then the window's close button (pyglet's on_close)."""
    path = workdir / "live.toml"
    path.write_text(RAMP_SCENE)
    viewer = Viewer(size=(320, 180), scene_path=path, record=workdir / "run.npz", panel=False)
    viewer.sim.step_budget = math.inf
    press(viewer, "X", frames=20)
    press(viewer, "R", frames=2)
    press(viewer, "X", frames=25)
    out = {
        "steps_since_reset": viewer.sim.steps_total,
        "written_before_close": (workdir / "run.npz").exists(),
    }
    viewer.window.dispatch_event("on_close")
    viewer.pump()
    out["closed"] = viewer.closed
    return out


SCENARIOS = {
    f.__name__: f
    for f in (
        drag_throw,
        drag_throw_paused,
        spring_into_plane,
        shoot,
        plane_tilt,
        plane_lift,
        home,
        save,
        record_close_button,
    )
}


if __name__ == "__main__":
    window_main(SCENARIOS)
