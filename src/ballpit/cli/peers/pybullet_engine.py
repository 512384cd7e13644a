"""PyBullet on the landing grid, with each ball a rigid body (``useMaximalCoordinates=True``).

A free sphere built as a multibody (PyBullet's default) goes through Featherstone's articulated-body
solver, PyBullet's slow path for free bodies; as a rigid body it is solved as Bullet's own
btRigidBody, the way Bullet's examples drop piles (2.4x as fast at 1,000 balls). 20 solver iterations
ran 1.6x as fast as PyBullet's default 50 with no deeper overlap (0.18 r at 1,000 balls, 0.34 r at
10,000); 10 let the 10,000-ball pile overlap half a radius (``benchmarks/peer_settings.py``).

Bullet mixes two bodies' materials as products, e = e_a·e_b and μ = μ_a·μ_b
(``btManifoldResult::calculateCombinedRestitution`` and ``...Friction``), so every body, the floor and
walls included, gets e = 0.5 and μ = 0.5 for e = 0.25 and μ = 0.25 at every contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .landing import DT, FRICTION, GRAVITY, MASS, RADIUS, RESTITUTION, Landing

STEPS_PER_ADVANCE = 4  # 1/60 s between the samples of positions, as for the other engines
BODY_RESTITUTION = RESTITUTION**0.5
BODY_FRICTION = FRICTION**0.5
WALL_THICKNESS = 0.1  # m: the walls are boxes this thick, their inner faces at x, z = ±half


@dataclass(frozen=True)
class PybulletSettings:
    """PyBullet's engine parameters for the landing."""

    solver_iterations: int = 20  # PyBullet's default is 50: 1.6x slower at 1,000 balls, no stiffer
    maximal_coordinates: bool = True

    def describe(self) -> str:
        bodies = "rigid bodies (useMaximalCoordinates=True)" if self.maximal_coordinates else "multibodies"
        return f"{bodies}, 1/{round(1 / DT)} s steps, {self.solver_iterations} solver iterations"


def build_world(
    client: int,
    centres: np.ndarray,
    half: float | None,
    restitution: float,
    friction: float,
    gravity: float,
    maximal_coordinates: bool = True,
) -> list[int]:
    """Balls of RADIUS and MASS at ``centres`` in PyBullet's ``client``, over a floor at y = 0 inside
    walls at x, z = ±``half`` (no floor or walls when ``half`` is None); returns the balls' ids.

    ``restitution`` and ``friction`` are each body's own (Bullet multiplies two bodies' values).
    """
    import pybullet as p

    p.setTimeStep(DT, physicsClientId=client)
    p.setGravity(0, -gravity, 0, physicsClientId=client)
    statics = []
    if half is not None:
        # y is up here too: the floor's normal is +y, walls are boxes
        floor = p.createCollisionShape(p.GEOM_PLANE, planeNormal=[0, 1, 0], physicsClientId=client)
        statics.append(p.createMultiBody(0, floor, physicsClientId=client))
        t = WALL_THICKNESS / 2
        wall_x = p.createCollisionShape(
            p.GEOM_BOX, halfExtents=[t, 5.0, half + 2 * t], physicsClientId=client
        )
        wall_z = p.createCollisionShape(
            p.GEOM_BOX, halfExtents=[half + 2 * t, 5.0, t], physicsClientId=client
        )
        for shape, pos in (
            (wall_x, [-half - t, 5.0, 0]),
            (wall_x, [half + t, 5.0, 0]),
            (wall_z, [0, 5.0, -half - t]),
            (wall_z, [0, 5.0, half + t]),
        ):
            statics.append(p.createMultiBody(0, shape, basePosition=pos, physicsClientId=client))
    sphere = p.createCollisionShape(p.GEOM_SPHERE, radius=RADIUS, physicsClientId=client)
    balls = [
        p.createMultiBody(
            MASS, sphere, basePosition=c, useMaximalCoordinates=maximal_coordinates, physicsClientId=client
        )
        for c in centres.tolist()
    ]
    for body in statics + balls:
        p.changeDynamics(
            body,
            -1,
            restitution=restitution,
            lateralFriction=friction,
            rollingFriction=0.0,
            spinningFriction=0.0,
            physicsClientId=client,
        )
    return balls


class PybulletRun:
    """A PyBullet DIRECT client holding the landing grid; ``advance`` takes four 1/240 s steps."""

    engine = "pybullet"

    def __init__(self, landing: Landing, settings: PybulletSettings) -> None:
        import pybullet as p

        self._p = p
        self.version = _pybullet_version()
        self.client = p.connect(p.DIRECT)
        p.setPhysicsEngineParameter(
            numSolverIterations=settings.solver_iterations, physicsClientId=self.client
        )
        self.balls = build_world(
            self.client,
            landing.centres,
            landing.half,
            BODY_RESTITUTION,
            BODY_FRICTION,
            GRAVITY,
            settings.maximal_coordinates,
        )
        if landing.velocities is not None:
            for body, v in zip(self.balls, landing.velocities.tolist(), strict=True):
                p.resetBaseVelocity(body, linearVelocity=v, physicsClientId=self.client)
        self.steps_per_advance = STEPS_PER_ADVANCE

    def advance(self) -> None:
        for _ in range(STEPS_PER_ADVANCE):
            self._p.stepSimulation(physicsClientId=self.client)

    def positions(self) -> np.ndarray:
        get = self._p.getBasePositionAndOrientation
        return np.array([get(b, physicsClientId=self.client)[0] for b in self.balls]).reshape(-1, 3)

    def velocities(self) -> np.ndarray:
        get = self._p.getBaseVelocity
        return np.array([get(b, physicsClientId=self.client)[0] for b in self.balls]).reshape(-1, 3)


def _pybullet_version() -> str:
    from importlib.metadata import version

    return version("pybullet")
