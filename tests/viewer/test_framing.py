"""Scenes with no ground are framed to fill the view right of the panel (framing.py), without a window."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.scene import default_scene_path, read_scene
from ballpit.viewer.camera import Camera
from ballpit.viewer.framing import FILL, fit, fits, scene_box
from ballpit.viewer.handover import capture
from ballpit.viewer.simulation import Simulation

SIZE = (1280, 720)


def shown_of(name: str):
    return capture(Simulation(read_scene(default_scene_path().with_name(f"{name}.toml"))))


@pytest.mark.parametrize("name", ["pile", "gas", "cradle", "cannon"])
@pytest.mark.parametrize("inset", [0.0, 330 / 1280])
def test_a_scene_with_no_ground_just_fills_the_view_along_its_files_line_of_sight(name, inset):
    shown = shown_of(name)
    box = scene_box(shown)
    assert box is not None
    look = shown.appearance
    camera = Camera.looking_at(look.camera_position, look.camera_look_at)
    camera.inset = inset
    fit(camera, look.camera_look_at, box, *SIZE)
    assert fits(camera, box, *SIZE)
    pixels, _ = camera.project(box, *SIZE)
    left = inset * SIZE[0]
    width = (pixels[:, 0].max() - pixels[:, 0].min()) / (SIZE[0] - left)
    height = (pixels[:, 1].max() - pixels[:, 1].min()) / SIZE[1]
    # as near as it can be: one side of the box reaches FILL of the view (allowing for the box not
    # being centred on the look-at point, half of it may reach the edge first)
    reach = max(
        np.abs(pixels[:, 0] - (left + SIZE[0]) / 2).max() / ((SIZE[0] - left) / 2),
        np.abs(pixels[:, 1] - SIZE[1] / 2).max() / (SIZE[1] / 2),
    )
    assert reach == pytest.approx(FILL, abs=1e-3)
    if name != "cannon":  # the cannon looks at 5 m, above its balls: room for the top one's 10 m flight
        assert max(width, height) > 0.4
    direction = camera.position - look.camera_look_at
    filed = look.camera_position - look.camera_look_at
    assert np.allclose(direction / np.linalg.norm(direction), filed / np.linalg.norm(filed))


def test_a_scene_on_a_ground_keeps_its_own_camera():
    assert scene_box(shown_of("slopes")) is None
