"""The headless runner: step a world for a duration, record what happened, summarise the run.

Used by ``ballpit simulate``; also handy from Python (``run(world, 10.0)``). Recording copies the
state arrays once per recorded step into the writers' buffers; nothing is created per ball per step.
"""

from __future__ import annotations

import collections.abc
import math
import time as clock
from dataclasses import dataclass, fields

import numpy as np
from tqdm import tqdm

from ..physics import DEFAULT_TIMESTEP, Contacts, World
from ..physics.core.contacts import SPHERE_PLANE, SPHERE_SPHERE
from ..physics.core.validation import MAX_TIMESTEP
from . import raise_if_stopped
from .trajectory import TrajectoryWriter
from .writers import EventWriter


@dataclass(frozen=True)
class Energy:
    """Mechanical energy in joules; potential is measured from y = 0 (from the origin along g)."""

    kinetic: float  # translational + rotational
    potential: float

    @property
    def total(self) -> float:
        return self.kinetic + self.potential


@dataclass(frozen=True)
class RunSummary:
    """What a run did, for the closing summary line."""

    steps: int
    sim_time: float  # s of simulated time
    wall_time: float  # s of real time spent stepping and recording
    sphere_plane_contacts: int
    sphere_sphere_contacts: int
    records: int  # trajectory records written (each one row per ball)
    energy_start: Energy
    energy_end: Energy

    @property
    def contacts(self) -> int:
        return self.sphere_plane_contacts + self.sphere_sphere_contacts

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.wall_time if self.wall_time > 0 else math.inf


def energy(world: World) -> Energy:
    """The world's kinetic (½mv² + ½Iω²) and gravitational potential (−m g·x) energy."""
    return Energy(world.kinetic_energy(), 0.0 + world.potential_energy())  # 0.0 +: no '-0'


ROUNDING = 64 * np.finfo(float).eps  # energies smaller than this times the run's scale print as 0


def tidy(value: float, scale: float) -> float:
    """``value``, or 0.0 when it is zero to within rounding next to ``scale`` (the run's energies)."""
    return 0.0 if abs(value) <= ROUNDING * scale else value


MAX_STEPS = 10**9  # a longer run is a mistake (a timestep of 1e-300 s), not a job: refused


class TooManySteps(ValueError):
    """A run of more than MAX_STEPS steps."""


def step_count(duration: float, dt: float) -> float:
    """How many steps ``duration`` takes at ``dt`` (a float: it may be astronomically large, or inf)."""
    return math.ceil(duration / dt - 1e-9) if duration / dt < 2.0**62 else duration / dt


EVENT_KINDS = ("impacts", "all")


class ImpactFilter:
    """Keeps, of each step's contacts, the impacts: pairs that were not in contact the step before.

    A bounce, a collision, a ball landing or rolling onto another plane is the first step of a
    contact, and is kept; the same pair resting or rolling on in the following steps is not. A
    contact that opens and closes again (a ball bouncing, or jostled in a pile) is kept each time it
    closes. Contacts present when the run starts count in its first step.
    """

    def __init__(self) -> None:
        self._previous = np.zeros(0, dtype=np.int64)  # sorted pair keys of the last step

    def __call__(self, contacts: Contacts) -> Contacts:
        """The impacts among one step's ``contacts``; call it once per step, in order."""
        keys = _pair_keys(contacts)
        previous = self._previous
        self._previous = np.sort(keys)
        if len(previous) == 0 or len(keys) == 0:
            return contacts
        at = np.minimum(np.searchsorted(previous, keys), len(previous) - 1)
        seen = previous[at] == keys
        if not seen.any():
            return contacts
        return Contacts(**{f.name: getattr(contacts, f.name)[~seen] for f in fields(Contacts)})


class SleepingContacts:
    """Adds, to each step's contacts, those of sleeping balls (``events_kind="all"``).

    A sleeping ball still rests on what it fell asleep on, but the step no longer solves that contact
    (it holds the ball still instead), so the step does not report it. Here each pair whose balls are
    all asleep now carries on the last contact solved for it: the same point, normal and impulse (the
    impulse that held it each step while awake), at each later step's start time.
    """

    def __init__(self) -> None:
        self._last = Contacts.empty()  # what the last step reported, carried rows included

    def __call__(self, world: World, contacts: Contacts, start: float) -> Contacts:
        """``contacts`` of the step that began at ``start``, with the sleeping balls' resting ones."""
        last = self._last
        if len(last):
            asleep = world.asleep
            held = asleep[last.a] & np.where(last.kind == SPHERE_SPHERE, asleep[last.b], True)
            if len(contacts) and held.any():
                held &= ~np.isin(_pair_keys(last), _pair_keys(contacts))
            if held.any():
                carried = Contacts(**{f.name: getattr(last, f.name)[held] for f in fields(Contacts)})
                carried.time[:] = start
                contacts = Contacts.concatenate([contacts, carried])
        self._last = contacts
        return contacts


def _pair_keys(contacts: Contacts) -> np.ndarray:
    """One integer per (kind, a, b) pair (ball and plane indices are below 2**30)."""
    return ((contacts.a.astype(np.int64) * 2 + contacts.kind) << 32) | contacts.b.astype(np.int64)


def step_plan(duration: float, dt: float) -> list[tuple[int, float]]:
    """Steps as (count, dt) runs that end exactly at ``duration``: whole steps, then any remainder.

    Raises TooManySteps for a run of more than MAX_STEPS steps.
    """
    count = step_count(duration, dt)
    if not count <= MAX_STEPS:
        raise TooManySteps(
            f"{duration:g} s in steps of {dt:g} s is {count:.3g} steps; the limit is {MAX_STEPS:.0e}"
        )
    whole = math.floor(duration / dt + 1e-9)
    rest = duration - whole * dt
    plan = [(whole, dt)] if whole else []
    if rest > 1e-9 * min(dt, duration):  # a step longer than the run: one step of the whole run
        plan.append((1, rest))
    return plan


def step_longer_than_run(duration: float, dt: float) -> str | None:
    """What is wrong when a step of ``dt`` is longer than the whole run (the command line refuses it:
    the run would be one step of ``duration`` instead) or than any step may be, else None."""
    if dt > MAX_TIMESTEP:
        return f"a step of {dt:g} s is longer than a step may be ({MAX_TIMESTEP:g} s): use a smaller --dt"
    if dt <= duration * (1 + 1e-9):
        return None
    return (
        f"a step of {dt:g} s is longer than the run ({duration:g} s): "
        "use a smaller --dt or a longer --duration"
    )


def progress_bar(total: int, name: str, progress: bool) -> tqdm:
    """The steps' progress bar on stderr: only on a terminal, after a second, gone when done."""
    return tqdm(
        total=total,
        unit="step",
        disable=None if progress else True,  # None: only on a terminal
        delay=1.0,
        leave=False,
        dynamic_ncols=True,
        desc=name,
    )


def run(
    world: World,
    duration: float,
    dt: float | None = None,
    *,
    observe: collections.abc.Callable[[World], None] | None = None,  # called at the start and after each step
    every: int = 1,
    trajectory: TrajectoryWriter | None = None,
    events: EventWriter | None = None,
    events_kind: str = "impacts",
    progress: bool = False,
    name: str = "simulate",
) -> RunSummary:
    """Advance ``world`` by ``duration`` seconds in steps of ``dt``, recording every ``every``-th step.

    ``dt`` defaults to the physics' default timestep; ``name`` labels the progress bar. The trajectory
    gets the initial state, every ``every``-th step and the final state. ``events`` gets the impacts
    (see ImpactFilter) or, with ``events_kind="all"``, every contact of every step, sleeping balls'
    resting contacts included (see SleepingContacts). The writers are
    not committed here; the caller commits them on success or discards them on failure.
    """
    if events_kind not in EVENT_KINDS:
        raise ValueError(f"events_kind must be one of {', '.join(EVENT_KINDS)}, got {events_kind!r}")
    keep = ImpactFilter() if events is not None and events_kind == "impacts" else None
    sleeping = SleepingContacts() if events is not None and events_kind == "all" else None
    dt = dt if dt is not None else DEFAULT_TIMESTEP
    plan = step_plan(duration, dt)
    total = sum(n for n, _ in plan)
    balls = world.spheres
    start_energy = energy(world)
    start_time = world.time

    def record() -> None:
        if trajectory is not None:
            trajectory.record(
                world.time, balls.positions, balls.velocities, balls.angular_velocities, balls.orientations
            )

    record()
    if observe is not None:
        observe(world)
    counts = np.zeros(2, dtype=np.int64)
    done = 0
    bar = progress_bar(total, name, progress)
    began = clock.perf_counter()
    try:
        for n, h in plan:
            for _ in range(n):
                raise_if_stopped()
                began_at = world.time
                contacts = world.step(h)
                done += 1
                if len(contacts):
                    counts += np.bincount(contacts.kind, minlength=2)[:2]
                if events is not None:
                    if sleeping is not None and world.sleep:
                        contacts = sleeping(world, contacts, began_at)
                    events.add(contacts if keep is None else keep(contacts))
                if done % every == 0 or done == total:
                    record()
                bar.update()  # cheap next to a step; tqdm redraws at most ~10 times a second
                if observe is not None:
                    observe(world)
    finally:
        bar.close()
    wall = clock.perf_counter() - began
    return RunSummary(
        steps=done,
        sim_time=world.time - start_time,  # what was stepped, so an interrupted or odd plan says so
        wall_time=wall,
        sphere_plane_contacts=int(counts[SPHERE_PLANE]),
        sphere_sphere_contacts=int(counts[SPHERE_SPHERE]),
        records=trajectory.records if trajectory is not None else 0,
        energy_start=start_energy,
        energy_end=energy(world),
    )


def format_summary(summary: RunSummary, name: str, integrator: str, dt: float, n_balls: int) -> list[str]:
    """The closing summary, a few short lines."""
    s = summary
    e0, e1 = s.energy_start, s.energy_end
    scale = max(abs(e.kinetic) + abs(e.potential) for e in (e0, e1))

    def j(value: float) -> str:
        return f"{tidy(value, scale):.6g}"

    lines = [
        f"{name}: {n_balls} balls, {s.steps} steps of {dt * 1000:.4g} ms "
        f"({s.sim_time:g} s simulated, {integrator})",
        f"  wall time {s.wall_time:.3f} s, {s.steps_per_second:,.0f} steps/s",
        f"  contacts {s.contacts} "
        f"({s.sphere_plane_contacts} sphere-plane, {s.sphere_sphere_contacts} sphere-sphere)",
        f"  energy start {j(e0.total)} J (kinetic {j(e0.kinetic)} + potential {j(e0.potential)}), "
        f"end {j(e1.total)} J (kinetic {j(e1.kinetic)} + potential {j(e1.potential)})",
    ]
    return lines
