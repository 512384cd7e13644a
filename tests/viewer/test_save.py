"""Ctrl+S's writer without a window: the saved file keeps the original's comments, never overwrites,
and loads back (``ballpit check`` too) into the same World as the one saved."""

from __future__ import annotations

import codecs
import re
import subprocess
import sys
from datetime import UTC, datetime

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import ballpit
from ballpit.scene import read_scene
from ballpit.viewer.camera import Camera
from ballpit.viewer.save import ROUND_OFF, SAVED_MARK, euler_xyz_degrees, save_scene, saved_path, scene_text
from ballpit.viewer.simulation import Simulation

from .conftest import subprocess_env

SCENE = """# A test scene: a ramp, a ball and a grid.
[world]
integrator = "rk4"   # the live choice may differ
timestep = 0.004166667

[camera]
position = [0, 3, 10]
look_at = [0, 1, 0]

[[plane]]                   # the ground
normal = [0, 1, 0]

[[plane]]                   # the ramp that gets tilted
position = [0, 1, 0]
rotation = [0, 0, 10]
size = [4, 3]
restitution = 0.3

[[sphere]]                  # the lone ball
position = [0.2, 1.6, 0]
radius = 0.25
color = "#e0482f"

[[grid]]                    # a small block
corner = [-1, 3, 0]
count = [2, 1, 2]
radius = 0.2
"""


def _states(world) -> dict[str, np.ndarray]:
    s, p = world.spheres, world.planes
    return {
        "positions": np.array(s.positions), "velocities": np.array(s.velocities),
        "angular_velocities": np.array(s.angular_velocities), "orientations": np.array(s.orientations),
        "radii": np.array(s.radii), "masses": np.array(s.masses),
        "ball_materials": np.array([[b.restitution, b.friction, b.rolling_friction, b.hollow] for b in s]),
        "plane_centers": np.array(p.centers), "plane_orientations": np.array(p.orientations),
        "plane_normals": np.array(p.normals), "half_sizes": np.array(p.half_sizes),
        "plane_materials": np.array([[q.restitution, q.friction, q.rolling_friction] for q in p]),
        "plane_motion": np.hstack([p.velocities, p.angular_velocities]),
    }  # fmt: skip


def assert_same_or_round_off(saved: np.ndarray, live: np.ndarray, key: str) -> None:
    """The same doubles, except live round-off (under 1e-12 of a scene at most 1 km across), saved as 0."""
    differ = saved != live
    assert (saved[differ] == 0.0).all(), key
    assert (np.abs(live[differ]) < 1e-9).all(), key


def assert_same_world(saved, live) -> None:
    a, b = _states(saved), _states(live)
    for key in ("positions", "velocities", "angular_velocities", "radii", "masses", "ball_materials",
                "plane_materials", "plane_motion", "half_sizes"):  # fmt: skip
        assert_same_or_round_off(a[key], b[key], key)
    assert np.allclose(a["orientations"], b["orientations"], rtol=0, atol=1e-15)  # renormalised on load
    for key in ("plane_centers", "plane_orientations", "plane_normals"):  # through Euler angles
        assert np.allclose(a[key], b[key], rtol=0, atol=1e-12), key
    assert saved.integrator == live.integrator
    assert np.array_equal(saved.gravity, live.gravity)


@pytest.mark.parametrize("angles", [(0, 0, 0), (10, -20, 30), (90, 45, 0), (-170, 89.9, 120), (0, 90, 0)])
def test_euler_angles_read_back_to_the_same_rotation(angles):
    q = Rotation.from_euler("xyz", angles, degrees=True).as_quat()
    back = Rotation.from_euler("xyz", euler_xyz_degrees(q), degrees=True)
    assert np.allclose(back.as_matrix(), Rotation.from_quat(q).as_matrix(), atol=1e-12)


def test_saved_names_count_up_beside_the_original_and_never_overwrite(tmp_path):
    original = tmp_path / "ramp.toml"
    assert saved_path(original) == tmp_path / "ramp-saved-1.toml"
    (tmp_path / "ramp-saved-1.toml").write_text("")
    assert saved_path(original) == tmp_path / "ramp-saved-2.toml"
    assert saved_path(tmp_path / "ramp-saved-1.toml") == tmp_path / "ramp-saved-2.toml"


def test_a_tilted_plane_moved_balls_and_an_added_ball_save_and_load_back_the_same(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(ballpit.load_scene(path), path)
    world = sim.world
    world.integrator = "rk2"
    world.planes[1].angular_velocity = (0.0, 0.0, 0.3)
    world.planes[1].velocity = (0.0, 0.2, 0.0)
    for _ in range(100):
        world.step(sim.timestep)
    world.planes[1].angular_velocity = (0.0, 0.0, 0.0)
    world.planes[1].velocity = (0.0, 0.0, 0.0)
    sim.add_ball((0.1, 0.2, 0.3), position=(2.0, 4.0, 1.0), radius=0.3, mass=2.0, velocity=(1.0, 2.0, 3.0))
    camera = Camera.looking_at((1.0, 2.0, 8.0), (0.0, 1.0, 0.0))

    saved = save_scene(sim, camera)
    assert saved == tmp_path / "ramp-saved-1.toml"
    assert save_scene(sim, camera) == tmp_path / "ramp-saved-2.toml"  # never overwrites
    assert path.read_text() == SCENE  # the original is untouched
    text = saved.read_text()
    for comment in ("# A test scene", "# the ground", "# the ramp that gets tilted", "# the lone ball",
                    "# the live choice may differ"):  # fmt: skip
        assert comment in text, comment
    assert "[[grid]]" not in text  # its balls moved: they are spheres now
    reloaded = read_scene(saved)
    loaded, look_of = reloaded.world, reloaded.appearance
    assert len(loaded.spheres) == 1 + 4 + 1
    assert_same_world(loaded, world)
    assert np.allclose(look_of.camera_position, camera.position)
    look = look_of.camera_look_at - look_of.camera_position
    assert np.allclose(look / np.linalg.norm(look), camera.forward)
    assert np.allclose(look_of.sphere_colors[-1], (0.1, 0.2, 0.3))

    check = subprocess.run(
        [sys.executable, "-m", "ballpit", "check", str(saved)], env=subprocess_env(None),
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert check.returncode == 0, check.stderr
    assert "ok: 6 balls, 2 planes, rk2" in check.stdout


def test_saving_before_the_drop_keeps_the_untouched_tables_and_adds_the_new_ball(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(ballpit.load_scene(path), path)
    sim.add_ball((1.0, 0.0, 0.0), position=(2.0, 4.0, 1.0), radius=0.3, velocity=(0.0, 0.0, -10.0))
    saved = save_scene(sim, Camera.looking_at((0, 3, 10), (0, 1, 0)))
    text = saved.read_text()
    assert text.count("[[sphere]]") == 1 + 4 + 1  # the grid's balls load after all spheres: written out
    body = text.partition("\n\n")[2]  # below the mark saying where it was saved from
    assert body.startswith(SCENE.split("[camera]")[0])  # the untouched top, comments and all
    assert_same_world(ballpit.load_scene(saved), sim.world)


def test_a_world_built_in_code_saves_everything(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    world = ballpit.World(gravity=(0, -3.0, 0), integrator="euler", linear_drag=0.1)
    world.add_plane(position=(0, 0, 0))
    world.add_plane(position=(1, 2, 0), rotation=(0, 20, 30), size=(2.0, 3.0), friction=0.2)
    world.add_sphere(position=(0, 5, 0), radius=0.4, hollow=True, angular_velocity=(1, 2, 3))
    sim = Simulation(world)
    saved = save_scene(sim, Camera())
    assert saved == tmp_path / "untitled-saved-1.toml"
    loaded = ballpit.load_scene(saved)
    assert_same_world(loaded, world)
    assert loaded.linear_drag == 0.1


def test_an_untouched_scene_saves_its_grid_as_a_grid(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(ballpit.load_scene(path), path)
    saved = save_scene(sim, Camera.looking_at((0, 3, 10), (0, 1, 0)))
    text = saved.read_text()
    assert "[[grid]]" in text and text.count("[[sphere]]") == 1
    assert_same_world(ballpit.load_scene(saved), sim.world)


def test_a_state_whose_balls_press_into_each_other_and_the_floor_saves_and_loads(tmp_path):
    """Balls at rest overlap a little (about 4e-5 m between pile.toml's 10 cm balls after 3 s), more
    than a scene's start allows by default (1e-6 m): the saved file allows what it holds, and loads."""
    path = tmp_path / "pair.toml"
    path.write_text("[[plane]]\nnormal = [0, 1, 0]\n\n[[sphere]]\nposition = [0, 0.1, 0]\nradius = 0.1\n"
                    "\n[[sphere]]\nposition = [1, 0.1, 0]\nradius = 0.1\n")  # fmt: skip
    sim = Simulation(read_scene(path), path)
    world = sim.world
    world.spheres[0].position = (0.0, 0.1 - 1e-5, 0.0)  # 1e-5 m into the floor
    world.spheres[1].position = (0.2 - 4e-5, 0.1, 0.0)  # 4e-5 m into ball 0
    saved = save_scene(sim, Camera.looking_at((0.0, 1.0, 3.0), (0.0, 0.0, 0.0)))
    loaded = read_scene(saved).world
    assert np.array_equal(loaded.spheres.positions, world.spheres.positions)
    assert "overlap_tolerance = 8e-05" in saved.read_text()  # twice the deepest, 4e-5 m
    with pytest.raises(ballpit.scene.SceneError, match=r"overlaps|cuts into"):
        read_scene(path.parent / _without_tolerance(saved))


def _without_tolerance(saved):
    """The saved file without its overlap_tolerance line: a hand-written start with these overlaps."""
    strict = saved.with_name("strict.toml")
    strict.write_text(
        "".join(ln for ln in saved.read_text().splitlines(True) if "overlap_tolerance" not in ln)
    )
    return strict.name


def test_an_untouched_scene_is_saved_without_an_overlap_tolerance(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(read_scene(path), path)
    saved = save_scene(sim, Camera.looking_at((1.0, 2.0, 8.0), (0.0, 1.0, 0.0)))
    assert "overlap_tolerance" not in saved.read_text()


def _numbers(text: str) -> np.ndarray:
    """Every number written in the TOML text's values (not in its comments)."""
    values = []
    for line in text.splitlines():
        value = line.split("#", 1)[0].partition("=")[2]
        values += [float(v) for v in re.findall(r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?", value)]
    return np.array(values)


def test_round_off_is_saved_as_zero_and_everything_else_exactly(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(ballpit.load_scene(path), path)
    world = sim.world
    world.planes[1].angular_velocity = (0.0, 0.0, 0.3)  # tilting it leaves round-off in its pose
    for _ in range(300):
        world.step(sim.timestep)
    world.planes[1].angular_velocity = (0.0, 0.0, 0.0)
    world.spheres[0].velocity = (2e-323, -3.55e-15, 1.5)  # as a run leaves them: a denormal, a cancellation
    world.spheres[0].angular_velocity = (0.0, -1e-30, 4.0)
    text = scene_text(sim, Camera.looking_at((0, 3, 10), (0, 1, 0)))
    numbers = _numbers(text)
    tiny = numbers[(numbers != 0.0) & (np.abs(numbers) < 1e-9)]
    assert tiny.size == 0, tiny  # no 2e-323, no -3.55e-15: every scale here is at least 1
    assert not re.search(r"-0\.0\b(?!\d)", text)  # no negative zeros either
    saved = tmp_path / "saved.toml"
    saved.write_text(text)
    loaded = ballpit.load_scene(saved)
    assert list(loaded.spheres[0].velocity) == [0.0, 0.0, 1.5]
    assert list(loaded.spheres[0].angular_velocity) == [0.0, 0.0, 4.0]
    assert_same_world(loaded, world)
    assert ROUND_OFF == 1e-12


def test_a_saved_file_says_what_it_was_saved_from_and_when_above_the_originals_comments(tmp_path):
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE)
    sim = Simulation(ballpit.load_scene(path), path)
    for _ in range(240):
        sim.world.step(sim.timestep)
    now = datetime(2026, 12, 2, 9, 30, 5, tzinfo=UTC)
    text = scene_text(sim, Camera.looking_at((0, 3, 10), (0, 1, 0)), now=now)
    first, second, third, blank = text.splitlines()[:4]
    assert first.startswith(SAVED_MARK + "ramp.toml") and "Ctrl+S" in first
    local = now.astimezone()
    assert local.strftime("%Y-%m-%d %H:%M:%S") in first and local.strftime("%Z") in first
    assert second == "# 1.000 s into its run, integrator RK4."
    assert "original's" in third and blank == ""
    assert text.index("# A test scene") > text.index(third)  # the original's comments follow, kept
    # saving the saved file again replaces the mark instead of piling marks up
    saved = tmp_path / "ramp-saved-1.toml"
    saved.write_text(text)
    again = scene_text(Simulation(ballpit.load_scene(saved), saved), Camera(), now=now)
    assert again.count(SAVED_MARK) == 1 and again.startswith(SAVED_MARK + "ramp-saved-1.toml")
    assert "# 0.000 s into its run" in again and again.count("# A test scene") == 1


def test_a_world_built_in_code_says_so_when_saved():
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    text = scene_text(Simulation(world), Camera(), now=datetime(2026, 12, 2, 9, 30, 5))
    assert text.startswith(SAVED_MARK + "a world built in code") and "original's" not in text


def test_a_bundled_scene_is_saved_in_the_current_directory_not_inside_the_package(tmp_path, monkeypatch):
    from ballpit.scene import bundled_scenes_dir, default_scene_path

    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in bundled_scenes_dir().iterdir())
    sim = Simulation(read_scene(default_scene_path()))
    camera = Camera.looking_at(sim.appearance.camera_position, sim.appearance.camera_look_at)
    saved = save_scene(sim, camera)
    assert saved == tmp_path / "slopes-saved-1.toml"
    assert sorted(p.name for p in bundled_scenes_dir().iterdir()) == before  # nothing added there
    assert read_scene(saved).world.planes[1].restitution == 0.8  # the demo's first slope, loaded back
    # a scene file of the user's own is saved beside it, wherever the current directory is
    own = tmp_path / "mine" / "drop.toml"
    own.parent.mkdir()
    own.write_text(SCENE)
    sim = Simulation(read_scene(own), own)
    assert save_scene(sim, camera) == own.parent / "drop-saved-1.toml"


def test_a_scene_starting_with_a_byte_order_mark_saves_with_its_comments(tmp_path):
    path = tmp_path / "notepad.toml"
    path.write_bytes(codecs.BOM_UTF8 + SCENE.encode())
    sim = Simulation(read_scene(path), path)
    saved = save_scene(sim, Camera.looking_at((1.0, 2.0, 8.0), (0.0, 1.0, 0.0)))
    assert "# A test scene: a ramp, a ball and a grid." in saved.read_text()
    assert_same_world(read_scene(saved).world, sim.world)
