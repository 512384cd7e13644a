"""Where a step's time goes, stage by stage (like Box2D's ``b2Profile``).

``World.profile`` is the last step's ``StepProfile``; ``RunProfile`` adds steps up for a run, so the
viewer's HUD and ``ballpit simulate --profile`` show the same figures.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from time import perf_counter


class Stage:
    """The names a step's time is reported under, one constant each (``profile.stage(Stage.PAIRS)``):
    a timer asked for any other name fails, so no stage reports under a name of its own making."""

    SLEEP = "sleep"
    PAIRS = "pairs"
    NARROW_PHASE = "narrow phase"
    CROWD_TEST = "crowd test"
    CONTACT_ROWS = "contact rows"
    PENETRATION = "penetration"
    IMPACTS = "impacts"
    RESTING_SOLVE = "resting solve"
    # a soft frame's stages (softstep.py, separate.py; Box2D's solver stages) and its energy guard
    PREPARE_CONTACTS = "prepare contacts"
    INTEGRATE_VELOCITIES = "integrate velocities"
    WARM_START = "warm start"
    SOFT_SOLVE = "soft solve"
    INTEGRATE_POSITIONS = "integrate positions"
    RELAX = "relax"
    RESTITUTION = "restitution"
    STORE_IMPULSES = "store impulses"
    SEPARATE = "separate"
    ENERGY_GUARD = "energy guard"
    TIME_OF_IMPACT = "time of impact"
    INTEGRATE = "integrate"


# The stages of a step, in the order a step runs them.
STAGES = (
    Stage.PAIRS,
    Stage.NARROW_PHASE,
    Stage.CROWD_TEST,
    Stage.CONTACT_ROWS,
    Stage.PENETRATION,
    Stage.IMPACTS,
    Stage.RESTING_SOLVE,
    Stage.PREPARE_CONTACTS,
    Stage.INTEGRATE_VELOCITIES,
    Stage.WARM_START,
    Stage.SOFT_SOLVE,
    Stage.INTEGRATE_POSITIONS,
    Stage.RELAX,
    Stage.RESTITUTION,
    Stage.STORE_IMPULSES,
    Stage.SEPARATE,
    Stage.ENERGY_GUARD,
    Stage.TIME_OF_IMPACT,
    Stage.INTEGRATE,
    Stage.SLEEP,
)


class _Timer:
    __slots__ = ("name", "seconds", "start")

    def __init__(self, seconds: dict[str, float], name: str) -> None:
        self.seconds, self.name = seconds, name

    def __enter__(self) -> None:
        self.start = perf_counter()

    def __exit__(self, *exc: object) -> None:
        self.seconds[self.name] += perf_counter() - self.start


@dataclass
class StepProfile:
    """One step: seconds per stage, intervals taken, pairs kept, contacts resolved, crowded or not."""

    seconds: dict[str, float] = field(default_factory=lambda: dict.fromkeys(STAGES, 0.0))
    total: float = 0.0  # the whole step, s (the stages plus the glue between them)
    intervals: int = 0
    pairs: int = 0
    contacts: int = 0
    crowded: bool = False

    def stage(self, name: str) -> _Timer:
        """``with profile.stage(Stage.IMPACTS): ...`` adds the block's time to that stage (one of
        ``STAGES``: any other name raises KeyError when the block ends)."""
        return _Timer(self.seconds, name)


@dataclass
class RunProfile:
    """Steps added up: mean time per stage and per step, intervals and contacts per step."""

    steps: int = 0
    crowded_steps: int = 0
    seconds: dict[str, float] = field(default_factory=lambda: dict.fromkeys(STAGES, 0.0))
    total: float = 0.0
    intervals: int = 0
    pairs: int = 0
    contacts: int = 0

    def add(self, step: StepProfile) -> None:
        self.steps += 1
        self.crowded_steps += step.crowded
        for name, s in step.seconds.items():
            self.seconds[name] += s
        self.total += step.total
        self.intervals += step.intervals
        self.pairs += step.pairs
        self.contacts += step.contacts

    def lines(self) -> list[str]:
        """A small table: milliseconds per step for each stage and in all, then the counts per step."""
        n = max(self.steps, 1)
        rows = [f"{name:<15}{1e3 * s / n:9.3f} ms" for name, s in self.seconds.items()]
        rows.append(f"{'step':<15}{1e3 * self.total / n:9.3f} ms")
        rows.append(
            f"intervals/step {self.intervals / n:.2f}   pairs {self.pairs / n:.0f}   "
            f"contacts {self.contacts / n:.1f}   crowded {self.crowded_steps}/{self.steps}"
        )
        return rows
