"""Feeding a frame to the renderer from a Simulation: the planes whenever they moved or the scene
changed, the interpolated balls and the enabled overlays every frame. Shared by the window and the
offscreen renderer."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ballpit.physics import quaternion

from . import overlays
from .renderer import Renderer
from .simulation import Phase, Simulation


@dataclass
class OverlayFlags:
    """Which debug overlays are shown (C, V, T)."""

    contacts: bool = False
    velocities: bool = False
    trails: bool = False


def plane_poses(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """Every plane's centre (P, 3) and orientation (P, 4) at the moment the balls are drawn.

    The balls are drawn ``alpha`` of the way from the previous step to the current one, which is
    (1 − alpha)·dt before the world's time. A plane moves at a constant velocity and angular velocity
    during a step, so its pose then is its current pose moved back by that much: exact, and no
    history of plane poses is needed.
    """
    planes = sim.world.planes
    centers = np.array(planes.centers, dtype=float).reshape(-1, 3)
    orientations = np.array(planes.orientations, dtype=float).reshape(-1, 4)
    if not len(centers) or sim.phase is not Phase.RUNNING or sim.alpha >= 1.0:
        return centers, orientations
    back = (1.0 - sim.alpha) * sim.timestep
    velocities = np.asarray(planes.velocities, dtype=float).reshape(-1, 3)
    spins = np.asarray(planes.angular_velocities, dtype=float).reshape(-1, 3)
    centers -= velocities * back
    rates = np.linalg.norm(spins, axis=1)
    turning = rates > 0.0
    if turning.any():
        axes = spins[turning] / rates[turning, None]
        undo = quaternion.from_axis_angle(axes, -rates[turning] * back)  # world frame: on the left
        orientations[turning] = quaternion.normalize(quaternion.multiply(undo, orientations[turning]))
    return centers, orientations


class FrameFeeder:
    """Uploads what the renderer needs for one frame and times it."""

    def __init__(self, renderer: Renderer) -> None:
        self.renderer = renderer
        self._generation: int | None = None
        self._sim: Simulation | None = None
        self._plane_pose: tuple[np.ndarray, np.ndarray] | None = None
        self.plane_uploads = 0  # how many times the plane quads were rebuilt (tests read it)
        self.upload_seconds = 0.0

    def upload(
        self, sim: Simulation, flags: OverlayFlags | None = None, eye: np.ndarray | None = None
    ) -> None:
        """Upload this frame's balls (sorted nearest first when ``eye`` is given), lines and, when the
        scene changed or a plane moved, the planes (a few quads: cheap every frame)."""
        started = time.perf_counter()
        flags = flags or OverlayFlags()
        look = sim.appearance
        world = sim.world
        centers, plane_orientations = plane_poses(sim)
        last = self._plane_pose
        moved = (
            last is None
            or last[0].shape != centers.shape
            or not (np.array_equal(last[0], centers) and np.array_equal(last[1], plane_orientations))
        )
        if moved or sim is not self._sim or sim.generation != self._generation:
            self.renderer.set_planes(centers, plane_orientations, world.planes.half_sizes, look.plane_colors)
            self._sim, self._generation = sim, sim.generation
            self._plane_pose = (centers, plane_orientations)
            self.plane_uploads += 1
        positions, orientations = sim.render_state()
        spheres = world.spheres
        self.renderer.upload_balls(positions, orientations, spheres.radii, look.sphere_colors, eye)

        world_lines, overlay_lines = overlays.empty(), overlays.empty()
        if flags.trails and sim.trails.filled:
            world_lines = overlays.trail_lines(sim.trails.ordered(), look.sphere_colors, positions)
        parts = []
        if flags.contacts and sim.contacts is not None and len(sim.contacts):
            parts.append(overlays.contact_lines(sim.contacts.point, sim.contacts.normal))
        if flags.velocities:
            parts.append(overlays.velocity_arrows(positions, np.asarray(spheres.velocities)))
        if parts:
            overlay_lines = np.concatenate(parts)
        self.renderer.upload_lines(world_lines, overlay_lines)
        self.upload_seconds = time.perf_counter() - started
