"""One appearance for a scene file and for a World built in code: the same palette, plane colours and
camera framing, carried by the Scene, not by the World."""

from __future__ import annotations

import numpy as np

import ballpit
from ballpit.scene import PALETTE, default_appearance, read_scene, scene_of
from ballpit.scene.colours import GROUND_COLOR, hex_to_rgb, plane_colors, restitution_colors
from ballpit.viewer.simulation import Simulation

TEXT = """
[[plane]]
[[plane]]
position = [0, 2, 0]
rotation = [0, 0, 20]
size = 4
restitution = 0.25
[[grid]]
corner = [-3, 5, 0]
count = [12, 1, 1]
spacing = 0.5
radius = 0.2
"""


def test_a_file_without_colours_or_camera_looks_like_the_same_world_built_in_code(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text(TEXT)
    scene = read_scene(path)
    look = scene.appearance
    code = default_appearance(scene.world)
    for name in ("camera_position", "camera_look_at", "sphere_colors", "plane_colors"):
        assert np.array_equal(getattr(look, name), getattr(code, name)), name
    assert look.name == "plain.toml" and scene.name == "plain" and code.name == "untitled"


def test_the_loaded_world_carries_no_scene_attribute(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text(TEXT)
    assert not hasattr(read_scene(path).world, "scene")
    assert not hasattr(ballpit.load_scene(path), "scene")


def test_default_colours_are_the_palette_and_the_restitution_ramp():
    world = ballpit.World()
    world.add_plane()
    world.add_plane(position=(0, 1, 0), size=2.0, restitution=0.0)
    world.add_plane(position=(0, 3, 0), size=2.0, restitution=1.0)
    world.add_spheres(np.arange(12)[:, None] * [1.0, 0, 0] + [0, 6, 0], radius=0.3)
    look = default_appearance(world)
    assert np.array_equal(look.sphere_colors[0], hex_to_rgb(PALETTE[0]))
    assert np.array_equal(look.sphere_colors[len(PALETTE)], look.sphere_colors[0])
    assert len({tuple(c) for c in look.sphere_colors[: len(PALETTE)]}) == len(PALETTE)
    assert np.array_equal(look.plane_colors[0], GROUND_COLOR)
    assert np.allclose(look.plane_colors[1], [0.29, 0.36, 0.50])  # dead: slate blue
    assert np.allclose(look.plane_colors[2], [0.93, 0.55, 0.20])  # elastic: orange
    assert np.allclose(restitution_colors([0.5]), [[0.30, 0.56, 0.42]])
    assert np.array_equal(plane_colors([0.5, 0.5], [True, False])[0], GROUND_COLOR)


def test_the_default_camera_frames_a_world_built_in_code():
    world = ballpit.World()
    world.add_spheres([[-20.0, 1.0, 0.0], [20.0, 1.0, 0.0], [0.0, 30.0, -5.0]], radius=0.5)
    look = default_appearance(world)
    view = look.camera_look_at - look.camera_position
    view /= np.linalg.norm(view)
    for p in world.spheres.positions:
        to_ball = p - look.camera_position
        cos = to_ball @ view / np.linalg.norm(to_ball)
        assert cos > np.cos(np.radians(25.0)), "every ball is inside a 50° cone around the view"


def test_the_viewer_gets_the_same_look_from_a_world_as_from_its_scene(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text(TEXT)
    scene = read_scene(path)
    from_scene = Simulation(scene)
    from_world = Simulation(scene.world)
    assert from_scene.appearance is scene.appearance and from_scene.path == path
    assert np.array_equal(from_world.appearance.sphere_colors, scene.appearance.sphere_colors)
    assert from_world.path is None and from_world.timestep == scene_of(scene.world).timestep
