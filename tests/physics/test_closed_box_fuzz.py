"""No ball ever leaves a closed box, whatever the radii, masses, speeds, gravity, slope, integrator and
timestep: a hypothesis search over small closed boxes, with every step split at its impacts
(``crowd_limit = inf``), as issue #25 attacked it."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ballpit

HALF = 0.5  # m: the box runs from (−0.5, 0, −0.5) to (0.5, 1, 0.5)


def closed_box(world: ballpit.World, restitution: float) -> None:
    walls = [((0, 1, 0), (0, 0, 0)), ((0, -1, 0), (0, 2 * HALF, 0))]
    walls += [
        (n, np.multiply(n, -HALF) + (0, HALF, 0)) for n in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1))
    ]
    for normal, position in walls:
        world.add_plane(position=position, normal=normal, restitution=restitution)


def outside(world: ballpit.World) -> np.ndarray:
    """Balls whose centre is out of the box (a ball touching a wall has its centre a radius inside)."""
    x = world.spheres.positions
    return (np.abs(x[:, 0]) > HALF) | (x[:, 1] < 0) | (x[:, 1] > 2 * HALF) | (np.abs(x[:, 2]) > HALF)


@st.composite
def scenes(draw):
    n = draw(st.integers(1, 8))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    radius = np.exp(rng.uniform(np.log(0.003), np.log(0.16), n))
    mass = np.exp(rng.uniform(np.log(0.01), np.log(2.0), n))
    speed = draw(st.floats(0.0, 52.0))
    gravity = (draw(st.floats(-24, 24)), draw(st.floats(-24, 0)), draw(st.floats(-24, 24)))
    slope = draw(st.floats(0.0, 60.0))
    e = draw(st.sampled_from([0.0, 0.5, 1.0]))
    integrator = draw(st.sampled_from(["euler", "rk2", "rk4"]))
    dt = draw(st.sampled_from([1 / 60, 1 / 120, 1 / 240]))
    return n, rng, radius, mass, speed, gravity, slope, e, integrator, dt


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenes())
def test_no_ball_leaves_a_closed_box_with_every_step_split_at_impacts(scene):
    _, rng, radius, mass, speed, gravity, slope, e, integrator, dt = scene
    world = ballpit.World(gravity=gravity, integrator=integrator)
    world.crowd_limit = float("inf")  # always split at impacts
    closed_box(world, e)
    world.add_plane(position=(0, 0.3, 0), rotation=(0, 0, slope), size=0.6, restitution=e)
    # balls placed apart from each other, from the walls and from the slope's square
    placed: list[np.ndarray] = []
    for r in radius:
        for _ in range(200):
            p = rng.uniform((-HALF + r, r, -HALF + r), (HALF - r, 2 * HALF - r, HALF - r))
            clear_of_slope = abs(world.planes[6].signed_distance(p)) > r or np.abs(p[[0, 2]]).max() > 0.31 + r
            if clear_of_slope and all(
                np.linalg.norm(p - q) > r + s for q, s in zip(placed, radius, strict=False)
            ):
                placed.append(p)
                break
        else:
            break
    k = len(placed)
    velocity = rng.normal(size=(k, 3))
    velocity *= speed / np.maximum(np.linalg.norm(velocity, axis=1), 1e-12)[:, None]
    world.add_spheres(np.array(placed), radius=radius[:k], mass=mass[:k], velocity=velocity)
    for step in range(60):
        world.step(dt)
        assert not outside(world).any(), f"a ball left the box at step {step}"
