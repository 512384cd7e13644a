"""Ball shadows and contact darkening on the planes: real shaders, real pixels read back, each picture
compared with the same view of the floor without the ball."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit
from ballpit.viewer import renderer as renderer_module
from ballpit.viewer import shadows
from ballpit.viewer.camera import Camera
from ballpit.viewer.simulation import Simulation

from .test_renderer import sphere_mask

SUN = shadows.SUN_DIRECTION
# looking down at the floor from the side away from the sun, so shadows fall towards the camera
CAMERA = Camera.looking_at((-2.5, 6.0, -4.0), (-0.6, 0.0, -0.8))


def floor_scene(balls: list[tuple[tuple[float, float, float], float]]) -> Simulation:
    """An infinite floor and the given (centre, radius) balls, standing still."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    for center, radius in balls:
        world.add_sphere(position=center, radius=radius)
    return Simulation(world)


def brightness(image: np.ndarray) -> np.ndarray:
    return image.astype(float).sum(axis=-1)


def pixel(point) -> tuple[int, int]:
    (x, y), _ = CAMERA.project(np.asarray(point, float), 200, 150)
    return int(y), int(x)


def darkening(offscreen, balls) -> tuple[np.ndarray, np.ndarray]:
    """How much darker each floor pixel is with the balls than without (brightness, 0..765), and
    which pixels the balls themselves cover (excluded from any comparison)."""
    empty = brightness(offscreen.render(floor_scene([]), CAMERA))
    shaded = brightness(offscreen.render(floor_scene(balls), CAMERA))
    covered = np.zeros(empty.shape, dtype=bool)
    for center, radius in balls:
        covered |= sphere_mask(CAMERA, center, radius * 1.08)  # a margin for the anti-aliased rim
    return np.where(covered, 0.0, empty - shaded), covered


def shadow_center(center, height: float = 0.0) -> np.ndarray:
    """Where the ray from a ball's centre away from the sun meets the floor."""
    center = np.asarray(center, float)
    return center - SUN * (center[1] - height) / SUN[1]


def test_the_floor_under_a_resting_ball_is_darker_than_far_from_it(offscreen):
    ball = ((0.0, 0.4, 0.0), 0.4)
    dark, covered = darkening(offscreen, [ball])
    # in its shadow, just outside its silhouette on the side away from the sun
    shade_point = shadow_center(ball[0]) - SUN * np.array([1, 0, 1]) * 0.3
    assert not covered[pixel(shade_point)]
    assert dark[pixel(shade_point)] > 120
    # contact darkening beside where it touches, across the sun's direction: no shadow there, yet darker
    across = np.cross(SUN, [0.0, 1.0, 0.0])
    beside = 0.45 * across / np.linalg.norm(across)
    assert not covered[pixel(beside)]
    assert dark[pixel(beside)] > 10
    # far from the ball the floor is exactly as it was
    for far in ([2.0, 0.0, 1.5], [-3.0, 0.0, 0.5], [1.0, 0.0, -3.0]):
        assert abs(dark[pixel(far)]) <= 3
    # and a ball resting on the floor is all it takes: the floor is still drawn in one draw call
    labels = [c.label for c in offscreen.renderer.draws.calls]
    assert labels.count("planes") == 1 and labels.count("balls") == 1


def shadow_centroid(dark: np.ndarray, threshold: float = 60.0) -> np.ndarray:
    rows, cols = np.nonzero(dark > threshold)
    assert len(rows) > 30
    return np.array([cols.mean() + 0.5, rows.mean() + 0.5])


def test_a_ball_far_above_casts_its_shadow_offset_along_the_light(offscreen):
    ball = ((0.0, 2.0, 0.0), 0.35)
    dark, covered = darkening(offscreen, [ball])
    expected = shadow_center(ball[0])
    (ex, ey), _ = CAMERA.project(expected, 200, 150)
    assert shadow_centroid(dark) == pytest.approx([ex, ey], abs=2.0)
    # offset along the light, away from the sun: nothing right under the ball
    below = pixel((0.0, 0.0, 0.0))
    assert not covered[below] and abs(dark[below]) <= 3
    assert np.linalg.norm(expected) > 1.2  # 2 m up: 1.25 m aside


def test_the_shadow_moves_when_the_ball_moves(offscreen):
    first = ((0.0, 1.0, 0.0), 0.35)
    moved = ((-1.0, 1.0, 0.5), 0.35)
    centroids = []
    for ball in (first, moved):
        dark, _ = darkening(offscreen, [ball])
        centroids.append(shadow_centroid(dark))
    for ball, centroid in zip((first, moved), centroids, strict=True):
        (ex, ey), _ = CAMERA.project(shadow_center(ball[0]), 200, 150)
        assert centroid == pytest.approx([ex, ey], abs=2.0)
    assert np.linalg.norm(centroids[1] - centroids[0]) > 10  # pixels


def test_the_shadow_moves_with_a_falling_ball_in_the_running_viewer(offscreen):
    """Driven by the physics: as a ball falls, its shadow closes in on the point under it."""
    world = ballpit.World()
    world.add_plane(position=(0, 0, 0))
    world.add_sphere(position=(0.0, 2.0, 0.0), radius=0.35)
    sim = Simulation(world)
    empty = brightness(offscreen.render(floor_scene([]), CAMERA))
    sim.start()
    centroids = []
    for _ in range(2):
        height = float(sim.world.spheres[0].position[1])
        dark = empty - brightness(offscreen.render(sim, CAMERA))
        dark[sphere_mask(CAMERA, sim.world.spheres[0].position, 0.35 * 1.08)] = 0.0
        (ex, ey), _ = CAMERA.project(shadow_center((0.0, height, 0.0)), 200, 150)
        centroids.append(shadow_centroid(dark))
        assert centroids[-1] == pytest.approx([ex, ey], abs=2.5)
        for _ in range(24):  # 0.4 s: it falls about 0.8 m
            sim.advance(1 / 60)
    assert np.linalg.norm(centroids[1] - centroids[0]) > 8


def test_shadows_fall_on_slopes_too_and_can_be_turned_off(offscreen):
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 1.0, 0), rotation=(0, 0, 15), size=3.0)
    world.add_sphere(position=(0.0, 2.2, 0.0), radius=0.3)
    sim = Simulation(world)
    slope_point = shadow_center((0.0, 2.2, 0.0), height=1.0)  # roughly: the slope is gentle
    with_shadows = brightness(offscreen.render(sim, CAMERA))
    offscreen.renderer.shadows = False
    try:
        without = brightness(offscreen.render(sim, CAMERA))
    finally:
        offscreen.renderer.shadows = True
    assert (without - with_shadows)[pixel(slope_point)] > 100


SLOPE = {"position": (-0.5, 1.0, -0.5), "rotation": (0, 0, 10), "size": 2.0}


def slope_scene(ball: bool) -> Simulation:
    """The floor, a 2 m square slope 1 m above it, and (``ball``) a ball 0.8 m above the slope."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    world.add_plane(**SLOPE)
    if ball:
        world.add_sphere(position=(-0.5, 1.9, -0.5), radius=0.25)
    return Simulation(world)


def slope_frame() -> tuple[np.ndarray, ...]:
    """The slope's centre, normal and in-plane axes."""
    slope = slope_scene(ball=False).world.planes[1]
    return (np.array(slope.position), np.array(slope.normal), *map(np.array, slope.axes))


SLOPE_FRAME = slope_frame()


def crosses_slope(start: np.ndarray, direction: np.ndarray, margin: float) -> bool:
    """Whether the half-line from ``start`` along ``direction`` crosses the slope at least ``margin``
    inside its edges (negative: or that close outside them)."""
    center, normal, u, v = SLOPE_FRAME
    t = np.dot(center - start, normal) / np.dot(direction, normal)
    if t <= 0:
        return False
    local = start + t * direction - center
    return max(abs(np.dot(local, u)), abs(np.dot(local, v))) <= 1.0 - margin


def floor_points(in_shadow: bool) -> list[np.ndarray]:
    """Floor points seen past the slope (not hidden by it), in its shadow or clear of it, by a
    20 cm margin: along the light each one's ray crosses the slope well inside it, or misses it."""
    found = []
    for x in np.linspace(-3, 3, 25):
        for z in np.linspace(-3, 3, 25):
            p = np.array([x, 0.0, z])
            row, col = pixel(p)
            if not (2 <= row < 148 and 2 <= col < 198):
                continue
            eye = np.asarray(CAMERA.position, float)
            if crosses_slope(eye, (p - eye) / np.linalg.norm(p - eye), -0.2):
                continue  # the slope is in front of it
            if crosses_slope(p, SUN, 0.2 if in_shadow else -0.2) == in_shadow:
                found.append(p)
    return found


def test_a_slope_shades_the_floor_under_it_along_the_light(offscreen):
    sim = slope_scene(ball=False)
    lit = brightness(offscreen.render(sim, CAMERA))
    shaded, clear = floor_points(in_shadow=True), floor_points(in_shadow=False)
    assert len(shaded) >= 5 and len(clear) >= 100
    # the floor's cells and grid lines differ by up to a third; the sun's share of the light is more
    typical_clear = np.median([lit[pixel(p)] for p in clear])
    assert all(typical_clear - lit[pixel(p)] > 150 for p in shaded)
    offscreen.renderer.shadows = False  # shadows off: no slope shadow either
    try:
        unshaded = brightness(offscreen.render(sim, CAMERA))
    finally:
        offscreen.renderer.shadows = True
    assert all(unshaded[pixel(p)] - lit[pixel(p)] > 100 for p in shaded)


def test_a_ball_above_a_slope_shades_the_slope_and_casts_no_second_shadow_through_it(offscreen):
    no_ball = brightness(offscreen.render(slope_scene(ball=False), CAMERA))
    ball = brightness(offscreen.render(slope_scene(ball=True), CAMERA))
    center = np.array([-0.5, 1.9, -0.5])
    covered = sphere_mask(CAMERA, center, 0.25 * 1.08)
    on_floor = shadow_center(center)  # where its shadow would fall if the slope let light through
    assert crosses_slope(on_floor, SUN, 0.3)
    eye = np.asarray(CAMERA.position, float)
    assert not crosses_slope(eye, (on_floor - eye) / np.linalg.norm(on_floor - eye), -0.1)  # seen
    assert not covered[pixel(on_floor)]
    assert abs(ball[pixel(on_floor)] - no_ball[pixel(on_floor)]) <= 6  # the slope's shade, nothing more
    # where the ray from the ball's centre away from the sun meets the slope: its shadow is there
    slope = slope_scene(ball=False).world.planes[1]
    t = np.dot(slope.position - center, slope.normal) / np.dot(-SUN, slope.normal)
    on_slope = center - t * SUN
    assert not covered[pixel(on_slope)]
    assert no_ball[pixel(on_slope)] - ball[pixel(on_slope)] > 100


def test_the_casters_written_out_for_the_scene_shade_as_a_program_written_for_sixteen(offscreen):
    """The plane and ball programs are compiled for the number of casting planes the scene has
    (casters.glsl's CASTERS): the picture is the one a program written out for all sixteen draws."""
    sim = slope_scene(ball=True)
    renderer = offscreen.renderer
    drawn = offscreen.render(sim, CAMERA)
    casters = len(renderer._caster_index)
    assert casters < renderer_module.MAX_CASTERS
    try:
        renderer._programs_for(renderer_module.MAX_CASTERS)
        written_for_all = offscreen.draw(CAMERA)
    finally:
        renderer._programs_for(casters)
    no_slope = brightness(offscreen.render(slope_scene(ball=False), CAMERA))
    assert (np.abs(no_slope - brightness(drawn)) > 100).any()  # the ball and its shadow are in it
    assert np.abs(drawn.astype(int) - written_for_all.astype(int)).max() <= 1


def test_each_of_several_slopes_shades_the_floor(offscreen):
    """Two slopes side by side: the floor along the light under each is in its shade, whichever is
    the first caster and whichever the second."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    centers = [np.array([-1.6, 1.0, -1.2]), np.array([0.6, 1.0, 0.4])]
    for center in centers:
        world.add_plane(position=tuple(center), rotation=(0, 0, 10), size=1.0)
    image = brightness(offscreen.render(Simulation(world), CAMERA))
    empty = brightness(offscreen.render(floor_scene([]), CAMERA))
    for center in centers:
        under = shadow_center(center)  # the floor point whose ray towards the sun meets the slope's middle
        row, col = pixel(under)
        assert 0 <= row < 150 and 0 <= col < 200
        assert empty[row, col] - image[row, col] > 100


def test_the_casters_shade_met_at_the_vertices_is_the_shade_worked_out_at_each_pixel(offscreen):
    """The plane program meets the first eight casters' rays per vertex and interpolates them
    (casters.glsl, CASTER_GROUPS); ten slopes here, so two groups and two casters per pixel. The picture
    is the one a program working out every caster at every pixel draws."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0))
    for i in range(10):
        x, z = -3.0 + 1.4 * (i % 5), -2.4 + 2.2 * (i // 5)
        world.add_plane(position=(x, 1.0 + 0.15 * i, z), rotation=(8.0 * (i % 3), 0, 12 - 5 * i), size=0.9)
    sim = Simulation(world)
    renderer = offscreen.renderer
    drawn = offscreen.render(sim, CAMERA)
    casters = len(renderer._caster_index)
    assert casters == 10
    per_pixel = renderer_module.Program(
        "plane.vert", "plane.frag", None, {"CASTERS": casters, "CASTER_GROUPS": 0}
    )
    interpolated = renderer.plane_program
    try:
        per_pixel.use()
        per_pixel.set_int("u_shadow_balls", renderer_module.SHADOW_BALLS_UNIT)
        per_pixel.set_int("u_shadow_cells", renderer_module.SHADOW_CELLS_UNIT)
        renderer.plane_program = per_pixel
        worked_out = offscreen.draw(CAMERA)
    finally:
        renderer.plane_program = interpolated
        per_pixel.delete()
    floor_only = brightness(offscreen.render(floor_scene([]), CAMERA))
    assert ((floor_only - brightness(drawn)) > 150).mean() > 0.05  # the slopes' shade is in it
    assert np.abs(drawn.astype(int) - worked_out.astype(int)).max() <= 2


# ---------------------------------------------------------------- the grid itself (no GL)


def cells_read(grid: shadows.ShadowGrid, point: np.ndarray) -> range:
    """Which balls (rows of grid.balls) the plane shader reads for a point, as plane.frag does."""
    g = (grid.axes @ point - grid.origin) / grid.cell_size
    nx, ny = grid.shape
    if not (0 <= g[0] < nx and 0 <= g[1] < ny):
        return range(0)
    first, end = grid.ranges[int(g[1]) * nx + int(g[0])]
    return range(first, end)


def test_every_ball_within_reach_of_a_point_is_in_the_cells_the_shader_reads():
    rng = np.random.default_rng(3)
    centers = rng.uniform((-3, 0.1, -3), (3, 4, 3), size=(400, 3))
    radii = rng.uniform(0.05, 0.3, size=400)
    grid = shadows.build(centers, radii, limit=10_000)
    assert grid.dropped == 0 and len(grid.balls) >= 400
    axes = shadows.sun_basis()
    for point in rng.uniform((-4, -0.5, -4), (4, 4, 4), size=(300, 3)):
        across = np.linalg.norm((centers - point) @ axes.T, axis=1)
        near = np.flatnonzero(across <= shadows.REACH * radii)
        read = grid.balls[sorted(cells_read(grid, point))]
        for k in near:
            assert np.any(np.all(np.isclose(read[:, :3], centers[k]), axis=1))


def test_a_crowded_cell_keeps_the_balls_nearest_the_sun():
    column = np.linspace(0.1, 3.0, 30)[:, None] * SUN  # 30 balls in a row along the sun's rays
    grid = shadows.build(column[::-1], np.full(30, 0.05), limit=8)
    read = grid.balls[list(cells_read(grid, column[0]))]  # what a point under the row reads
    assert len(read) == 8 and grid.dropped > 0
    along = read[:, :3] @ SUN
    assert np.all(np.diff(along) < 0)  # nearest the sun first
    assert along.min() == pytest.approx(np.sort(column @ SUN)[-8], rel=1e-6)


def test_the_sun_grid_stays_bounded():
    rng = np.random.default_rng(4)
    centers = np.concatenate([rng.uniform(-500, 500, size=(1000, 3)), rng.uniform(-1, 1, size=(1000, 3))])
    grid = shadows.build(centers, np.full(2000, 0.01))
    assert grid.cells <= shadows.MAX_CELLS
    assert grid.ranges.shape == (grid.cells, 2) and grid.ranges[-1, 1] == len(grid.balls)
    assert np.all(np.diff(grid.ranges, axis=1) <= shadows.LIMIT)
    assert np.all(grid.ranges[1:, 0] == grid.ranges[:-1, 1])


def test_a_ball_under_a_slope_is_in_its_shade(offscreen):
    def scene(slope: bool) -> Simulation:
        world = ballpit.World(gravity=(0, 0, 0))
        world.add_plane(position=(0, 0, 0))
        if slope:
            world.add_plane(position=(0, 1.5, 0), size=3.0)  # its shadow covers the ball (below)
        world.add_sphere(position=(0.0, 0.3, 0.0), radius=0.3)
        return Simulation(world)

    camera = Camera.looking_at((0.0, 0.6, 4.0), (0.0, 0.3, 0.0))  # under the slope's level
    assert crosses_slope_at((0.0, 0.3, 0.0), height=1.5, half=1.5)
    ball = sphere_mask(camera, (0.0, 0.3, 0.0), 0.3 * 0.9)  # inside the rim
    lit = brightness(offscreen.render(scene(False), camera))[ball].mean()
    shaded = brightness(offscreen.render(scene(True), camera))[ball].mean()
    assert shaded < 0.75 * lit


def crosses_slope_at(point, height: float, half: float) -> bool:
    """Whether the ray from ``point`` towards the sun crosses the level square of half size ``half``
    centred above the origin at ``height``."""
    point = np.asarray(point, float)
    hit = point + SUN * (height - point[1]) / SUN[1]
    return bool(abs(hit[0]) < half and abs(hit[2]) < half)
