"""Where the viewer looks from: the scene's view (framed to fill the part of the window right of the
panel), Home, the orbit camera's start, and each frame's camera motion (flying on the held keys, or
following the orbited ball)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import controls
from .camera import Camera
from .framing import fit, scene_box
from .orbit import Orbit

if TYPE_CHECKING:
    from .app import Viewer
    from .handover import Shown
    from .simulation import Simulation


class ViewControl:
    """The camera and the orbit state of one Viewer."""

    def __init__(self, viewer: Viewer, camera: Camera) -> None:
        self.viewer = viewer
        self.camera = camera
        self.orbit = Orbit()

    def scene_view(self, shown: Shown) -> None:
        """The camera where the scene file puts it; a scene with no ground is framed so that it fills
        the view right of the panel (framing.py)."""
        v = self.viewer
        look = shown.appearance
        self.camera.look_from(look.camera_position, look.camera_look_at)
        self.camera.inset = v.panel.width / max(v.window.width, 1)
        box = scene_box(shown)
        if box is not None:
            fit(self.camera, look.camera_look_at, box, v.window.width, v.window.height)

    def home(self) -> None:
        """Home: back to the scene's view, flying free."""
        self.orbit.stop()
        self.scene_view(self.viewer.shown)

    def start_orbit(self, target: object = None, ball: int | None = None) -> None:
        """Orbit ``target`` (by default what the view's centre shows, else the scene's look-at point)."""
        if target is not None:
            self.orbit.start(self.camera, target, ball)
            return
        from .picking import pick, pointer_ray

        v = self.viewer
        w, h = v.window.width, v.window.height
        middle = v.panel.width + (w - v.panel.width) / 2  # the view's centre
        ray = pointer_ray(self.camera, middle, h / 2, w, h)

        def aim(sim: Simulation) -> object:
            hit = pick(ray, sim.world)
            return hit.point if hit is not None else sim.appearance.camera_look_at

        v.command(aim, lambda point: self.orbit.start(self.camera, point))

    def move(self, held: set[str], seconds: float) -> None:
        """One frame: follow the orbited ball, or fly on the held keys."""
        orbit, shown = self.orbit, self.viewer.shown
        if orbit.active:
            if orbit.follow is not None and orbit.follow < shown.ball_count:
                orbit.carry(self.camera, shown.positions[orbit.follow])
            return
        self.camera.fly(controls.fly_direction(held), min(seconds, 0.1), controls.fly_speed_multiplier(held))
