"""The schema's defaults are the physics' own: a default ball, plane and world from a scene file are
exactly what World() and World.add_* give."""

from __future__ import annotations

import inspect

import numpy as np

import ballpit
from ballpit.physics import DEFAULT_TIMESTEP, INTEGRATOR_NAMES
from ballpit.scene import read_scene, schema


def test_defaults_are_the_signatures_of_the_physics():
    for function, defaults in [
        (ballpit.World.__init__, schema.WORLD_DEFAULTS),
        (ballpit.World.add_sphere, schema.BALL_DEFAULTS),
        (ballpit.World.add_plane, schema.PLANE_DEFAULTS),
    ]:
        parameters = inspect.signature(function).parameters
        for key, value in defaults.items():
            assert parameters[key].default == value, (function.__name__, key)
    assert schema.TIMESTEP_DEFAULT == DEFAULT_TIMESTEP
    assert schema.INTEGRATORS == INTEGRATOR_NAMES


def test_every_physics_parameter_has_a_scene_key():
    # A new add_sphere/add_plane/World parameter must get a key (or be left out on purpose here).
    ball = set(inspect.signature(ballpit.World.add_sphere).parameters) - {"self", "position"}
    plane = set(inspect.signature(ballpit.World.add_plane).parameters) - {"self"}
    world = set(inspect.signature(ballpit.World.__init__).parameters) - {"self"}
    assert ball == set(schema.BALL_COLUMNS)
    assert plane <= set(schema.PLANE_KEYS)
    assert world <= set(schema.WORLD_KEYS)


def test_a_default_scene_builds_exactly_the_default_world(tmp_path):
    path = tmp_path / "defaults.toml"
    path.write_text(
        "[[plane]]\n[[plane]]\nposition = [0, -1, 0]\nsize = 3\n[[sphere]]\nposition = [0, 1, 0]\n"
    )
    scene = read_scene(path)
    built = scene.world

    expected = ballpit.World()
    expected.add_plane()
    expected.add_plane(position=(0, -1, 0), size=3.0)
    expected.add_sphere(position=(0, 1, 0))

    assert np.array_equal(built.gravity, expected.gravity)
    assert built.integrator == expected.integrator
    assert (built.linear_drag, built.angular_drag) == (expected.linear_drag, expected.angular_drag)
    assert built.restitution_threshold == expected.restitution_threshold
    a, b = built.spheres, expected.spheres
    for column in ("positions", "velocities", "angular_velocities", "orientations", "radii", "masses"):
        assert np.array_equal(getattr(a, column), getattr(b, column)), column
    ball, want = a[0], b[0]
    assert (ball.restitution, ball.friction, ball.rolling_friction, ball.hollow) == (
        want.restitution,
        want.friction,
        want.rolling_friction,
        want.hollow,
    )
    for column in ("centers", "normals", "orientations", "half_sizes", "restitutions"):
        assert np.array_equal(getattr(built.planes, column), getattr(expected.planes, column)), column
    assert scene.timestep == DEFAULT_TIMESTEP
