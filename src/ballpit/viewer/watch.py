"""What the panel shows of the run, copied on the physics side at each hand-over (as the HUD's facts).

``Watch`` is the panel's part of a ``Shown``: the world's settings, the selected ball's or plane's
state, and, while the plots are open, copies of the traces (energy; the selected ball's height and
speed; the contact count; the time per stage of the step). ``Traces`` samples the run after every
live step; stepping back cuts what lies after the present. No GL and no ImGui here.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..physics.core.contacts import SPHERE_SPHERE
from ..physics.core.profile import STAGES
from .save import euler_xyz_degrees
from .simulation import Phase, Simulation

TRACE_SECONDS = 10.0  # simulated seconds the plots span


@dataclass
class BallFacts:
    index: int
    position: np.ndarray
    velocity: np.ndarray
    spin: np.ndarray
    radius: float
    mass: float
    restitution: float
    friction: float
    rolling_friction: float
    kinetic: float  # J, translational + rotational
    potential: float  # J, −m·g·x
    contacts: int  # in the last step


@dataclass
class PlaneFacts:
    index: int
    position: np.ndarray
    rotation: list[float]  # extrinsic x, y, z degrees (as the scene file writes it)
    normal: np.ndarray
    size: tuple[float, float] | None  # None: infinite
    restitution: float
    friction: float
    rolling_friction: float
    velocity: np.ndarray
    angular_velocity: np.ndarray


@dataclass
class WorldFacts:
    name: str
    path: Any
    phase: Phase
    time: float
    time_scale: float
    integrator: str
    timestep: float
    substeps: int
    gravity: np.ndarray
    sleep: bool
    restitution_threshold: float | None  # None: automatic
    threshold_used: float  # m/s, what the step uses now
    balls: int
    replay: bool
    history: bool  # a history to step back through


@dataclass
class TraceCopy:
    """Copies of the traces, arrays over simulated time."""

    energy: dict[str, np.ndarray] = field(default_factory=dict)
    time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    contacts: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ball: int | None = None
    height: np.ndarray = field(default_factory=lambda: np.zeros(0))
    speed: np.ndarray = field(default_factory=lambda: np.zeros(0))
    stages: dict[str, float] = field(default_factory=dict)  # ms per step, by stage
    step_ms: float = 0.0


@dataclass
class Watch:
    world: WorldFacts
    selected: BallFacts | PlaneFacts | None = None
    traces: TraceCopy | None = None


class Traces:
    """After every live step: the contact count and the selected ball's height and speed."""

    def __init__(self, window: float = TRACE_SECONDS) -> None:
        self.window = window
        self.samples: deque[tuple[float, int, float, float]] = deque()
        self.ball: int | None = None

    def follow(self, ball: int | None) -> None:
        """Trace ``ball`` from now on (its earlier samples go: they were another ball's)."""
        if ball != self.ball:
            self.ball = ball
            self.samples.clear()

    def cut(self, time: float) -> None:
        """The run goes on from ``time`` (s): the samples after it go (they were of a future dropped)."""
        while self.samples and self.samples[-1][0] > time:
            self.samples.pop()

    def sample(self, sim: Simulation) -> None:
        t = float(sim.world.time)
        while self.samples and self.samples[-1][0] >= t:  # stepped back, then on: the old future goes
            self.samples.pop()
        height = speed = np.nan
        if self.ball is not None and self.ball < sim.ball_count:
            ball = sim.world.spheres[self.ball]
            height = float(ball.position[1])
            v = np.asarray(ball.velocity, dtype=float)
            speed = float(np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
        self.samples.append((t, sim.last_step_contacts, height, speed))
        while self.samples and self.samples[0][0] < t - self.window:
            self.samples.popleft()

    def copy(self) -> TraceCopy:
        if not self.samples:
            return TraceCopy(ball=self.ball)
        data = np.array(self.samples, dtype=float).T.copy()  # rows: ImPlot takes contiguous arrays
        return TraceCopy(time=data[0], contacts=data[1], height=data[2], speed=data[3], ball=self.ball)


def world_facts(sim: Simulation) -> WorldFacts:
    world = sim.world
    return WorldFacts(
        name=sim.appearance.name,
        path=sim.path,
        phase=sim.shown_phase,
        time=float(world.time),
        time_scale=sim.time_scale,
        integrator=world.integrator,
        timestep=sim.timestep,
        substeps=world.substeps,
        gravity=np.array(world.gravity, dtype=float),
        sleep=world.sleep,
        restitution_threshold=world.restitution_threshold,
        threshold_used=float(world.model.restitution_threshold_for(sim.timestep)),
        balls=sim.ball_count,
        replay=sim.timeline.replay is not None,
        history=sim.timeline.history is not None,
    )


def ball_facts(sim: Simulation, index: int) -> BallFacts | None:
    world = sim.world
    if not 0 <= index < len(world.spheres):
        return None
    b = world.spheres[index]
    v, w = np.array(b.velocity, dtype=float), np.array(b.angular_velocity, dtype=float)
    kinetic = 0.5 * b.mass * float((v * v).sum()) + 0.5 * b.inertia * float((w * w).sum())
    potential = -b.mass * float((np.asarray(world.gravity) * np.asarray(b.position)).sum())
    contacts = 0
    c = sim.contacts
    if c is not None and len(c):
        mine = (np.asarray(c.a) == index) | (
            (np.asarray(c.kind) == SPHERE_SPHERE) & (np.asarray(c.b) == index)
        )
        contacts = int(mine.sum())
    return BallFacts(
        index,
        np.array(b.position, dtype=float),
        v,
        w,
        b.radius,
        b.mass,
        b.restitution,
        b.friction,
        b.rolling_friction,
        kinetic,
        potential,
        contacts,
    )


def plane_facts(sim: Simulation, index: int) -> PlaneFacts | None:
    world = sim.world
    if not 0 <= index < len(world.planes):
        return None
    p = world.planes[index]
    return PlaneFacts(
        index=index,
        position=np.array(p.position, dtype=float),
        rotation=euler_xyz_degrees(p.orientation),
        normal=np.array(p.normal, dtype=float),
        size=p.size,
        restitution=p.restitution,
        friction=p.friction,
        rolling_friction=p.rolling_friction,
        velocity=np.array(p.velocity, dtype=float),
        angular_velocity=np.array(p.angular_velocity, dtype=float),
    )


def watch(sim: Simulation, selected: tuple[str, int] | None, traces: Traces | None) -> Watch:
    """The panel's copy of the run (``traces``: copy the plots' traces too)."""
    out = Watch(world_facts(sim))
    if selected is not None:
        kind, index = selected
        out.selected = ball_facts(sim, index) if kind == "ball" else plane_facts(sim, index)
    if traces is not None:
        copy = traces.copy()
        copy.energy = sim.timeline.energy.series()
        p = sim.profile
        n = max(p.steps, 1)
        copy.stages = {name: 1e3 * p.seconds.get(name, 0.0) / n for name in STAGES}
        copy.step_ms = 1e3 * p.total / n
        out.traces = copy
    return out
