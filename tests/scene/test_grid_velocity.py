"""A [[grid]] whose velocity and velocity jitter could reach beyond what the engine steps is refused
as a scene error naming the entry and the key, not with a traceback from the physics."""

from __future__ import annotations

import pytest

from .helpers import refused

GRID = "[[grid]]\ncorner = [0, 1, 0]\ncount = [2, 2, 2]\nradius = 0.1\n"


@pytest.mark.parametrize(
    ("keys", "key", "reach"),
    [
        ("velocity = [5e8, 0, 0]\nvelocity_jitter = 9e8\n", "velocity_jitter", "1.4e+09"),
        ("velocity_jitter = 999999999.5\nvelocity = [0, 0, -1]\n", "velocity_jitter", "1e+09"),
    ],
)
def test_a_grid_velocity_jitter_reaching_beyond_1e9_is_a_scene_error(tmp_path, keys, key, reach):
    path = tmp_path / "fast.toml"
    path.write_text(GRID + keys)
    refused(path, "grid #1", f"key '{key}'", f"could reach {reach} m/s", "beyond 1e9 m/s")


def test_a_grid_velocity_jitter_within_the_limit_loads(tmp_path):
    from ballpit.scene import read_scene

    path = tmp_path / "ok.toml"
    path.write_text(GRID + "velocity = [4e8, 0, 0]\nvelocity_jitter = 5e8\n")
    world = read_scene(path).world
    assert abs(world.spheres.velocities).max() <= 9e8
