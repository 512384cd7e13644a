"""Feeding a frame to the renderer from a Simulation: planes when the scene changes, the interpolated
balls and the enabled overlays every frame. Shared by the window and the offscreen renderer."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from . import overlays
from .handover import Needs, Shown, capture
from .renderer import Renderer, solid_planes
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
        self._plane_pose = np.zeros((0, 7))
        self._solid = np.zeros(0, dtype=bool)  # the planes that are floors or slopes (renderer.py)
        self.plane_uploads = 0  # how many times the plane quads were rebuilt (tests read it)
        self.upload_seconds = 0.0

    def upload(
        self,
        sim: Simulation | Shown,
        flags: OverlayFlags | None = None,
        eye: np.ndarray | None = None,
        extra_lines: np.ndarray | None = None,
    ) -> None:
        """Upload this frame's balls (sorted nearest first when ``eye`` is given), lines (``extra_lines``
        are drawn on top, like the overlays) and the planes when the scene changed or they moved.
        ``sim``: what the physics handed over, or a Simulation to copy it from now."""
        started = time.perf_counter()
        flags = flags or OverlayFlags()
        if isinstance(sim, Shown):
            shown = sim
        else:
            needs = Needs(flags.contacts, flags.velocities, flags.trails, energy=False, hud=False)
            shown = capture(sim, needs)
        pose = np.hstack([shown.plane_centers, shown.plane_orientations])
        changed = shown.generation != self._generation
        if changed or len(self._solid) != len(pose):  # which planes are solid: as the scene starts
            self._solid = solid_planes(shown.plane_orientations, shown.plane_half_sizes)
        if changed or pose.shape != self._plane_pose.shape or not np.array_equal(pose, self._plane_pose):
            self.renderer.set_planes(shown.plane_centers, shown.plane_orientations, shown.plane_half_sizes,
                                     shown.appearance.plane_colors, self._solid)  # fmt: skip
            self._generation, self._plane_pose = shown.generation, pose
            self.plane_uploads += 1
        positions = shown.positions
        self.renderer.upload_balls(positions, shown.orientations, shown.radii, shown.sphere_colors, eye)
        self._upload_ghosts(shown)

        trails, overlay_lines = overlays.empty(), overlays.empty()
        if flags.trails and shown.trails is not None and shown.trails.shape[1] == len(positions):
            eye = shown.plane_centers.mean(axis=0) + (0, 1e3, 0) if eye is None else eye  # no eye: from above
            trails = overlays.trail_ribbons(shown.trails, shown.sphere_colors, shown.radii, eye, positions)
        parts = []
        if flags.contacts and shown.contact_points is not None:
            parts.append(overlays.contact_lines(shown.contact_points, shown.contact_normals))
        if flags.velocities and shown.velocities is not None and len(shown.velocities) == len(positions):
            parts.append(overlays.velocity_arrows(positions, shown.velocities))
        if extra_lines is not None and len(extra_lines):
            parts.append(extra_lines)
        if parts:
            overlay_lines = np.concatenate(parts)
        self.renderer.upload_lines(trails, overlay_lines)
        self.upload_seconds = time.perf_counter() - started

    def _upload_ghosts(self, shown: Shown) -> None:
        """Every ghost world's balls, tinted by integrator, as one translucent instance set."""
        from .ghosts import GHOST_ALPHA, TINTS

        ghosts = shown.ghosts
        if not ghosts:
            if self.renderer.ghost_count:  # none drawn already: nothing to upload
                self.renderer.upload_ghosts(np.zeros((0, 3)), np.zeros((0, 4)), np.zeros(0), np.zeros((0, 3)))
            return
        self.renderer.upload_ghosts(
            np.concatenate([g[1] for g in ghosts]),
            np.concatenate([g[2] for g in ghosts]),
            np.concatenate([g[3] for g in ghosts]),
            np.concatenate([np.broadcast_to(TINTS[name], (len(p), 3)) for name, p, _, _ in ghosts]),
            GHOST_ALPHA,
        )
