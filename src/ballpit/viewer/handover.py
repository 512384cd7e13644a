"""The hand-over from the physics to the window: a copy of what one frame draws.

The physics side owns the Simulation and its World; after each batch of steps it captures a ``Shown``
(ball and plane poses, the overlays asked for, the ghosts, the HUD's facts, the timeline bar, the
energy trace while the plot is open) and hands it over. The window draws the latest one and never reads
the World itself, so it never waits for a step and never sees one half done (MuJoCo's ``simulate``
does the same with its render copy). A Shown is never changed after capture. No GL here.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .simulation import Simulation


@dataclass(frozen=True)
class Needs:
    """Which optional parts the window draws now (the rest is not copied)."""

    contacts: bool = False
    velocities: bool = False
    trails: bool = False
    energy: bool = False
    hud: bool = True


@dataclass
class HudFacts:
    """What the HUD says about the run, read from the Simulation at capture."""

    name: str
    time: float
    time_scale: float
    real_time_factor: float
    integrator: str
    timestep: float
    steps_per_second: float
    balls: int
    contacts: int
    kinetic_energy: float
    state: str
    timeline: list[str]
    profile: list[str]
    running: bool

    @classmethod
    def of(cls, sim: Simulation) -> HudFacts:
        from .hud import profile_body, timeline_lines
        from .simulation import Phase

        world = sim.world
        state = sim.phase.value
        if sim.phase is Phase.RUNNING and sim.time_scale != 1.0:
            state = f"running at ×{sim.time_scale:g}"
        return cls(
            name=sim.appearance.name,
            time=float(world.time),
            time_scale=sim.time_scale,
            real_time_factor=sim.real_time_factor,
            integrator=world.integrator,
            timestep=sim.timestep,
            steps_per_second=sim.steps_per_second,
            balls=sim.ball_count,
            contacts=sim.last_step_contacts,
            kinetic_energy=float(sim.kinetic_energy()),
            state=state,
            timeline=timeline_lines(sim),
            profile=profile_body(sim),
            running=sim.phase is Phase.RUNNING,
        )


@dataclass
class Bar:
    """The timeline bar: where the present sits in the span kept, and the span in seconds."""

    fraction: float
    oldest: float
    now: float
    newest: float
    kind: str  # "history" or "replay"


@dataclass
class Shown:
    """One frame's copy of the Simulation (see the module docstring)."""

    generation: int
    appearance: Any  # the scene's Appearance (name, camera start, plane colours)
    sphere_colors: np.ndarray
    positions: np.ndarray  # (N, 3) interpolated, as Simulation.render_state
    orientations: np.ndarray  # (N, 4)
    radii: np.ndarray
    plane_centers: np.ndarray
    plane_orientations: np.ndarray
    plane_half_sizes: np.ndarray
    velocities: np.ndarray | None = None
    contact_points: np.ndarray | None = None
    contact_normals: np.ndarray | None = None
    trails: np.ndarray | None = None  # (samples, N, 3), oldest first
    ghosts: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=list)
    hud: HudFacts | None = None
    bar: Bar | None = None
    energy: Any = None  # an EnergyTrace copy while the plot is open
    error: str | None = None
    message: str = ""
    path: Any = None  # the scene file (for the HUD's save/reload messages)

    @property
    def ball_count(self) -> int:
        return len(self.positions)


def capture(sim: Simulation, needs: Needs = Needs(), hud: HudFacts | None = None) -> Shown:
    """Copy what a frame draws out of ``sim`` (call it while nothing steps the World). ``hud``: facts
    to reuse instead of reading them again (they are read at most ten times a second)."""
    world = sim.world
    spheres, planes = world.spheres, world.planes
    positions, orientations = sim.render_state()
    centers, plane_orientations = sim.render_planes()
    shown = Shown(
        generation=sim.generation,
        appearance=sim.appearance,
        # a replay or the history may hold fewer balls now than the scene has colours for
        sphere_colors=np.array(sim.appearance.sphere_colors[: len(positions)], dtype=float),
        positions=np.array(positions, dtype=float),
        orientations=np.array(orientations, dtype=float),
        radii=np.array(spheres.radii, dtype=float),
        plane_centers=np.array(centers, dtype=float),
        plane_orientations=np.array(plane_orientations, dtype=float),
        plane_half_sizes=np.array(planes.half_sizes, dtype=float),
        error=sim.error,
        message=sim.message,
        path=sim.path,
    )
    if needs.velocities:
        shown.velocities = np.array(spheres.velocities, dtype=float)
    if needs.contacts and sim.contacts is not None and len(sim.contacts):
        shown.contact_points = np.array(sim.contacts.point, dtype=float)
        shown.contact_normals = np.array(sim.contacts.normal, dtype=float)
    if needs.trails and sim.trails.filled:
        shown.trails = sim.trails.ordered()  # fancy indexing: a copy
    timeline = sim.timeline
    for name, ghost in timeline.ghost_worlds():
        g = ghost.spheres
        shown.ghosts.append((name, np.array(g.positions), np.array(g.orientations), np.array(g.radii)))
    source = timeline.source
    if source is not None:
        oldest, now, newest = timeline.span()
        kind = "replay" if timeline.replay is not None else "history"
        shown.bar = Bar(source.fraction(), oldest, now, newest, kind)
    if needs.energy:
        shown.energy = copy.deepcopy(timeline.energy)
    shown.hud = hud if hud is not None else (HudFacts.of(sim) if needs.hud else None)
    return shown
