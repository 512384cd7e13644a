"""Feeding a frame to the renderer from a Simulation: planes when the scene changes, the interpolated
balls and the enabled overlays every frame. Shared by the window and the offscreen renderer."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from . import overlays
from .renderer import Renderer
from .simulation import Simulation


@dataclass
class OverlayFlags:
    """Which debug overlays are shown (C, V, T)."""

    contacts: bool = False
    velocities: bool = False
    trails: bool = False


class FrameFeeder:
    """Uploads what the renderer needs for one frame and times it."""

    def __init__(self, renderer: Renderer) -> None:
        self.renderer = renderer
        self._generation: int | None = None
        self._sim: Simulation | None = None
        self._plane_pose = np.zeros((0, 7))
        self.plane_uploads = 0  # how many times the plane quads were rebuilt (tests read it)
        self.upload_seconds = 0.0

    def upload(
        self,
        sim: Simulation,
        flags: OverlayFlags | None = None,
        eye: np.ndarray | None = None,
        extra_lines: np.ndarray | None = None,
    ) -> None:
        """Upload this frame's balls (sorted nearest first when ``eye`` is given), lines (``extra_lines``
        are drawn on top, like the overlays) and the planes when the scene changed or they moved."""
        started = time.perf_counter()
        flags = flags or OverlayFlags()
        look = sim.appearance
        world = sim.world
        centers, plane_orientations = sim.render_planes()
        pose = np.hstack([centers, plane_orientations])
        changed = sim is not self._sim or sim.generation != self._generation
        if changed or pose.shape != self._plane_pose.shape or not np.array_equal(pose, self._plane_pose):
            planes = world.planes
            self.renderer.set_planes(centers, plane_orientations, planes.half_sizes, look.plane_colors)
            self._sim, self._generation, self._plane_pose = sim, sim.generation, pose
            self.plane_uploads += 1
        positions, orientations = sim.render_state()
        spheres = world.spheres
        colors = look.sphere_colors[: len(positions)]  # a replay or the history may hold fewer balls now
        self.renderer.upload_balls(positions, orientations, spheres.radii, colors, eye)
        self._upload_ghosts(sim)

        world_lines, overlay_lines = overlays.empty(), overlays.empty()
        if flags.trails and sim.trails.filled:
            world_lines = overlays.trail_lines(sim.trails.ordered(), colors, positions)
        parts = []
        if flags.contacts and sim.contacts is not None and len(sim.contacts):
            parts.append(overlays.contact_lines(sim.contacts.point, sim.contacts.normal))
        if flags.velocities:
            parts.append(overlays.velocity_arrows(positions, np.asarray(spheres.velocities)))
        if extra_lines is not None and len(extra_lines):
            parts.append(extra_lines)
        if parts:
            overlay_lines = np.concatenate(parts)
        self.renderer.upload_lines(world_lines, overlay_lines)
        self.upload_seconds = time.perf_counter() - started

    def _upload_ghosts(self, sim: Simulation) -> None:
        """Every ghost world's balls, tinted by integrator, as one translucent instance set."""
        from .ghosts import GHOST_ALPHA, TINTS

        ghosts = sim.timeline.ghost_worlds()
        if not ghosts:
            self.renderer.upload_ghosts(np.zeros((0, 3)), np.zeros((0, 4)), np.zeros(0), np.zeros((0, 3)))
            return
        spheres = [g.spheres for _, g in ghosts]
        self.renderer.upload_ghosts(
            np.concatenate([s.positions for s in spheres]),
            np.concatenate([s.orientations for s in spheres]),
            np.concatenate([s.radii for s in spheres]),
            np.concatenate([np.broadcast_to(TINTS[name], (len(g.spheres), 3)) for name, g in ghosts]),
            GHOST_ALPHA,
        )
