"""The hand-over from the physics to the window: a copy of what one frame draws.

The physics side owns the Simulation and its World; after each batch of steps it captures a ``Shown``
(ball and plane poses, the overlays asked for, the ghosts, the HUD's facts, the timeline bar, the
energy trace while the plot is open) and hands it over. The window draws the latest one and never reads
the World itself, so it never waits for a step and never sees one half done (MuJoCo's ``simulate``
does the same with its render copy). A Shown is never changed after capture, but for its ghosts when
they are stepped in a process of their own: the frame of its step may come after the capture, and the
window takes it when it shows the state (``resolve_ghosts``). No GL here.
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
        from .simulation import Phase

        world = sim.world
        phase = sim.shown_phase
        state = phase.value
        if phase is Phase.RUNNING and sim.time_scale != 1.0:
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
            running=phase is Phase.RUNNING,
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
    ghost_step: int | None = None  # the main run's step the ghosts are drawn at
    ghost_run: Any = None  # ghosts stepped elsewhere (ghostproc.RemoteGhosts), asked again when shown
    hud: HudFacts | None = None
    bar: Bar | None = None
    energy: Any = None  # an EnergyWindow copy while the plot is open
    error: str | None = None
    message: str = ""
    path: Any = None  # the scene file (for the HUD's save/reload messages)
    time: float = 0.0  # the World's time (s) of the state copied
    step: int | None = None  # its step in the history (None before the drop, or in a replay)
    watch: Any = None  # the panel's copy of the run (watch.py), when the window has a panel

    @property
    def ball_count(self) -> int:
        return len(self.positions)

    def resolve_ghosts(self) -> None:
        """The ghosts stepped in their own process: take their frame at this state's step, or the
        nearest earlier one, if it came after the capture (the window calls it before drawing)."""
        run = self.ghost_run
        if run is None or self.step is None or self.ghost_step == self.step:
            return
        frame = run.frame_at(self.step)
        if frame is not None and frame.step != self.ghost_step:
            self.ghosts, self.ghost_step = list(frame.bodies), frame.step


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
        time=float(world.time),
        step=sim.timeline.history.current if sim.timeline.history is not None else None,
    )
    if needs.velocities:
        shown.velocities = np.array(spheres.velocities, dtype=float)
    if needs.contacts and sim.contacts is not None and len(sim.contacts):
        shown.contact_points = np.array(sim.contacts.point, dtype=float)
        shown.contact_normals = np.array(sim.contacts.normal, dtype=float)
    if needs.trails and sim.trails.filled:
        shown.trails = sim.trails.ordered()  # fancy indexing: a copy
    timeline = sim.timeline
    ghosts = timeline.ghosts
    if ghosts is not None:
        frame = ghosts.frame_at(shown.step)
        if frame is not None:
            shown.ghosts, shown.ghost_step = list(frame.bodies), frame.step
        if ghosts.remote:
            shown.ghost_run = ghosts
    source = timeline.source
    if source is not None:
        oldest, now, newest = timeline.span()
        kind = "replay" if timeline.replay is not None else "history"
        shown.bar = Bar(source.fraction(), oldest, now, newest, kind)
    if needs.energy:
        shown.energy = copy.deepcopy(timeline.energy)
    shown.hud = hud if hud is not None else (HudFacts.of(sim) if needs.hud else None)
    return shown


def profile_body(sim: Simulation) -> list[str]:
    """The profile page's lines after its title: where the step's time went over the last second,
    stage by stage (``World.profile``, like Box2D's b2Profile), with intervals, pairs and contacts per
    step; empty before any step."""
    p = sim.profile
    if not p.steps:
        return []
    return [f"{p.steps} steps", f"{'stage':<15}{'per step':>12}", *p.lines()]


def timeline_lines(sim: Simulation) -> list[str]:
    """HUD lines for the history or replay and, with ghosts on, each integrator's energy drift."""
    from .ghosts import LABELS

    timeline = sim.timeline
    lines = []
    span = timeline.span()
    if timeline.replay is not None:
        lines.append(f"replay      {timeline.replay.trajectory.path.name}")
    elif span is not None and timeline.history is not None and timeline.history.in_past:
        lines.append(f"history     {span[2] - span[1]:.3f} s in the past; Space resumes")
    if timeline.ghosts is not None and timeline.ghosts.error is not None:
        lines.append(f"ghosts stopped: {timeline.ghosts.error}")
    for name, drift, main in timeline.drifts():
        what = "run  " if main else "ghost"
        unit = "%" if timeline.ghosts is not None and timeline.ghosts.reference_energy != 0.0 else "J"
        lines.append(f"E drift {what} {LABELS[name]:5s} {drift:+10.4f} {unit}")
    return lines
