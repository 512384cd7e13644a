"""Offscreen pixel tests of the real renderer (headless EGL, real shaders, real GL draw calls)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.scene.colours import restitution_colors
from ballpit.viewer.camera import Camera
from ballpit.viewer.simulation import Simulation

from .conftest import REPO

RED = (0.9, 0.1, 0.1)


def render(offscreen, world, camera, flags=None, sim=None):
    sim = sim or Simulation(world)
    return offscreen.render(sim, camera, flags)


def background_pixel() -> np.ndarray:
    from ballpit.viewer.renderer import BACKGROUND

    return np.round(np.array(BACKGROUND) * 255)


def not_background(image: np.ndarray, tolerance: float = 12) -> np.ndarray:
    return np.abs(image.astype(float) - background_pixel()).max(axis=-1) > tolerance


def sphere_mask(camera: Camera, center, radius: float, width: int = 200, height: int = 150) -> np.ndarray:
    """Which pixels' centre rays hit the sphere, computed in NumPy (the reference for the GPU)."""
    inverse = np.linalg.inv(camera.view_projection(width / height).astype(float))
    cols, rows = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    ndc = np.stack([cols / width * 2 - 1, 1 - rows / height * 2, np.ones_like(cols), np.ones_like(cols)], -1)
    far = ndc @ inverse
    direction = far[..., :3] / far[..., 3:] - camera.position
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    oc = camera.position - np.asarray(center, float)
    b = direction @ oc
    return b**2 - (oc @ oc - radius**2) >= 0


def one_ball(position, orientation=(0, 0, 0, 1), radius=0.4, color=RED, gravity=(0, 0, 0)):
    world = ballpit.World(gravity=gravity)
    world.add_sphere(position=position, radius=radius, orientation=orientation)
    sim = Simulation(world)
    sim.appearance.sphere_colors = np.array([color])
    return sim


def axis_angle(axis, degrees) -> tuple:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    half = math.radians(degrees) / 2
    return (*(axis * math.sin(half)), math.cos(half))


def test_an_empty_scene_is_all_background(offscreen):
    image = render(offscreen, ballpit.World(), Camera.looking_at((0, 2, 8), (0, 0, 0)))
    assert image.shape == (150, 200, 3)
    assert np.abs(image.astype(float) - background_pixel()).max() <= 1


def test_a_ball_appears_where_the_camera_projects_it_in_its_colour(offscreen):
    camera = Camera.looking_at((0, 0, 6), (0, 0, 0))
    center = np.array([1.0, 0.5, 0.0])
    sim = one_ball(center, radius=0.4)
    image = offscreen.render(sim, camera)
    (px, py), depth = camera.project(center, 200, 150)
    radius_px = 0.4 / (depth * math.tan(math.radians(25.0))) * 75  # roughly: r / (d·tan(fov/2)) · h/2
    mask = not_background(image)
    expected = sphere_mask(camera, center, 0.4)
    assert expected.sum() > 300
    assert (mask & expected).sum() / (mask | expected).sum() > 0.97  # the same pixels as ray casting
    rows, cols = np.nonzero(mask)
    assert cols.mean() + 0.5 == pytest.approx(px, abs=0.5)
    assert rows.mean() + 0.5 == pytest.approx(py, abs=0.5)
    ball = image[mask].astype(int)
    red = (ball[:, 0] > ball[:, 1] + 60) & (ball[:, 0] > ball[:, 2] + 60)
    assert red.mean() > 0.35  # the ball's own colour covers about half of it (the rest is white)
    assert not mask[int(py), int(px + 1.6 * radius_px)]  # just outside: background


def test_a_rotated_ball_shows_its_pattern_turned(offscreen):
    camera = Camera.looking_at((0, 0, 3), (0, 0, 0))
    images = {}
    for label, q in {
        "identity": (0, 0, 0, 1),
        "60 about y": axis_angle((0, 1, 0), 60),
        "120 about y": axis_angle((0, 1, 0), 120),
        "90 about x": axis_angle((1, 0, 0), 90),
    }.items():
        sim = one_ball((0, 0, 0), orientation=q, radius=0.6)
        images[label] = offscreen.render(sim, camera).astype(float)
    mask = not_background(images["identity"].astype(np.uint8))
    for image in images.values():  # the silhouette never changes
        assert np.mean(not_background(image.astype(np.uint8)) == mask) > 0.995
    inside = mask

    def difference(a, b):
        return np.abs(images[a] - images[b])[inside].mean()

    assert difference("identity", "60 about y") > 40  # one segment turned: colours swap
    assert difference("identity", "120 about y") < 4  # two segments: the same pattern again
    cy, cx = 75, 100
    assert images["identity"][cy, cx, 0] > images["identity"][cy, cx, 2] + 60  # a red segment faces us
    assert images["90 about x"][cy, cx].min() > 150  # the white pole cap faces us


def test_planes_are_coloured_by_bounciness_see_through_from_behind_with_bright_edges(offscreen):
    front = Camera.looking_at((0, 0, 5), (0, 0, 0))
    back = Camera.looking_at((0, 0, -5), (0, 0, 0))
    images = {}
    for e in (0.0, 1.0):
        world = ballpit.World()
        world.add_plane(position=(0.3, 0.3, 0), normal=(0, 0, 1), size=2.0, restitution=e)
        images[e] = render(offscreen, world, front).astype(int)
        images[e, "back"] = render(offscreen, world, back).astype(int)
    cy, cx = 75, 100
    dead, bouncy = images[0.0][cy, cx], images[1.0][cy, cx]
    assert dead[2] > dead[0]  # slate blue
    assert bouncy[0] > bouncy[2] + 60  # orange
    assert np.allclose(
        restitution_colors([0.0, 1.0])[:, 0] < restitution_colors([0.0, 1.0])[:, 2], [True, False]
    )
    # seen from behind it is a wall you look through: a faint tint, darker than the lit front, with
    # its bright rim still drawn
    back_pixel = images[1.0, "back"][cy, cx]
    assert 0 < np.abs(back_pixel - background_pixel()).max() < 30
    assert back_pixel.sum() < bouncy.sum()
    (back_edge_x, back_edge_y), _ = back.project(np.array([-0.7 + 0.03, 0.3, 0.0]), 200, 150)
    assert images[1.0, "back"][int(back_edge_y), int(back_edge_x)].min() > background_pixel().max() + 60
    # the plane spans x ∈ [-0.7, 1.3]: its left edge band is near-white, far outside is background
    (edge_x, edge_y), _ = front.project(np.array([-0.7 + 0.03, 0.3, 0.0]), 200, 150)
    assert images[1.0][int(edge_y), int(edge_x)].min() > 170
    assert not not_background(images[1.0][10, 5][None].astype(np.uint8))[0]


def test_the_ground_fades_into_the_background_with_distance(offscreen):
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))  # infinite
    camera = Camera.looking_at((0, 1.5, 0), (0, 1.5, -10))  # horizontal view: horizon at the middle row
    image = render(offscreen, world, camera).astype(float)
    bg = background_pixel()
    near = np.abs(image[145] - bg).max(axis=-1).mean()
    far = np.abs(image[77] - bg).max(axis=-1).mean()
    sky = np.abs(image[60] - bg).max(axis=-1).max()
    assert near > 40
    assert far < 10
    assert sky <= 1


def test_a_ball_half_through_the_ground_is_hidden_below_it(offscreen):
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    world.add_sphere(position=(0, 0, 0), radius=0.5)
    sim = Simulation(world)
    sim.appearance.sphere_colors = np.array([RED])
    camera = Camera.looking_at((0, 0.3, 4), (0, 0, 0))
    image = offscreen.render(sim, camera).astype(int)
    (ax, ay), _ = camera.project(np.array([0.0, 0.3, 0.4]), 200, 150)  # on the ball, above ground
    (bx, by), _ = camera.project(np.array([0.0, -0.3, 0.4]), 200, 150)  # on the ball, below ground
    above, below = image[int(ay), int(ax)], image[int(by), int(bx)]
    assert above[0] > above[2] + 60
    assert not below[0] > below[2] + 60


@pytest.mark.parametrize("count", [5, 5000])
def test_all_balls_are_one_instanced_draw_call(offscreen, count):
    rng = np.random.default_rng(1)
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_spheres(rng.uniform((-4, 0.2, -4), (4, 4, 4), size=(count, 3)), radius=0.1)
    image = render(offscreen, world, Camera.looking_at((0, 4, 12), (0, 2, 0)))
    draws = offscreen.renderer.draws
    balls = [c for c in draws.calls if c.label == "balls"]
    assert len(balls) == 1
    assert balls[0].function == "glDrawArraysInstanced" and balls[0].instances == count
    assert [c.label for c in draws.calls] == ["planes", "balls"]
    assert not_background(image).any()
    # many balls are uploaded nearest first; the picture is the same as in world order
    offscreen.feeder.upload(Simulation(world))  # no eye: world order
    unsorted = offscreen.draw(Camera.looking_at((0, 4, 12), (0, 2, 0)))
    # random balls overlap, and where two meet their depths can tie; a tie goes to whichever is drawn
    # last, so the odd pixel on an intersection curve may differ (with either depth rule), never more
    differs = np.abs(unsorted.astype(int) - image.astype(int)).max(axis=-1) > 2
    assert differs.sum() <= 3


def test_overlays_draw_contacts_velocity_arrows_and_trails(offscreen):
    from ballpit.viewer.frame import OverlayFlags

    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_sphere(position=(0, 0.3, 0), radius=0.3, velocity=(2, 0, 0))  # rolling on the ground
    sim = Simulation(world)
    sim.start()
    for _ in range(12):
        sim.advance(1 / 60)
    assert sim.contacts is not None and len(sim.contacts) > 0
    camera = Camera.looking_at((0, 2, 4), (0, 0, 0))
    plain = offscreen.render(sim, camera).astype(int)
    assert [c.label for c in offscreen.renderer.draws.calls] == ["planes", "balls"]
    flags = OverlayFlags(contacts=True, velocities=True, trails=True)
    shown = offscreen.render(sim, camera, flags).astype(int)
    labels = [c.label for c in offscreen.renderer.draws.calls]
    assert labels == ["planes", "balls", "trails", "overlay lines"]
    changed = np.abs(shown - plain).max(axis=-1) > 40
    assert changed.sum() > 20
    # the contact cross (yellow) sits at the contact point under the ball
    point = sim.contacts.point[-1]
    (cx, cy), _ = camera.project(point, 200, 150)
    window = shown[int(cy) - 3 : int(cy) + 4, int(cx) - 3 : int(cx) + 4].reshape(-1, 3)
    assert ((window[:, 0] > 180) & (window[:, 1] > 170) & (window[:, 2] < 120)).any()


def test_multisampled_rendering_gives_anti_aliased_ball_edges(offscreen):
    from ballpit.viewer.render import Offscreen

    with Offscreen((64, 48), samples=4) as screen:  # a second context, multisampled
        from ballpit.viewer.framebuffer import Framebuffer

        assert isinstance(screen.target, Framebuffer) and screen.target.multisample
        sim = one_ball((0, 0, 0), radius=0.6)
        image = screen.render(sim, Camera.looking_at((0, 0, 3), (0, 0, 0))).astype(float)
    edge_values = np.abs(image - background_pixel()).max(axis=-1)
    partial = (edge_values > 8) & (edge_values < 0.5 * edge_values.max())
    assert partial.sum() > 8  # anti-aliased edge pixels exist


def closed_box(half: float = 1.0) -> ballpit.World:
    """Six walls facing in (as gas.toml's cube), with no balls yet."""
    world = ballpit.World(gravity=(0, 0, 0))
    for axis in range(3):
        for sign in (-1.0, 1.0):
            position, normal = np.zeros(3), np.zeros(3)
            position[axis], normal[axis] = sign * half, -sign
            world.add_plane(position=position, normal=normal, size=2 * half, restitution=0.5)
    return world


def test_the_walls_you_look_through_into_a_closed_box_are_see_through(offscreen):
    world = closed_box()
    world.add_sphere(position=(0, 0, 0), radius=0.4)  # red, inside
    world.add_sphere(position=(0, 0, -2.0), radius=0.4)  # blue, outside behind the far wall
    sim = Simulation(world)
    sim.appearance.sphere_colors = np.array([RED, (0.1, 0.2, 0.95)])
    camera = Camera.looking_at((0.4, 0.6, 5.0), (0, 0, 0))
    image = offscreen.render(sim, camera).astype(int)
    (px, py), _ = camera.project(np.array([0.0, 0.0, 0.4]), 200, 150)
    inside = image[int(py) - 2 : int(py) + 3, int(px) - 2 : int(px) + 3].reshape(-1, 3)
    assert np.all(inside[:, 0] > inside[:, 2] + 40)  # the red ball shows through the near wall
    labels = [c.label for c in offscreen.renderer.draws.calls]
    assert labels == ["planes", "balls", "see-through planes"]  # still one draw call for all balls
    empty = offscreen.render(Simulation(closed_box()), camera).astype(int)
    assert np.abs(empty[int(py), int(px)] - image[int(py), int(px)]).max() > 40
    # the near wall is still there: tinted, and its rim is drawn
    (ex, ey), _ = camera.project(np.array([-1.0 + 0.03, 0.0, 1.0]), 200, 150)
    assert image[int(ey), int(ex)].min() > 120
    # a wall seen from the side it faces stays opaque: the blue ball behind the far wall is hidden
    blue = (image[..., 2] > image[..., 0] + 60) & (image[..., 2] > image[..., 1] + 40)
    assert blue.sum() == 0


def test_the_gas_scene_shows_its_balls_inside_the_cube(offscreen):
    gas = ballpit.load_scene(REPO / "scenes" / "gas.toml")
    sim = Simulation(gas)
    camera = Camera.looking_at(sim.appearance.camera_position, sim.appearance.camera_look_at)
    image = offscreen.render(sim, camera).astype(int)
    walls = ballpit.World(gravity=(0, 0, 0))
    for plane in gas.planes:
        walls.add_plane(position=plane.position, normal=plane.normal, size=3.0, restitution=1.0)
    bare = Simulation(walls)
    bare.appearance.plane_colors = sim.appearance.plane_colors
    empty = offscreen.render(bare, camera).astype(int)
    changed = np.abs(image - empty).max(axis=-1) > 30
    assert changed.mean() > 0.05  # hundreds of balls visible, not one opaque wall


@pytest.mark.parametrize("gap", [0.0, 1e-5, 1e-3])
def test_balls_touching_the_back_of_an_opaque_wall_never_show_through_it(offscreen, gap):
    """A wall facing the camera hides a row of balls resting against its far side, at every sample of
    a multisampled frame (the impostor's depth must never come in front of the true sphere)."""
    from ballpit.viewer.render import Offscreen

    def scene(with_balls: bool) -> Simulation:
        world = ballpit.World(gravity=(0, 0, 0))
        world.add_plane(position=(0, 1.5, 2.0), normal=(0, 0, 1), size=(5.0, 3.0), restitution=0.5)
        if with_balls:
            grid = [(x, y, 2.0 - 0.1 - gap) for x in np.linspace(-1.8, 1.8, 13) for y in (0.1, 0.5, 1.0, 1.4)]
            world.add_spheres(grid, radius=0.1)
        sim = Simulation(world)
        sim.appearance.sphere_colors = np.tile(RED, (len(world.spheres), 1))
        return sim

    camera = Camera.looking_at((0.0, 6.5, 8.5), (0.0, 1.2, 0.0))
    with Offscreen((480, 270), samples=4) as screen:
        wall = screen.render(scene(False), camera).astype(int)
        balls = screen.render(scene(True), camera).astype(int)
    leaks = int((np.abs(balls - wall).max(axis=-1) > 2).sum())
    assert leaks == 0


def test_a_slope_tilted_over_keeps_its_colour_on_its_back(offscreen):
    """A slope (a finite plane facing up as the scene starts) is solid: tilted until its back faces the
    camera it is drawn opaque in its own colour, lit as a face of its own, not as a faint wall."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    world.add_plane(position=(0, 1.5, 0), rotation=(0, 0, 10), size=2.0, restitution=1.0)  # orange
    sim = Simulation(world)
    camera = Camera.looking_at((0.0, 4.0, -6.0), (0.0, 1.5, 0.0))
    front = offscreen.render(sim, camera).astype(int)
    (cx, cy), _ = camera.project(np.array([0.0, 1.5, 0.0]), 200, 150)
    center = (int(cy), int(cx))
    assert front[center][0] > front[center][2] + 60  # orange, from the front
    slope = world.planes[1]
    slope.angular_velocity = (math.radians(120), 0.0, 0.0)  # tipped over towards +z, away from the camera
    for _ in range(240):
        world.step(1 / 240)
    slope.angular_velocity = (0.0, 0.0, 0.0)
    eye = np.asarray(camera.position, float)
    assert np.dot(eye - slope.position, slope.normal) < 0  # the camera sees its back now
    back = offscreen.render(sim, camera).astype(int)
    assert "solid plane backs" in [c.label for c in offscreen.renderer.draws.calls]
    pixel = back[center]
    assert np.abs(pixel - background_pixel()).max() > 40  # not a faint tint over the background
    assert pixel[0] > pixel[2] + 30 and pixel[0] > pixel[1]  # still orange (in the shade: darker)


def test_trails_are_ribbons_several_pixels_wide_in_the_balls_colour_fading_with_age(offscreen):
    """T draws each ball's recent path as a band facing the eye, not a 1-pixel line: here a ball of
    0.3 m passing 3 m from the camera leaves a trail about 8 pixels wide next to it."""
    from ballpit.viewer.frame import OverlayFlags

    world = ballpit.World(gravity=(0, 0, 0))
    world.add_sphere(position=(-1.5, 1.0, 0.0), radius=0.3, velocity=(2.0, 0.0, 0.0))
    sim = Simulation(world)
    sim.appearance.sphere_colors = np.array([RED])
    sim.start()
    for _ in range(60):  # 1 s: from x = -1.5 to 0.5
        sim.advance(1 / 60)
    camera = Camera.looking_at((0.0, 1.0, 3.0), (-0.3, 1.0, 0.0))
    plain = offscreen.render(sim, camera).astype(int)
    traced = offscreen.render(sim, camera, OverlayFlags(trails=True)).astype(int)
    assert "trails" in [c.label for c in offscreen.renderer.draws.calls]
    trail = np.abs(traced - plain).max(axis=-1) > 20
    widths = {}
    for x in (-0.5, -1.0):  # just behind the ball, and half a second back
        (px, _), _ = camera.project(np.array([x, 1.0, 0.0]), 200, 150)
        column = trail[:, int(px)]
        widths[x] = int(column.sum())
        assert np.all(traced[column, int(px), 0] > traced[column, int(px), 2] + 20)  # red, as the ball
    assert widths[-0.5] >= 5 and widths[-1.0] >= 3
    # it fades with age: newer parts are more opaque (redder over the dark background)
    (new_x, new_y), _ = camera.project(np.array([-0.5, 1.0, 0.0]), 200, 150)
    (old_x, old_y), _ = camera.project(np.array([-1.3, 1.0, 0.0]), 200, 150)
    assert traced[int(new_y), int(new_x), 0] > traced[int(old_y), int(old_x), 0] + 15
