"""The plan stage: the crowd test decides how a step is taken, split at every impact or as one soft
frame of substeps (Box2D v3's soft step).

Splitting a step at each impact is what gives the textbook answers, but it costs a pass over the world
per impact: where many pairs may meet within the step (a pile landing or resting) the step is taken
as a soft frame instead (soft.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from ..core.contacts import SPHERE_PLANE, ContactPoints
from ..core.profile import Stage
from ..core.settings import CROWD_OVERLAP, CROWD_PAIRS, SPECULATIVE_REACH
from ..core.state import V, with_static
from ..dynamics import moving_planes
from .collide import Collision, Motion
from .context import Step


class Strategy(Enum):
    """How a step is taken."""

    SPLIT = "split at impacts"
    SOFT = "a soft frame"


@dataclass(frozen=True)
class Plan:
    """The crowd test's verdict: split the step at every impact, or take it as a soft frame of
    ``substeps`` substeps (tried again with more when it cannot keep its promises, soft.py)."""

    strategy: Strategy
    substeps: int = 0

    @staticmethod
    def soft(substeps: int) -> Plan:
        return Plan(Strategy.SOFT, substeps)


SPLIT = Plan(Strategy.SPLIT)


def plan(step: Step, collision: Collision, motion: Motion) -> Plan:
    """The crowd test over the measured contacts: a soft frame of the world's substeps when the step
    is ``crowded``, else split at impacts."""
    with step.profile.stage(Stage.CROWD_TEST):
        crowd = crowded(step, collision.contacts, motion.lin)
    return Plan.soft(step.model.substeps) if crowd else SPLIT


def crowded(step: Step, c: ContactPoints, accel: np.ndarray) -> bool:
    """Whether the step is crowded: taken as one soft-step frame over every kept pair ``c`` instead of
    split at each impact.

    Meetings are counted along today's normals: the gap after dt, g + v_n·dt + ½·a_n·dt², falls to
    contact. More than ``model.crowd_limit`` meetings make the step crowded; so does, among
    CROWD_PAIRS kept pairs or more (a pile), any meeting or touching contact, and so does any overlap
    deeper than CROWD_OVERLAP of a radius (``model.crowd_limit`` inf: never).
    """
    dt, model, touching = step.dt, step.model, step.touching
    if len(c) == 0:  # nothing near anything (free flight): nothing can meet
        return False
    many = len(c) >= CROWD_PAIRS and model.crowd_limit != np.inf  # inf: always split at impacts
    # balls overlapping deeply (created at one point, or left so by a crowd) are pushed apart by the
    # soft step, whose planes hold, not jumped apart by positions
    deep = model.crowd_limit != np.inf and bool(
        np.count_nonzero(c.gap < -CROWD_OVERLAP * model.spheres.radius[c.a])
    )
    if deep:
        return True
    if not many and len(c) <= model.crowd_limit:  # too few pairs to be more meetings
        return False
    # among many pairs (a pile) a touching contact makes the step crowded too: a pile rests in the
    # soft step it landed in, not alternately in the two (and a pile at rest needs no meetings counted)
    if many and np.count_nonzero(c.gap < touching):
        return True
    dv, da = _relative_motion(step, c, accel)
    ahead = c.gap + np.einsum("ij,ij->i", dv * dt + 0.5 * dt * dt * da, c.normal)
    meetings = np.count_nonzero((c.gap >= touching) & (ahead < touching))
    return meetings > (0 if many else model.crowd_limit)


def speculative_reach(step: Step, c: ContactPoints, accel: np.ndarray) -> np.ndarray:
    """The contacts of ``c`` within SPECULATIVE_REACH times the distance they could close in the step
    (by the same bound the time of impact uses), touching ones included."""
    dv, da = _relative_motion(step, c, accel)
    closing = step.model.integrator.closing_speed_bound(dv, da, step.dt) * step.dt
    return c.gap < step.touching + SPECULATIVE_REACH * closing


def _relative_motion(step: Step, c: ContactPoints, accel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's relative velocity (against a moving plane's surface) and acceleration."""
    model = step.model
    v, acc = with_static(step.state.body[:, V]), with_static(accel)
    dv = v.take(c.a, axis=0) - v.take(c.b, axis=0)  # rows by index: faster than v[c.a]
    da = acc.take(c.a, axis=0) - acc.take(c.b, axis=0)
    if model.moving_planes():  # relative to a moving plane's surface under the contact point
        on = c.kind == SPHERE_PLANE
        dv[on] -= moving_planes.surface_velocity(model, step.state, c.other[on], c.point[on])
    return dv, da
