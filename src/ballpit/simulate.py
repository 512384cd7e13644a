"""The headless runner: step a world for a duration, record what happened, summarise the run.

Used by ``ballpit simulate``; also handy from Python (``run(world, 10.0)``). Recording copies the
state arrays once per recorded step into the writers' buffers; nothing is created per ball per step.
"""

from __future__ import annotations

import collections.abc
import math
import time as clock
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from .physics import World
from .physics.contacts import SPHERE_PLANE, SPHERE_SPHERE
from .writers import EventWriter, TrajectoryWriter


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


def inertias(world: World) -> np.ndarray:
    """Each ball's moment of inertia (kg·m²), read once through the public views."""
    return np.array([s.inertia for s in world.spheres], dtype=float)


def energy(world: World, inertia: np.ndarray | None = None) -> Energy:
    """Kinetic (½mv² + ½Iω²) and gravitational potential (−m g·x) energy of every ball."""
    balls = world.spheres
    if len(balls) == 0:
        return Energy(0.0, 0.0)
    inertia = inertias(world) if inertia is None else inertia
    m = balls.masses
    v = balls.velocities
    w = balls.angular_velocities
    kinetic = 0.5 * float(m @ np.einsum("ij,ij->i", v, v)) + 0.5 * float(
        inertia @ np.einsum("ij,ij->i", w, w)
    )
    potential = 0.0 - float(m @ (balls.positions @ world.gravity))  # 0.0 -: no '-0' without gravity
    return Energy(kinetic, potential)


def step_plan(duration: float, dt: float) -> list[tuple[int, float]]:
    """Steps as (count, dt) runs that end exactly at ``duration``: whole steps, then any remainder."""
    whole = math.floor(duration / dt + 1e-9)
    rest = duration - whole * dt
    plan = [(whole, dt)] if whole else []
    if rest > 1e-9 * dt:
        plan.append((1, rest))
    return plan


def run(
    world: World,
    duration: float,
    dt: float | None = None,
    *,
    observe: collections.abc.Callable[[World], None] | None = None,  # called at the start and after each step
    every: int = 1,
    trajectory: TrajectoryWriter | None = None,
    events: EventWriter | None = None,
    progress: bool = False,
) -> RunSummary:
    """Advance ``world`` by ``duration`` seconds in steps of ``dt``, recording every ``every``-th step.

    The trajectory gets the initial state, every ``every``-th step and the final state. The writers
    are not committed here; the caller commits them on success or discards them on failure.
    """
    scene = getattr(world, "scene", None)
    dt = dt if dt is not None else (scene.timestep if scene is not None else 1.0 / 240.0)
    plan = step_plan(duration, dt)
    total = sum(n for n, _ in plan)
    balls = world.spheres
    inertia = inertias(world)
    start_energy = energy(world, inertia)

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
    bar = tqdm(
        total=total,
        unit="step",
        disable=None if progress else True,  # None: only on a terminal
        delay=1.0,
        leave=False,
        dynamic_ncols=True,
        desc=getattr(scene, "name", "simulate"),
    )
    began = clock.perf_counter()
    try:
        for n, h in plan:
            for _ in range(n):
                contacts = world.step(h)
                done += 1
                if len(contacts):
                    counts += np.bincount(contacts.kind, minlength=2)[:2]
                    if events is not None:
                        events.add(contacts)
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
        sim_time=duration,
        wall_time=wall,
        sphere_plane_contacts=int(counts[SPHERE_PLANE]),
        sphere_sphere_contacts=int(counts[SPHERE_SPHERE]),
        records=trajectory.records if trajectory is not None else 0,
        energy_start=start_energy,
        energy_end=energy(world, inertia),
    )


def format_summary(summary: RunSummary, name: str, integrator: str, dt: float, n_balls: int) -> list[str]:
    """The closing summary, a few short lines."""
    s = summary
    e0, e1 = s.energy_start, s.energy_end
    lines = [
        f"{name}: {n_balls} balls, {s.steps} steps of {dt * 1000:.4g} ms "
        f"({s.sim_time:g} s simulated, {integrator})",
        f"  wall time {s.wall_time:.3f} s, {s.steps_per_second:,.0f} steps/s",
        f"  contacts {s.contacts} "
        f"({s.sphere_plane_contacts} sphere-plane, {s.sphere_sphere_contacts} sphere-sphere)",
        f"  energy start {e0.total:.6g} J (kinetic {e0.kinetic:.6g} + potential {e0.potential:.6g}), "
        f"end {e1.total:.6g} J (kinetic {e1.kinetic:.6g} + potential {e1.potential:.6g})",
    ]
    return lines
