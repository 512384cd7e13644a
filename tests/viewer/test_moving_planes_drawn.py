"""Planes moved by the physics are drawn where they are: real shaders, real pixels read back."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballpit
from ballpit.viewer.camera import Camera
from ballpit.viewer.simulation import Simulation

from .test_renderer import background_pixel

ORANGE = (0.95, 0.55, 0.15)
FRONT = Camera.looking_at((0, 0, 6), (0, 0, 0))


def plane_pixels(image: np.ndarray) -> np.ndarray:
    """Where the orange plate is (its lit face), as a mask."""
    image = image.astype(int)
    return (image[..., 0] > image[..., 2] + 60) & (np.abs(image - background_pixel()).max(axis=-1) > 40)


def plate(velocity=(0, 0, 0), angular_velocity=(0, 0, 0), size=(2.0, 0.4)) -> Simulation:
    """A plate facing the camera (normal +z), long along x, moving as told; no gravity, no balls."""
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(
        position=(0, 0, 0),
        normal=(0, 0, 1),
        size=size,
        velocity=velocity,
        angular_velocity=angular_velocity,
    )
    sim = Simulation(world)
    sim.appearance.plane_colors = np.array([ORANGE])
    return sim


def at(point) -> tuple[int, int]:
    (x, y), _ = FRONT.project(np.asarray(point, float), 200, 150)
    return int(y), int(x)


def test_a_plane_moved_by_the_physics_is_drawn_at_its_new_place(offscreen):
    sim = plate(velocity=(0, 1.0, 0))
    before = plane_pixels(offscreen.render(sim, FRONT))
    assert before[at((0, 0, 0))] and not before[at((0, 1.0, 0))]
    uploads = offscreen.feeder.plane_uploads
    sim.start()
    for _ in range(60):  # one second at 60 frames per second: the plate rises 1 m
        sim.advance(1 / 60)
    after = plane_pixels(offscreen.render(sim, FRONT))
    assert sim.world.planes[0].position[1] == pytest.approx(1.0, abs=0.02)
    assert after[at((0, 1.0, 0))] and not after[at((0, 0, 0))]
    assert offscreen.feeder.plane_uploads == uploads + 1
    # a plane standing still is not uploaded again
    offscreen.render(sim, FRONT)
    assert offscreen.feeder.plane_uploads == uploads + 1


def test_a_turning_paddle_is_drawn_turning(offscreen):
    sim = plate(angular_velocity=(0, 0, math.pi / 2))  # a quarter turn per second about the view axis
    flat = plane_pixels(offscreen.render(sim, FRONT))
    tip_flat, tip_up = at((0.8, 0, 0)), at((0, 0.8, 0))
    assert flat[tip_flat] and not flat[tip_up]
    sim.start()
    for _ in range(60):
        sim.advance(1 / 60)
    turned = plane_pixels(offscreen.render(sim, FRONT))
    assert turned[tip_up] and not turned[tip_flat]
    # halfway through the turn (at 0.5 s) it is drawn at 45 degrees
    sim.reset()
    sim.start()
    for _ in range(30):
        sim.advance(1 / 60)
    diagonal = plane_pixels(offscreen.render(sim, FRONT))
    assert diagonal[at((0.6, 0.6, 0))] and not diagonal[tip_flat] and not diagonal[tip_up]


def test_planes_are_drawn_at_the_moment_the_balls_are_drawn(offscreen):
    """Balls are drawn interpolated between the last two steps; a moving plane is drawn at the same
    moment (its pose moved back along its motion), so a ball riding it does not sink into it."""
    sim = plate(velocity=(0, 2.0, 0), angular_velocity=(0, 0, 1.0))
    sim.start()
    dt = sim.timestep
    sim.advance(2.5 * dt)  # two steps taken, half a step in the accumulator
    assert sim.alpha == pytest.approx(0.5)
    centers, orientations = sim.render_planes()
    # the balls are drawn halfway between step 1 and step 2, at 1.5 dt: so is the plane
    shown = 1.5 * dt
    assert centers[0] == pytest.approx([0, 2.0 * shown, 0])
    q = orientations[0]
    assert 2 * math.atan2(q[2], q[3]) == pytest.approx(1.0 * shown)  # a turn about z
    sim.toggle_pause()  # paused: drawn where they are
    centers, _ = sim.render_planes()
    assert centers[0] == pytest.approx(sim.world.planes[0].position)


def test_ballpit_render_draws_a_moving_plane_where_it_is(tmp_path):
    """The offscreen renderer behind ``ballpit render``: the first and last frames show the plate at
    its start and at its end."""
    from ballpit.viewer.render import render_world

    world = ballpit.World(gravity=(0, 0, 0))
    world.add_plane(position=(0, 0, 0), normal=(0, 0, 1), size=(2.0, 0.4), velocity=(0, 1.0, 0))
    look = Simulation(
        world
    ).appearance  # the camera render uses for a world built in code, framed before it moves
    camera = Camera.looking_at(look.camera_position, look.camera_look_at)
    out = render_world(world, tmp_path / "frames/", duration=1.0, fps=10, size=(200, 150), progress=False)
    from PIL import Image

    frames = sorted(out.glob("frame_*.png"))
    assert len(frames) == 10

    def lit(image: np.ndarray, point) -> bool:
        (x, y), _ = camera.project(np.asarray(point, float), 200, 150)
        return np.abs(image[int(y), int(x)].astype(int) - background_pixel()).max() > 40

    first, last = (np.asarray(Image.open(f).convert("RGB")) for f in (frames[0], frames[-1]))
    assert lit(first, (0, 0, 0)) and not lit(first, (0, 0.9, 0))
    assert lit(last, (0, 0.9, 0)) and not lit(last, (0, 0, 0))
