"""Values written into the world by hand are checked before a step uses them (issue #25, section 3):
gravity, plane views, huge Python integers and view indices."""

import math
import re

import numpy as np
import pytest

import ballpit
from ballpit.physics.core import validation


def test_gravity_reads_as_a_read_only_array_so_nan_cannot_be_written_into_it():
    world = ballpit.World()
    with pytest.raises(ValueError, match="read-only"):
        world.gravity[1] = math.nan
    assert world.gravity.tolist() == [0.0, -9.81, 0.0]
    world.gravity = (0.0, -1.62, 0.0)  # assigning a whole vector still works
    assert world.gravity.tolist() == [0.0, -1.62, 0.0]


@pytest.mark.parametrize("g", [(0, -1e300, 0), (2e9, 0, 0)])
def test_gravity_beyond_a_billion_metres_per_second_squared_is_refused(g):
    with pytest.raises(ValueError, match=r"gravity must have components of at most 1e\+09"):
        ballpit.World(gravity=g)
    world = ballpit.World()
    with pytest.raises(ValueError, match="gravity"):
        world.gravity = g
    assert world.gravity.tolist() == [0.0, -9.81, 0.0]
    assert validation.MAX_GRAVITY == 1e9  # as every other bound, and scene files' largest number


@pytest.mark.parametrize("index", [1.5, "0", None])
def test_views_take_only_integer_indices(index):
    world = ballpit.World()
    world.add_spheres([[0, 1, 0], [2, 1, 0]])
    world.add_plane()
    with pytest.raises(TypeError, match="indices must be integers"):
        world.spheres[index]
    with pytest.raises(TypeError, match="indices must be integers"):
        world.planes[index]
    assert world.spheres[np.int64(1)].index == 1 and world.spheres[-1].index == 1


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda w: w.add_sphere(radius=10**400), "radius"),
        (lambda w: w.add_sphere(mass=-(10**400)), "mass"),
        (lambda w: w.add_sphere(position=(10**400, 0, 0)), "position"),
        (lambda w: w.add_spheres([[0, 0, 0]], radius=10**400), "radius"),
        (lambda w: w.add_plane(size=10**400), "size"),
        (lambda w: setattr(w, "linear_drag", 10**5000), "linear_drag"),
    ],
)
def test_integers_too_large_for_a_float_raise_the_documented_value_error(call, name):
    world = ballpit.World()
    with pytest.raises(ValueError, match=f"{name} must be finite.*too large for a float"):
        call(world)
    assert len(world.spheres) == 0 and len(world.planes) == 0


def _world_with_planes() -> ballpit.World:
    world = ballpit.World()
    world.add_plane()
    world.add_plane(position=(0, 0, -2), rotation=(90, 0, 0), size=(4, 2), velocity=(0, 0.1, 0))
    world.add_sphere(position=(0, 1, 0), radius=0.5)
    world.step(0.01)
    return world


BAD_PLANE_WRITES = [
    ("centers", (1, 1), math.nan, "center"),
    ("centers", (0, 0), 2e9, "center"),
    ("normals", (1, 2), math.nan, "normal"),
    ("normals", (0, 1), 0.5, "normal"),  # no longer a unit vector
    ("velocities", (0, 0), math.nan, "velocity"),
    ("angular_velocities", (1, 1), math.inf, "angular_velocity"),
    ("half_sizes", (1, 0), math.nan, "half_size"),
    ("half_sizes", (0, 1), -1.0, "half_size"),
    ("orientations", (1, 3), math.nan, "orientation"),
    ("restitutions", (0,), math.nan, "restitution"),
]


@pytest.mark.parametrize(("column", "where", "value", "name"), BAD_PLANE_WRITES)
def test_a_bad_value_written_into_a_plane_view_is_refused_by_name_and_put_back(column, where, value, name):
    world = _world_with_planes()
    good = np.array(getattr(world.planes, column))
    body = world.state.body.copy()
    time = world.time
    getattr(world.planes, column)[where] = value
    plane = where[0]
    with pytest.raises(ValueError, match=rf"^plane #{plane} has a bad {name} .*the world was not stepped"):
        world.step(0.01)
    assert world.time == time
    np.testing.assert_array_equal(world.state.body, body)
    np.testing.assert_array_equal(getattr(world.planes, column), good)  # the last good value is back
    world.step(0.01)  # and the world steps on from it
    assert np.isfinite(world.state.body).all()
    assert np.isfinite(world.planes.centers).all() and np.isfinite(world.planes.normals).all()


def test_a_bad_value_written_through_a_single_plane_view_is_refused_too():
    world = _world_with_planes()
    world.planes[1].normal[:] = (math.nan, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"^plane #1 has a bad normal \[nan, 0.0, 0.0\]"):
        world.step(0.01)
    assert np.isfinite(world.planes.normals).all()


def test_a_bad_plane_value_written_after_a_restore_is_put_back_to_the_restored_value():
    world = _world_with_planes()
    snap = world.snapshot()
    world.step(0.01)
    world.restore(snap)
    centre = world.planes[1].position.copy()
    world.planes.centers[1, 0] = math.inf
    with pytest.raises(ValueError, match="plane #1 has a bad center"):
        world.step(0.01)
    np.testing.assert_array_equal(world.planes[1].position, centre)


def _world_with_balls() -> ballpit.World:
    world = ballpit.World()
    world.add_plane()
    world.add_spheres([[0, 1, 0], [2, 3, 0]], radius=0.5, angular_velocity=(0, 1, 0))
    world.step(0.01)
    return world


def test_a_zero_quaternion_written_into_a_ball_view_is_refused_by_name_and_put_back():
    world = _world_with_balls()
    ball = world.spheres[1]
    good = np.array(world.state.body)
    ball.orientation[:] = 0.0
    refusal = (
        r"^sphere #1 has a zero orientation quaternion \[0.0, 0.0, 0.0, 0.0\], which cannot be normalised; "
        r"the world was not stepped and keeps its last good state$"
    )
    with pytest.raises(ValueError, match=refusal):
        world.step(0.01)
    np.testing.assert_array_equal(world.state.body, good)
    world.step(0.01)  # and it steps on from there, every time
    world.step(0.01)
    assert abs(np.linalg.norm(ball.orientation) - 1.0) < 1e-12


@pytest.mark.parametrize(
    ("write", "message"),
    [
        (lambda w: w.spheres[0].position.__setitem__(slice(None), math.nan), "non-finite position"),
        (lambda w: w.spheres.velocities.__setitem__((1, 2), math.inf), "non-finite velocity"),
        (
            lambda w: w.spheres.angular_velocities.__setitem__((1, 0), 2e9),
            "beyond 1e+09 in its angular_velocity",
        ),
        (lambda w: w.spheres.orientations.__setitem__((0, 3), 1e300), "too large orientation quaternion"),
    ],
)
def test_a_bad_value_written_into_a_ball_view_is_put_back_as_the_last_step_left_it(write, message):
    world = _world_with_balls()
    good = np.array(world.state.body)
    world.spheres[0].velocity[0] = 0.25  # a good value written beside the bad one stays
    good[0, 3] = 0.25
    write(world)
    with pytest.raises(
        ValueError, match=re.escape(message) + ".*the world was not stepped and keeps its last good state"
    ):
        world.step(0.01)
    np.testing.assert_array_equal(world.state.body, good)
    world.step(0.01)
    assert np.isfinite(world.state.body).all()


def test_a_bad_value_written_through_a_view_kept_from_before_the_last_step_is_refused():
    world = _world_with_balls()
    kept = world.spheres.positions
    world.step(0.01)
    kept[0, 1] = math.nan  # no copy was taken since that step: refused by name, not put back
    with pytest.raises(
        ValueError, match=r"^sphere #0 has a non-finite position \(nan\); the world was not stepped$"
    ):
        world.step(0.01)


def test_a_ball_view_kept_from_before_a_restore_says_the_ball_is_no_longer_there():
    world = _world_with_balls()
    snap = world.snapshot()
    later = world.add_sphere(position=(5, 1, 0))
    plane = world.add_plane(position=(0, 10, 0))
    world.restore(snap)
    for read in (lambda: later.position, lambda: later.radius, lambda: setattr(later, "velocity", (1, 0, 0))):
        gone = r"^sphere #2 is no longer in the world, which holds 2 balls: it was removed, or the world"
        with pytest.raises(
            IndexError, match=gone + r" restored to a snapshot taken before this ball was added$"
        ):
            read()
    with pytest.raises(IndexError, match=r"^plane #1 is no longer in the world, which holds 1 plane: "):
        _ = plane.normal
    assert world.spheres[1].position[1] > 2.0  # views of balls that were there still work


def test_a_bad_value_is_not_put_back_from_another_balls_copy_after_a_ball_is_removed():
    world = _world_with_balls()
    world.add_sphere(position=(4, 1, 0))
    assert world.spheres.positions[2, 0] == 4.0  # copied now, as the views hand the positions out
    world.remove_sphere(0)  # the rows after it move down: the copy no longer lines up
    world.spheres[1].position[:] = math.nan
    with pytest.raises(ValueError, match=r"^sphere #1 has a non-finite position"):
        world.step(0.01)
    assert world.spheres[0].position[0] == 2.0  # nothing of the removed ball's written anywhere
    assert world.spheres[1].position.tolist() == [4.0, 1.0, 0.0]  # put back from a copy taken since
