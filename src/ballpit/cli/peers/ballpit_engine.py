"""ballpit on the landing grid, as its bundled piles run: RK4, 1/60 s frames of 4 soft substeps.

ballpit mixes two bodies' materials as restitution e = e_a·e_b and friction μ = √(μ_a·μ_b)
(``physics/rows.py``), so every body gets e = 0.5 and μ = 0.25 for e = 0.25, μ = 0.25 at every contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .landing import DT, FRICTION, GRAVITY, MASS, RADIUS, RESTITUTION, Landing

BODY_RESTITUTION = RESTITUTION**0.5  # e_a·e_b = 0.25
BODY_FRICTION = FRICTION  # √(μ_a·μ_b) = 0.25


@dataclass(frozen=True)
class BallpitSettings:
    """How ballpit steps the landing: ``substeps`` soft substeps of DT in each frame."""

    integrator: str = "rk4"
    substeps: int = 4

    def describe(self) -> str:
        return (
            f"{self.integrator.upper()}, 1/{round(1 / (DT * self.substeps))} s frames of {self.substeps} "
            "soft substeps"
        )


class BallpitRun:
    """A World holding the landing grid; ``advance`` steps one frame (``steps_per_advance`` steps of DT)."""

    engine = "ballpit"

    def __init__(self, landing: Landing, settings: BallpitSettings) -> None:
        import ballpit

        self.version = ballpit.__version__
        world = ballpit.World(gravity=(0.0, -GRAVITY, 0.0), integrator=settings.integrator)
        world.substeps = settings.substeps
        material = {"restitution": BODY_RESTITUTION, "friction": BODY_FRICTION, "rolling_friction": 0.0}
        world.add_plane(normal=(0, 1, 0), **material)
        for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
            world.add_plane(position=np.multiply(normal, -landing.half), normal=normal, **material)
        velocity = (0.0, 0.0, 0.0) if landing.velocities is None else landing.velocities
        world.add_spheres(landing.centres, radius=RADIUS, mass=MASS, velocity=velocity, **material)
        self.world = world
        self.steps_per_advance = settings.substeps
        self._frame = DT * settings.substeps

    def advance(self) -> None:
        self.world.step(self._frame)

    def positions(self) -> np.ndarray:
        return np.array(self.world.spheres.positions)

    def velocities(self) -> np.ndarray:
        return np.array(self.world.spheres.velocities)
