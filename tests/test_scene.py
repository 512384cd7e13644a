"""load_scene: what a scene file builds, its defaults, grids, and the line numbers its errors carry."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import ballpit
from ballpit.scene import (
    PALETTE,
    Appearance,
    Scene,
    SceneError,
    first_overlap,
    load_scene,
    read_scene,
    resolve_scene_path,
)


def write(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def load_error(tmp_path: Path, text: str) -> SceneError:
    with pytest.raises(SceneError) as info:
        load_scene(write(tmp_path, text))
    return info.value


def test_a_full_scene_builds_the_world_it_describes(tmp_path):
    scene = read_scene(
        write(
            tmp_path,
            """
[world]
gravity = [0, -3.5, 0]
integrator = "RK2"
timestep = 0.01
linear_drag = 0.1
angular_drag = 0.2
restitution_threshold = 0.05
duration = 3

[camera]
position = [1, 2, 3]
look_at = [0, 1, 0]

[[plane]]
normal = [0, 1, 0]

[[plane]]
position = [0, 2, 0]
rotation = [10, 20, 30]
size = [2, 3]
restitution = 0.4
friction = 0.3
rolling_friction = 0.01
color = "#102030"

[[sphere]]
position = [0, 5, 0]
radius = 0.3
mass = 2.0
velocity = [1, 0, 0]
angular_velocity = [0, 0, 4]
orientation = [0, 0, 0, 2]
restitution = 0.9
friction = 0.7
rolling_friction = 0.02
hollow = true
color = [1, 0, 0.5]
""",
        )
    )
    world = scene.world
    assert ballpit.load_scene is load_scene
    assert np.allclose(world.gravity, [0, -3.5, 0])
    assert world.integrator == "rk2"
    assert world.linear_drag == 0.1 and world.angular_drag == 0.2
    assert world.restitution_threshold == 0.05
    assert len(world.planes) == 2 and len(world.spheres) == 1

    ball = world.spheres[0]
    assert np.allclose(ball.position, [0, 5, 0]) and np.allclose(ball.velocity, [1, 0, 0])
    assert np.allclose(ball.angular_velocity, [0, 0, 4])
    assert np.allclose(ball.orientation, [0, 0, 0, 1]), "orientation is normalised"
    assert ball.radius == 0.3 and ball.mass == 2.0 and ball.hollow
    assert math.isclose(ball.inertia, 2 / 3 * 2.0 * 0.3**2)
    assert (ball.restitution, ball.friction, ball.rolling_friction) == (0.9, 0.7, 0.02)

    slope = world.planes[1]
    expected_normal = Rotation.from_euler("xyz", [10, 20, 30], degrees=True).apply([0, 1, 0])
    assert np.allclose(slope.normal, expected_normal)
    assert slope.size == (2.0, 3.0)
    assert (slope.restitution, slope.friction, slope.rolling_friction) == (0.4, 0.3, 0.01)
    assert world.planes[0].infinite

    info = scene.appearance
    assert isinstance(scene, Scene) and isinstance(info, Appearance)
    assert scene.path == info.path == tmp_path / "scene.toml" and scene.name == "scene"
    assert np.allclose(info.camera_position, [1, 2, 3]) and np.allclose(info.camera_look_at, [0, 1, 0])
    assert np.allclose(info.sphere_colors, [[1, 0, 0.5]])
    assert np.allclose(info.plane_colors[1], [0x10 / 255, 0x20 / 255, 0x30 / 255])
    assert scene.timestep == 0.01 and scene.duration == 3.0


def test_defaults_match_the_design(tmp_path):
    scene = read_scene(write(tmp_path, "[[plane]]\nposition = [0, 0, 0]\n[[sphere]]\nposition = [0, 1, 0]\n"))
    world = scene.world
    assert np.allclose(world.gravity, [0, -9.81, 0]) and world.integrator == "rk4"
    ball, plane = world.spheres[0], world.planes[0]
    assert ball.radius == 0.5 and ball.mass == 1.0 and not ball.hollow
    assert (ball.restitution, ball.friction, ball.rolling_friction) == (1.0, 0.5, 0.0)
    assert (plane.restitution, plane.friction, plane.rolling_friction) == (0.8, 0.5, 0.0)
    assert plane.infinite and np.allclose(plane.normal, [0, 1, 0])
    info = scene.appearance
    assert scene.timestep == pytest.approx(1 / 240) and scene.duration is None
    assert info.sphere_colors.shape == (1, 3) and info.plane_colors.shape == (1, 3)
    assert np.all((info.sphere_colors >= 0) & (info.sphere_colors <= 1))
    # no [camera]: one is placed in front of the scene, looking at it
    assert info.camera_position[2] > info.camera_look_at[2]


def test_scene_info_is_read_only(tmp_path):
    scene = read_scene(write(tmp_path, "[[sphere]]\nposition = [0, 1, 0]\n"))
    with pytest.raises(ValueError):
        scene.appearance.sphere_colors[0, 0] = 0.0
    with pytest.raises(AttributeError):
        scene.timestep = 1.0  # type: ignore[misc]


def test_default_ball_colours_cycle_the_palette(tmp_path):
    text = "".join(f"[[sphere]]\nposition = [{2 * k}, 1, 0]\n" for k in range(len(PALETTE) + 2))
    colors = read_scene(write(tmp_path, text)).appearance.sphere_colors
    assert np.allclose(colors[0], colors[len(PALETTE)])
    assert len({tuple(c) for c in colors[: len(PALETTE)]}) == len(PALETTE)


def test_grid_places_a_block_of_balls(tmp_path):
    scene = read_scene(
        write(
            tmp_path,
            """
[[grid]]
corner = [1, 2, 3]
count = [2, 3, 4]
spacing = [0.5, 0.6, 0.7]
radius = 0.2
mass = 0.3
velocity = [0, -1, 0]
color = "#ff0000"
""",
        )
    )
    balls = scene.world.spheres
    assert len(balls) == 24
    pos = balls.positions
    assert np.allclose(pos.min(axis=0), [1, 2, 3])
    assert np.allclose(pos.max(axis=0), [1.5, 3.2, 5.1])
    assert np.allclose(balls.radii, 0.2) and np.allclose(balls.masses, 0.3)
    assert np.allclose(balls.velocities, [0, -1, 0])
    assert np.allclose(scene.appearance.sphere_colors, [1, 0, 0])


def test_grid_center_jitter_and_seed_are_deterministic(tmp_path):
    def grid(seed: int, name: str):
        text = (
            "[[grid]]\ncenter = [0, 5, 0]\ncount = [4, 4, 4]\nspacing = 0.5\nradius = 0.2\n"
            f"jitter = 0.04\nvelocity_jitter = 1.0\nseed = {seed}\n"
        )
        return load_scene(write(tmp_path, text, name)).spheres

    a, b, c = grid(3, "a.toml"), grid(3, "b.toml"), grid(4, "c.toml")
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    assert not np.allclose(a.positions, c.positions)
    assert np.allclose(a.positions.mean(axis=0), [0, 5, 0], atol=0.04)
    regular = (np.indices((4, 4, 4)).reshape(3, -1).T - 1.5) * 0.5 + [0, 5, 0]
    assert np.abs(a.positions - regular).max() <= 0.04
    assert 0 < np.abs(a.velocities).max() <= 1.0


def test_grid_colour_list_cycles(tmp_path):
    text = '[[grid]]\ncorner = [0, 1, 0]\ncount = [3, 1, 1]\ncolor = ["#ff0000", [0, 0, 1]]\n'
    colors = read_scene(write(tmp_path, text)).appearance.sphere_colors
    assert np.allclose(colors, [[1, 0, 0], [0, 0, 1], [1, 0, 0]])


def test_touching_balls_and_a_ball_resting_on_a_plane_are_allowed(tmp_path):
    world = load_scene(
        write(
            tmp_path,
            "[[plane]]\n[[sphere]]\nposition = [0, 0.5, 0]\n[[sphere]]\nposition = [1, 0.5, 0]\n",
        )
    )
    assert len(world.spheres) == 2


def test_a_ball_cutting_into_a_plane_is_an_error(tmp_path):
    err = load_error(tmp_path, "[[plane]]\n\n[[sphere]]\nposition = [0, 0.3, 0]\n")
    assert err.line == 4 and err.entry == "sphere #1" and err.key == "position"
    assert "plane #1" in str(err)


def test_errors_carry_file_line_entry_and_key(tmp_path):
    err = load_error(
        tmp_path, "[[sphere]]\nposition = [0, 1, 0]\n\n[[sphere]]\nposition = [3, 1, 0]\nradius = -1.0\n"
    )
    assert str(err) == f"{tmp_path / 'scene.toml'}:6: sphere #2: key 'radius': must be positive, got -1.0"
    assert (err.line, err.entry, err.key) == (6, "sphere #2", "radius")
    assert isinstance(err, ValueError)


def test_line_numbers_survive_multiline_values_and_lookalike_strings(tmp_path):
    text = (
        "# [[sphere]] in a comment\n"
        "[[sphere]]\n"
        'note = """\n'
        "[[sphere]]\n"
        "radius = 1\n"
        '"""\n'
        "position = [\n"
        "  0,\n"
        "  [1],\n"
        "]\n"
    )
    err = load_error(tmp_path, text)
    assert err.line == 3 and "unknown key 'note'" in str(err)
    text = "[[sphere]]\nposition = [0, 1, 0]\n\n[[sphere]]  # second\nposition = [\n 0,\n 1,\n]\n"
    err = load_error(tmp_path, text)
    assert err.line == 5 and err.entry == "sphere #2" and "must have 3 components" in str(err)


def test_overlap_is_reported_on_the_later_ball(tmp_path):
    text = "[[sphere]]\nposition = [0, 1, 0]\nradius = 0.5\n[[grid]]\ncorner = [5, 1, 0]\ncount = [2, 1, 1]\n"
    text += "[[sphere]]\nposition = [0.6, 1.2, 0]\nradius = 0.3\n"
    err = load_error(tmp_path, text)
    assert err.entry == "sphere #2" and err.line == 8 and "overlaps sphere #1" in str(err)


def test_grid_ball_overlapping_a_sphere_names_the_ball(tmp_path):
    text = (
        "[[sphere]]\nposition = [1.1, 1, 0]\nradius = 0.3\n[[grid]]\ncorner = [0, 1, 0]\ncount = [3, 1, 1]\n"
    )
    text += "spacing = 1.1\nradius = 0.3\n"
    err = load_error(tmp_path, text)
    assert err.entry == "grid #1" and "ball [1, 0, 0] overlaps sphere #1" in str(err)


def test_grid_spacing_smaller_than_diameter_plus_jitter_is_an_error(tmp_path):
    err = load_error(
        tmp_path,
        "[[grid]]\ncorner = [0, 1, 0]\ncount = [2, 2, 2]\nradius = 0.2\nspacing = 0.45\njitter = 0.1\n",
    )
    assert err.entry == "grid #1" and err.key == "spacing" and "2·radius + 2·jitter" in str(err)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_first_overlap_agrees_with_brute_force(seed):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 4, size=(400, 3))
    radii = rng.uniform(0.02, 0.12, size=400)
    d = np.linalg.norm(pos[:, None] - pos[None], axis=2)
    bad = (d < radii[:, None] + radii[None]) & ~np.eye(400, dtype=bool)
    pair = first_overlap(pos, radii)
    if bad.any():
        i, j = pair
        assert i < j and bad[i, j]
    else:
        assert pair is None
    # spread them out until nothing overlaps
    assert first_overlap(pos * 100, radii) is None


def test_first_overlap_handles_many_balls_in_one_place():
    pos = np.zeros((3000, 3))
    assert first_overlap(pos, np.full(3000, 0.1)) == (0, 1)


def test_resolve_scene_path_finds_bundled_scenes_by_name(tmp_path):
    assert resolve_scene_path("slopes").name == "slopes.toml"
    assert resolve_scene_path("slopes.toml").is_file()
    assert resolve_scene_path(tmp_path / "missing.toml") == tmp_path / "missing.toml"


def test_a_plane_moves_as_its_scene_table_says(tmp_path):
    world = load_scene(
        write(tmp_path, "[[plane]]\nsize = 2\nvelocity = [0, 1, 0]\nangular_velocity = [0, 0, 0.5]\n")
    )
    plane = world.planes[0]
    assert plane.velocity == pytest.approx((0, 1, 0)) and plane.angular_velocity == pytest.approx((0, 0, 0.5))
    world.step(0.5)
    assert plane.position == pytest.approx((0, 0.5, 0))
    assert plane.normal == pytest.approx((-np.sin(0.25), np.cos(0.25), 0))  # turned 0.25 rad about z
    error = load_error(tmp_path, "[[plane]]\nangular_velocity = [0, 'fast', 0]\n")
    assert "angular_velocity" in str(error) and "plane #1" in str(error)
