"""MuJoCo on the landing grid, at its fastest stable settings at the landing's 240 Hz.

Settings (``benchmarks/peer_settings.py``; figures in docs/benchmarks.md): implicitfast, elliptic
cones and the CG solver capped at 10 iterations. At 1,000 balls that ran 3.3x as fast as CG's 100
iterations to tolerance 1e-8, with the deepest overlap 0.30 r against 0.26 r (0.37 r at 10,000 balls);
pyramidal cones and the PGS solver were slower, and Newton, MuJoCo's default solver, gave no result
within 300 s. "Stable": every ball stays in the box and no overlap reaches half a radius.

MuJoCo has no restitution coefficient: a contact is a soft constraint that behaves like a damped
spring, set by ``solref`` = (time constant, damping ratio ζ). A linear spring-damper released when it
stops pushing bounces with e = exp(−πζ/√(1 − ζ²)), so ζ = −ln e / √(π² + ln² e) = 0.404 for e = 0.25.
At 240 Hz a contact lasts about six steps and the discrete spring is livelier on fast impacts:
measured from the speeds at which the ball crosses the floor's surface, impacts at 0.25-1 m/s rebound
with e = 0.23-0.24, at 2-6 m/s with e = 0.26-0.38. No other ζ comes closer over that range (ζ = 0.5
gives 0.11-0.29). The time constant stays at MuJoCo's default, 0.02 s (4.8 steps; MuJoCo asks for at
least 2): stiffer contacts make e swing more with the impact speed.

Friction: MuJoCo takes the larger of two geoms' coefficients, so every geom has μ = 0.25, with
``condim`` 3 (sliding friction only, no torsional or rolling resistance, as in the other engines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .landing import DT, FRICTION, GRAVITY, MASS, RADIUS, RESTITUTION, Landing

STEPS_PER_ADVANCE = 4  # 1/60 s between the samples of positions, as for the other engines
# MuJoCo's arena (contacts, constraint rows, the solver's scratch) is sized for the whole model up
# front. Left to MuJoCo it asks for 1.8 GB at 1,000 balls and cannot allocate it at 10,000; the landing
# uses 8.3 KB a ball at 1,000 balls (``MjData.maxuse_arena``), so 100 KB a ball leaves room for piles
# ten times as deep.
ARENA_PER_BALL = 100_000  # bytes
ARENA_MIN = 16 << 20
DAMPRATIO = -math.log(RESTITUTION) / math.sqrt(math.pi**2 + math.log(RESTITUTION) ** 2)


@dataclass(frozen=True)
class MujocoSettings:
    """MuJoCo's ``<option>`` and contact ``solref`` for the landing."""

    integrator: str = "implicitfast"
    cone: str = "elliptic"
    solver: str = "CG"
    iterations: int = 10  # MuJoCo's default is 100 (to tolerance 1e-8): 3.3x slower at 1,000 balls
    tolerance: float = 1e-8
    ls_iterations: int = 50
    timeconst: float = 0.02
    dampratio: float = DAMPRATIO

    def describe(self) -> str:
        return (
            f"{self.integrator}, {self.cone} cones, {self.solver} solver ({self.iterations} iterations, "
            f"tolerance {self.tolerance:g}), 1/{round(1 / DT)} s steps, solref ({self.timeconst:g} s, "
            f"damping ratio {self.dampratio:.3g})"
        )


def model_xml(landing: Landing, settings: MujocoSettings) -> str:
    """The MJCF of the landing grid: y is up (gravity along −y), the floor and walls are planes."""
    s = settings
    h = landing.half
    planes = [("0 0 0", "0 1 0")] + [
        (f"{-h!r} 0 0", "1 0 0"),
        (f"{h!r} 0 0", "-1 0 0"),
        (f"0 0 {-h!r}", "0 0 1"),
        (f"0 0 {h!r}", "0 0 -1"),
    ]
    walls = "".join(f'<geom type="plane" size="0 0 1" pos="{pos}" zaxis="{z}"/>' for pos, z in planes)
    balls = "".join(
        f'<body pos="{x!r} {y!r} {z!r}"><freejoint/><geom type="sphere" size="{RADIUS!r}" mass="{MASS!r}"/>'
        "</body>"
        for x, y, z in landing.centres.tolist()
    )
    arena = max(ARENA_MIN, ARENA_PER_BALL * landing.n)
    return (
        "<mujoco>"
        f'<size memory="{arena}"/>'
        f'<option timestep="{DT!r}" gravity="0 {-GRAVITY!r} 0" integrator="{s.integrator}" '
        f'cone="{s.cone}" solver="{s.solver}" iterations="{s.iterations}" tolerance="{s.tolerance!r}" '
        f'ls_iterations="{s.ls_iterations}"/>'
        f'<default><geom condim="3" friction="{FRICTION!r} 0 0" solref="{s.timeconst!r} {s.dampratio!r}"/>'
        "</default>"
        f"<worldbody>{walls}{balls}</worldbody>"
        "</mujoco>"
    )


class MujocoRun:
    """An MjModel and MjData of the landing grid; ``advance`` takes four 1/240 s steps in one call."""

    engine = "mujoco"

    def __init__(self, landing: Landing, settings: MujocoSettings) -> None:
        import mujoco

        self.version = mujoco.__version__
        self._mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_string(model_xml(landing, settings))
        self.data = mujoco.MjData(self.model)
        if landing.velocities is not None:
            self.data.qvel.reshape(-1, 6)[:, :3] = landing.velocities
        self.steps_per_advance = STEPS_PER_ADVANCE

    def advance(self) -> None:
        self._mujoco.mj_step(self.model, self.data, nstep=STEPS_PER_ADVANCE)

    def positions(self) -> np.ndarray:
        return self.data.qpos.reshape(-1, 7)[:, :3].copy()

    def velocities(self) -> np.ndarray:
        return self.data.qvel.reshape(-1, 6)[:, :3].copy()  # a free joint's linear velocity: world frame
