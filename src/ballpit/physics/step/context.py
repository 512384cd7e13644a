"""What every stage of one step shares: the world's parts, the step's settings and what it has done."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..collision.pairs import PairCache
from ..contact.warm_start import WarmStart
from ..core.contacts import EventLog
from ..core.profile import Stage, StepProfile
from ..core.state import State
from ..core.steppable import PlanesAsStepped
from ..dynamics import moving_planes
from ..dynamics.forces import ForceTerm
from ..dynamics.integrators import Workspace, integrate
from ..dynamics.model import Model
from .checkpoint import Parts


@dataclass
class Step:
    """One step's context: the world's model, the parts the stages change (``Parts``: the state, the
    kept pairs, the warm start), the step's settings, and its outputs (events, profile, intervals).

    ``intervals`` counts the intervals integrated so far in this step: the strategies read it (is this
    the first interval? is the bound MAX_INTERVALS reached?), and ``World.step`` copies it into the
    profile at the end, which only measures.
    """

    model: Model
    parts: Parts
    workspace: Workspace
    dt: float
    restitution_threshold: float  # m/s, approach speed below which nothing bounces
    touching: float  # m, the gap under which a pair is touching (Model.contact_slop)
    events: EventLog
    profile: StepProfile
    began: float  # perf_counter() when the step began
    checked_planes: PlanesAsStepped  # the plane columns as the step found them (steppable.reject_bad_planes)
    intervals: int = 0

    # the parts, each by its name (read often)
    state: State = field(init=False)
    pairs: PairCache = field(init=False)
    warm: WarmStart = field(init=False)

    def __post_init__(self) -> None:
        self.state, self.pairs, self.warm = self.parts.state, self.parts.pairs, self.parts.warm

    def again(self) -> Step:
        """The same step to be taken again from its start: nothing done yet (its profile goes on)."""
        return replace(self, events=EventLog(), intervals=0)


def integrate_interval(step: Step, forces: list[ForceTerm], push: ForceTerm | None, h: float) -> None:
    """Advance every ball by ``h`` under the force terms ``forces``, plus the contact forces ``push``,
    and move the planes along with them; one more interval of the step."""
    with step.profile.stage(Stage.INTEGRATE):
        terms = forces if push is None else [*forces, push]
        integrate(step.model.integrator, step.state.body, terms, h, step.workspace)
        moving_planes.advance(step.model, step.state, h)
    step.intervals += 1
