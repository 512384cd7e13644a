"""``ballpit compare``: the same scene under every registered integrator, against an RK4 reference.

Each integrator runs from its own copy of the scene's initial world at the scene's timestep; the
reference is RK4 at a quarter of that step. For each run the table gives the total-energy drift
(final − initial, in J and in % of the initial total, and the largest |drift| along the way) and how
far its balls end from the reference's (largest and RMS distance over the balls).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..physics import World
from ..physics.dynamics.integrators import DEFAULT_INTEGRATOR, INTEGRATOR_NAMES
from . import raise_if_stopped
from .energy_trace import EnergyRecorder, EnergyTrace
from .simulate import progress_bar, step_longer_than_run, step_plan

INTEGRATORS = INTEGRATOR_NAMES
REFERENCE_INTEGRATOR = DEFAULT_INTEGRATOR
REFERENCE_DIVISOR = 4  # the reference's step is the scene's step over this
DEFAULT_DURATION = 10.0  # s, when neither --duration nor the scene's [world] duration is given
MAX_STEPS = 10**8  # steps of the reference run; a longer run is a mistake, not a job
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


class CompareError(ValueError):
    """A comparison that cannot be run as asked (one line for the user)."""


@dataclass(frozen=True, eq=False)
class SceneInput:
    """What compare needs from a scene file: its initial world, timestep, suggested duration and name."""

    world: World
    timestep: float  # s per step
    duration: float | None  # s, or None
    name: str


def open_scene(scene: str | Path) -> SceneInput:
    """Load a scene (a path or a bundled scene's name); the one place compare reads scene settings.

    Raises ``SceneError`` (one line) for a bad or missing file.
    """
    from ..scene import read_scene, resolve_scene_path

    info = read_scene(resolve_scene_path(scene))
    return SceneInput(world=info.world, timestep=info.timestep, duration=info.duration, name=info.name)


@dataclass(frozen=True, eq=False)
class Run:
    """One integrator's run: its energies at every step and where its balls ended."""

    integrator: str
    dt: float  # s per step
    steps: int
    energy: EnergyTrace
    final_positions: np.ndarray  # (N, 3) m
    reference: bool = False

    @property
    def label(self) -> str:
        return f"{self.integrator} dt/{REFERENCE_DIVISOR} (reference)" if self.reference else self.integrator

    @property
    def initial_energy(self) -> float:
        return float(self.energy.total[0])

    @property
    def drift(self) -> float:
        """Final minus initial total energy (J)."""
        return float(self.energy.drift[-1])

    @property
    def max_abs_drift(self) -> float:
        """The largest |total energy − initial| over the run (J)."""
        return float(np.max(np.abs(self.energy.drift)))

    def drift_percent(self) -> float:
        """``drift`` in % of |initial total energy|; NaN when that is zero."""
        e0 = abs(self.initial_energy)
        return 100.0 * self.drift / e0 if e0 > 0 else math.nan


@dataclass(frozen=True, eq=False)
class Comparison:
    """Every integrator's run and the reference, all over the same duration."""

    name: str
    duration: float  # s
    dt: float  # s, the integrators' step
    runs: tuple[Run, ...]  # in the order of INTEGRATORS
    reference: Run

    def distance(self, run: Run) -> tuple[float, float]:
        """(largest, RMS) distance over the balls from ``run``'s end positions to the reference's (m)."""
        d = np.linalg.norm(run.final_positions - self.reference.final_positions, axis=1)
        if len(d) == 0:
            return 0.0, 0.0
        return float(d.max()), float(np.sqrt(np.mean(d * d)))


def _run(
    initial: World, integrator: str, duration: float, dt: float, bar: tqdm, reference: bool = False
) -> Run:
    """Step a fresh copy of ``initial`` under ``integrator``, recording the energies every step."""
    world = initial.copy()
    world.integrator = integrator
    record = EnergyRecorder()
    record(world)
    steps = 0
    for n, h in step_plan(duration, dt):
        for _ in range(n):
            raise_if_stopped()
            try:
                world.step(h)
            except FloatingPointError as e:
                raise FloatingPointError(
                    f"the {integrator} run failed at t = {world.time:.6g} s: {e}"
                ) from None
            record(world)
            steps += 1
            bar.update()
    positions = np.array(world.spheres.positions, dtype=float).reshape(-1, 3)
    return Run(integrator, dt, steps, record.trace(), positions, reference)


def compare(
    initial: World, duration: float, dt: float, *, name: str = "scene", progress: bool = False
) -> Comparison:
    """Run every integrator at ``dt`` and the RK4 reference at ``dt / REFERENCE_DIVISOR``.

    ``initial`` is not changed: every run steps its own copy. Raises ``CompareError`` for a run of
    more than MAX_STEPS steps and lets ``FloatingPointError`` from the physics through.
    """
    ref_dt = dt / REFERENCE_DIVISOR
    ref_steps = sum(n for n, _ in step_plan(duration, ref_dt)) if duration / ref_dt <= MAX_STEPS else math.inf
    if ref_steps > MAX_STEPS:
        raise CompareError(
            f"{duration:g} s in reference steps of {ref_dt:g} s is {duration / ref_dt:.3g} steps; "
            f"the limit is {MAX_STEPS:.0e} (use a larger step or a shorter --duration)"
        )
    steps = sum(n for n, _ in step_plan(duration, dt))
    bar = progress_bar(len(INTEGRATORS) * steps + ref_steps, name, progress)
    try:
        runs = []
        for integrator in INTEGRATORS:
            bar.set_description(f"{name}: {integrator}", refresh=False)
            runs.append(_run(initial, integrator, duration, dt, bar))
        bar.set_description(f"{name}: reference", refresh=False)
        reference = _run(initial, REFERENCE_INTEGRATOR, duration, ref_dt, bar, reference=True)
    finally:
        bar.close()
    return Comparison(name=name, duration=duration, dt=dt, runs=tuple(runs), reference=reference)


TABLE_COLUMNS = (
    ("integrator", "<"),
    ("steps", ">"),
    ("drift J", ">"),
    ("drift %", ">"),
    ("max |drift| J", ">"),
    ("drift - ref J", ">"),
    ("distance max m", ">"),
    ("distance rms m", ">"),
)


def format_table(result: Comparison, n_balls: int) -> list[str]:
    """The comparison as text: a heading, the initial energy and one row per run."""
    ref = result.reference
    e0 = ref.energy
    balls = f"{n_balls} ball" if n_balls == 1 else f"{n_balls} balls"
    lines = [
        f"{result.name}: {balls}, {result.duration:g} s in steps of {result.dt * 1000:.4g} ms "
        f"(reference: {ref.integrator} in steps of {ref.dt * 1000:.4g} ms)",
        f"initial energy {ref.initial_energy:.6g} J (kinetic {e0.kinetic[0]:.6g} + potential "
        f"{e0.potential[0]:.6g})",
        "",
    ]
    rows = []
    for run in (*result.runs, ref):
        percent = run.drift_percent()
        if run.reference:
            versus, far = "-", ("-", "-")
        else:
            versus = f"{run.drift - ref.drift:+.4g}"
            far = tuple(f"{d:.4g}" for d in result.distance(run))
        rows.append(
            (
                run.label,
                str(run.steps),
                f"{run.drift:+.6g}",
                "n/a" if math.isnan(percent) else f"{percent:+.4g}",
                f"{run.max_abs_drift:.6g}",
                versus,
                *far,
            )
        )
    widths = [max(len(h), *(len(r[k]) for r in rows)) for k, (h, _) in enumerate(TABLE_COLUMNS)]
    for cells in ([h for h, _ in TABLE_COLUMNS], *rows):
        lines.append(
            "  ".join(
                f"{c:{align}{w}}" for c, (_, align), w in zip(cells, TABLE_COLUMNS, widths, strict=True)
            ).rstrip()
        )
    lines += [
        "",
        "drift: final minus initial total energy; drift - ref: that minus the reference's drift;",
        "distance: from each ball's end position to the reference's, largest and root-mean-square",
    ]
    return lines


def main(args: argparse.Namespace) -> int:
    """The ``ballpit compare`` command (``args``: scene, duration, dt, plot, quiet)."""
    from .plots import PlotFile, drift_figure

    scene = open_scene(args.scene)
    dt = args.dt or scene.timestep
    duration = args.duration or scene.duration or DEFAULT_DURATION
    too_long = step_longer_than_run(duration, dt)
    if too_long:
        print(f"ballpit: {scene.name}: {too_long}", file=sys.stderr)
        return EXIT_BAD_INPUT
    plot = PlotFile(args.plot) if args.plot is not None else None
    try:
        try:
            result = compare(scene.world, duration, dt, name=scene.name, progress=not args.quiet)
        except CompareError as e:
            print(f"ballpit: {scene.name}: {e}", file=sys.stderr)
            return EXIT_BAD_INPUT
        except FloatingPointError as e:
            print(f"ballpit: {scene.name}: {e}", file=sys.stderr)
            return EXIT_FAILED
        if plot is not None:
            runs: Sequence[tuple[str, EnergyTrace, bool]] = [
                (run.label, run.energy, run.reference) for run in (*result.runs, result.reference)
            ]
            title = (
                f"{scene.name}: total-energy drift, steps of {dt * 1000:.4g} ms "
                f"(E(0) = {result.reference.initial_energy:.6g} J)"
            )
            plot.commit(drift_figure(runs, title))
            plot = None
    finally:
        if plot is not None:
            plot.discard()
    for line in format_table(result, len(scene.world.spheres)):
        print(line)
    if args.plot is not None:
        print(f"wrote {args.plot}")
    return EXIT_OK
