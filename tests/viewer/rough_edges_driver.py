"""Real windows under Xvfb for the rough edges a first trial found (test_rough_edges_window.py runs it):
a slope tilted over by the arrow keys, a click above the horizon, the HUD in a small window. Same
protocol as window_driver.py; input goes in as real pyglet events through the window."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import window_driver as wd

import ballpit


def click(viewer, x: float, y_from_top: float) -> None:
    """A left click at a window point given from the top-left corner (as images are)."""
    from pyglet.window import mouse

    y = viewer.window.height - y_from_top
    viewer.window.dispatch_event("on_mouse_press", int(x), int(y), mouse.LEFT, 0)
    viewer.window.dispatch_event("on_mouse_release", int(x), int(y), mouse.LEFT, 0)
    wd.pump(viewer, 2)


def slope_world() -> ballpit.World:
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_plane(position=(0, 1.5, 0), size=3.0, restitution=1.0)  # orange
    return world


def tilt_slope_over(workdir: Path) -> dict:
    """X, click the slope, hold ↑ for 2 s: it tips away from the camera until its back faces it."""
    from ballpit.scene import Scene, default_appearance

    world = slope_world()
    scene = Scene(world, default_appearance(world))
    scene.appearance.camera_position = np.array([0.0, 4.0, -7.0])
    scene.appearance.camera_look_at = np.array([0.0, 1.5, 0.0])
    viewer = wd.open_viewer(size=(640, 360), world=scene)
    wd.press(viewer, "H")  # no HUD over the slope
    wd.press(viewer, "X")  # a plane moves as the world steps; the first minute's prompt goes
    size = (viewer.window.width, viewer.window.height)
    (x, y), _ = viewer.camera.project(np.array([0.0, 1.5, 0.0]), *size)
    before = wd.grab(viewer)[int(y), int(x)].tolist()
    click(viewer, x, y)
    out = {"selected": viewer.interaction.selected_plane, "before": before}
    wd.hold(viewer, ["UP"], frames=120)
    click(viewer, 5, 5)  # on the sky: deselected, so the amber selection tint is not what is seen
    slope = viewer.sim.world.planes[1]
    eye = np.asarray(viewer.camera.position, float)
    out["facing_camera"] = float(np.dot(eye - slope.position, slope.normal))  # < 0: its back
    out["tilt_degrees"] = float(np.degrees(np.arccos(np.clip(slope.normal[1], -1, 1))))
    (x, y), _ = viewer.camera.project(np.asarray(slope.position), *size)
    image = wd.grab(viewer)
    out["after"] = image[int(y) - 1 : int(y) + 2, int(x) - 1 : int(x) + 2].reshape(-1, 3).tolist()
    out["color"] = viewer.sim.appearance.plane_colors[1].tolist()
    from PIL import Image

    Image.fromarray(image.astype(np.uint8)).save(workdir / "tilted.png")
    return out


def click_above_horizon(workdir: Path) -> dict:
    """The bundled demo at 1280x720: a click a few pixels above where the ground fades into the sky."""
    from ballpit.viewer.picking import pointer_ray
    from ballpit.viewer.renderer import BACKGROUND

    viewer = wd.open_viewer(size=(1280, 720))
    wd.pump(viewer, 2)
    image = wd.grab(viewer)
    column = image[:, 640]
    background = np.round(np.array(BACKGROUND) * 255)
    ground = np.flatnonzero(np.abs(column - background).max(axis=1) > 6)  # the first row not sky
    row = int(ground[0]) - 4
    ray = pointer_ray(viewer.camera, 640, viewer.window.height - row, 1280, 720)
    out = {"row": row, "ground_distance": float(-ray.origin[1] / ray.direction[1])}
    click(viewer, 640, row)
    out["selected"] = viewer.interaction.selected_plane
    click(viewer, 640, row + 200)  # well below it: the ground near by is picked as before
    out["selected_near"] = viewer.interaction.selected_plane
    return out


def hud_sizes(workdir: Path) -> dict:
    """The HUD panel in a 1280x720 and an 800x450 window, as a share of each window's height."""
    out = {}
    for size in ((1280, 720), (800, 450)):
        viewer = wd.open_viewer(size=size, world=wd.balls_world())
        wd.pump(viewer, 3)
        left, top, right, bottom = wd.hud_rectangle(viewer)
        out[f"{size[0]}x{size[1]}"] = {"height": bottom - top, "width": right - left,
                                       "window": [viewer.window.width, viewer.window.height],
                                       "font": viewer.hud.label.font_size}  # fmt: skip
        viewer.close()
        viewer.pump()
    return out


SCENARIOS = {f.__name__: f for f in (tilt_slope_over, click_above_horizon, hud_sizes)}

if __name__ == "__main__":
    wd.main(SCENARIOS)
