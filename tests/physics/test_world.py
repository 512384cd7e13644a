"""World construction, views, planes and argument checking."""

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import ballpit
from ballpit.physics.core import steppable


def test_views_read_and_write_the_world_arrays():
    world = ballpit.World()
    ball = world.add_sphere(position=(1, 2, 3), radius=0.25, mass=2.0)
    ball.velocity = (4.0, 0.0, 0.0)
    assert world.spheres.velocities[0] == pytest.approx([4.0, 0.0, 0.0])
    world.spheres.positions[0] = (7.0, 8.0, 9.0)
    assert ball.position == pytest.approx([7.0, 8.0, 9.0])
    assert (ball.radius, ball.mass, ball.index) == (0.25, 2.0, 0)
    assert ball.orientation == pytest.approx([0, 0, 0, 1])


@pytest.mark.parametrize(("hollow", "factor"), [(False, 2 / 5), (True, 2 / 3)])
def test_sphere_inertia_is_the_textbook_value(hollow, factor):
    world = ballpit.World()
    ball = world.add_sphere(radius=0.3, mass=2.0, hollow=hollow)
    assert ball.inertia == pytest.approx(factor * 2.0 * 0.3**2)


def test_adding_ten_thousand_balls_one_by_one_grows_storage_geometrically():
    world = ballpit.World()
    capacities = set()
    for i in range(10_000):
        world.add_sphere(position=(i, 0, 0), radius=0.1)
        capacities.add(world.state.capacity)
    assert len(world.spheres) == 10_000
    assert len(capacities) <= math.ceil(math.log2(10_000 / 16)) + 1  # doubling: a copy per power of two
    assert world.spheres[-1].position == pytest.approx([9999, 0, 0])


def test_batch_add_broadcasts_arguments():
    world = ballpit.World()
    idx = world.add_spheres(np.zeros((5, 3)) + [[0, 1, 0]], radius=[0.1, 0.2, 0.3, 0.4, 0.5], mass=2.0)
    assert list(idx) == [0, 1, 2, 3, 4]
    assert world.spheres.radii == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])
    assert world.spheres[3].inertia == pytest.approx(0.4 * 2.0 * 0.16)


@pytest.mark.parametrize("angles", [(0, 0, 30), (25, -40, 70), (180, 0, 0), (10, 200, -35)])
def test_plane_rotation_is_extrinsic_xyz_degrees(angles):
    world = ballpit.World()
    plane = world.add_plane(rotation=angles, size=2.0)
    expected = Rotation.from_euler("xyz", angles, degrees=True)
    assert plane.normal == pytest.approx(expected.apply([0, 1, 0]), abs=1e-12)
    assert plane.axes[0] == pytest.approx(expected.apply([1, 0, 0]), abs=1e-12)
    q = plane.orientation
    assert min(np.abs(q - expected.as_quat()).max(), np.abs(q + expected.as_quat()).max()) < 1e-12


def test_plane_from_normal_takes_the_shortest_turn_and_flips_about_x_for_down():
    world = ballpit.World()
    tilted = world.add_plane(normal=(1, 1, 0), size=(2.0, 3.0))
    assert tilted.normal == pytest.approx(np.array([1, 1, 0]) / math.sqrt(2))
    assert tilted.axes[0] == pytest.approx(np.array([1, -1, 0]) / math.sqrt(2))  # +x turned 45° about −z
    assert tilted.axes[1] == pytest.approx([0, 0, 1])
    assert tilted.size == (2.0, 3.0)
    down = world.add_plane(normal=(0, -1, 0))
    assert down.normal == pytest.approx([0, -1, 0])
    assert down.axes[0] == pytest.approx([1, 0, 0])
    assert down.axes[1] == pytest.approx([0, 0, -1])
    assert down.size is None and down.infinite
    assert world.add_plane().normal == pytest.approx([0, 1, 0])


def test_plane_queries_cover_face_edge_and_corner():
    world = ballpit.World()
    square = world.add_plane(position=(0, 1, 0), size=2.0)
    assert square.signed_distance([0.5, 3.0, 0.5]) == pytest.approx(2.0)
    assert square.signed_distance([0.5, -1.0, 0.5]) == pytest.approx(-2.0)
    assert square.closest_point([0.5, 3.0, -0.5]) == pytest.approx([0.5, 1.0, -0.5])  # face
    assert square.closest_point([3.0, 2.0, 0.2]) == pytest.approx([1.0, 1.0, 0.2])  # edge
    assert square.closest_point([3.0, 2.0, -4.0]) == pytest.approx([1.0, 1.0, -1.0])  # corner
    assert square.distance([4.0, 5.0, 1.0]) == pytest.approx(5.0)  # from the corner (1, 1, 1)
    many = square.closest_point(np.array([[0, 5, 0], [9, 1, 9]]))
    assert many == pytest.approx(np.array([[0, 1, 0], [1, 1, 1]]))


BAD_SPHERES = [
    ({"radius": -1.0}, "radius", ValueError),
    ({"radius": 0.0}, "radius", ValueError),
    ({"mass": 0.0}, "mass", ValueError),
    ({"mass": float("inf")}, "mass", ValueError),
    ({"position": (0, float("nan"), 0)}, "position", ValueError),
    ({"position": (0, 1)}, "position", ValueError),
    ({"velocity": (1, 2, 3, 4)}, "velocity", ValueError),
    ({"velocity": "fast"}, "velocity", TypeError),
    ({"angular_velocity": (0, float("inf"), 0)}, "angular_velocity", ValueError),
    ({"orientation": (0, 0, 0, 0)}, "orientation", ValueError),
    ({"restitution": -0.5}, "restitution", ValueError),
    ({"friction": "lots"}, "friction", TypeError),
    ({"hollow": "yes"}, "hollow", TypeError),
]


@pytest.mark.parametrize(("kwargs", "name", "error"), BAD_SPHERES)
def test_add_sphere_rejects_bad_input_naming_argument_and_value(kwargs, name, error):
    world = ballpit.World()
    with pytest.raises(error) as info:
        world.add_sphere(**kwargs)
    message = str(info.value)
    assert name in message
    assert repr(next(iter(kwargs.values()))) in message
    assert len(world.spheres) == 0


BAD_PLANES = [
    ({"normal": (0, 0, 0)}, "normal"),
    ({"normal": (0, 1, 0), "rotation": (0, 0, 10)}, "normal"),
    ({"rotation": (0, 0)}, "rotation"),
    ({"size": -2.0}, "size"),
    ({"size": (1.0, 0.0)}, "size"),
    ({"size": (1.0, 2.0, 3.0)}, "size"),
    ({"position": (0, float("nan"), 0)}, "position"),
]


@pytest.mark.parametrize(("kwargs", "name"), BAD_PLANES)
def test_add_plane_rejects_bad_input_naming_argument(kwargs, name):
    world = ballpit.World()
    with pytest.raises((ValueError, TypeError), match=name):
        world.add_plane(**kwargs)
    assert len(world.planes) == 0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"integrator": "rk5"}, "integrator"),
        ({"gravity": (0, -9.81)}, "gravity"),
        ({"linear_drag": -1.0}, "linear_drag"),
        ({"angular_drag": float("nan")}, "angular_drag"),
        ({"restitution_threshold": -0.1}, "restitution_threshold"),
    ],
)
def test_world_rejects_bad_parameters(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        ballpit.World(**kwargs)


def test_setting_a_non_finite_value_is_rejected_and_the_world_keeps_no_nan():
    world = ballpit.World()
    ball = world.add_sphere(position=(0, 1, 0))
    with pytest.raises(ValueError, match="velocity"):
        ball.velocity = (float("nan"), 0, 0)
    with pytest.raises(ValueError, match="dt"):
        world.step(float("nan"))
    with pytest.raises(ValueError, match="dt"):
        world.step(-0.1)
    with pytest.raises(ValueError, match="integrator"):
        world.integrator = "verlet"
    assert np.isfinite(world.state.body).all()


def test_step_advances_time():
    world = ballpit.World()
    world.step(0.25)
    world.step(0.25)
    assert world.time == pytest.approx(0.5)


def test_the_physics_package_imports_no_window_or_gl_library():
    code = (
        "import sys, ballpit, ballpit.physics\n"
        "w = ballpit.World(); w.add_plane(); w.add_sphere(position=(0, 1, 0)); w.step(0.01)\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pyglet', 'OpenGL', 'pyrr')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_a_nan_written_straight_into_the_arrays_is_refused_by_name_before_stepping():
    world = ballpit.World()
    world.add_sphere(position=(0, 1, 0))
    world.add_sphere(position=(3, 1, 0))
    world.spheres.velocities[1, 2] = float("nan")
    with pytest.raises(ValueError, match=r"sphere #1 has a non-finite velocity"):
        world.step(0.01)
    assert world.time == 0.0


def test_substeps_are_whole_numbers_from_one_to_a_thousand():
    world = ballpit.World(substeps=1000)
    assert world.substeps == 1000
    for bad in (10**12, 1001, 0, 2.0, True):
        with pytest.raises(
            ValueError, match=rf"substeps must be a whole number from 1 to 1,000, got {bad!r}"
        ):
            ballpit.World(substeps=bad)
        with pytest.raises(ValueError, match="substeps"):
            world.substeps = bad
    assert world.substeps == 1000


def test_a_restitution_above_one_is_refused_for_balls_and_planes_alike():
    # e = 1 is elastic; more would be a ball leaving faster than it came, which the step never lets an
    # impact do (it keeps every impact from adding energy), so it is refused rather than held to 1.
    world = ballpit.World()
    ball = world.add_sphere(position=(0, 1, 0), restitution=1.0)
    plane = world.add_plane(restitution=1.0)
    for call in (
        lambda: world.add_sphere(restitution=2),
        lambda: world.add_spheres([[0, 3, 0], [0, 5, 0]], restitution=[0.5, 1.5]),
        lambda: world.add_plane(restitution=1.01),
        lambda: setattr(ball, "restitution", 2.0),
        lambda: setattr(plane, "restitution", 2.0),
    ):
        with pytest.raises(ValueError, match=r"restitution must be from 0 to 1, got"):
            call()
    assert (ball.restitution, plane.restitution, len(world.spheres), len(world.planes)) == (1.0, 1.0, 1, 1)
    world.planes.restitutions[0] = 2.0  # written straight into the column: refused by the step, put back
    with pytest.raises(ValueError, match=r"plane #0 has a bad restitution 2.0: it must be from 0 to 1"):
        world.step(0.01)
    assert plane.restitution == 1.0


def test_a_step_longer_than_a_billion_seconds_is_refused_by_name_without_a_warning():
    world = ballpit.World()
    world.add_plane()
    world.add_sphere(position=(0, 1, 0))
    body = world.state.body.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an overflow warning on the way would raise here
        with pytest.raises(ValueError, match=r"^dt must be at most 1e\+09 s, got 1e\+308$"):
            world.step(1e308)
    assert world.time == 0.0
    np.testing.assert_array_equal(world.state.body, body)


def test_planes_added_one_by_one_are_copied_once_not_once_a_plane(monkeypatch):
    # Adding a plane copied every plane's columns (40,000 planes took 18.7 s to load); now it appends
    # its own row to the copy a step puts bad values back from.
    copies = []
    real = steppable.planes_as_stepped
    monkeypatch.setattr(steppable, "planes_as_stepped", lambda *a: copies.append(1) or real(*a))
    world = ballpit.World()
    for k in range(100):
        world.add_plane(position=(0, -k, 0))
    assert len(copies) <= 1


def test_planes_added_after_a_step_are_put_back_like_the_others():
    world = ballpit.World()
    world.add_plane()
    world.add_sphere(position=(0, 1, 0))
    world.step(0.01)
    for k in range(1, 4):
        world.add_plane(position=(0, 0, -k), normal=(0, 0, 1), size=(2.0, 1.0 + k))
    good = {name: np.array(getattr(world.planes, name)) for name in ("centers", "normals", "half_sizes")}
    world.planes.centers[0, 1] = math.nan
    world.planes.normals[2] = (0.0, 0.0, 0.0)
    world.planes.half_sizes[3, 1] = -1.0
    with pytest.raises(ValueError, match=r"^plane #0 has a bad center"):
        world.step(0.01)
    for name, values in good.items():
        np.testing.assert_array_equal(getattr(world.planes, name), values)
    world.step(0.01)


def test_a_pair_touches_within_ten_micrometres_or_a_thousandth_of_the_smallest_radius():
    world = ballpit.World()
    assert world.model.contact_slop() == 1e-5  # no balls: CONTACT_SLOP
    world.add_sphere(radius=0.5)
    assert world.model.contact_slop() == 1e-5
    world.add_sphere(position=(3, 0, 0), radius=1e-4)
    assert world.model.contact_slop() == pytest.approx(1e-7)
