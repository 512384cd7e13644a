"""Time of impact by conservative advancement, vectorised over candidate pairs.

For each pair, φ(t) is the gap (distance minus radii) along the path the integrator will take. The
gap cannot shrink faster than the bound L on the pair's relative speed over the interval, so stepping
t ← t + φ(t)/L never jumps past the first contact (Mirtich's conservative advancement). For a
head-on approach at constant velocity one step lands exactly on the contact; gravity adds a few more.
This is what stops fast balls tunnelling: a ball at 500 m/s that would cross a plane inside one step
is stopped where it first touches.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def first_contact(
    gap_at: Callable[[np.ndarray, np.ndarray], np.ndarray],
    speed_bound: np.ndarray,
    t_max: float,
    tolerance: float,
    max_iterations: int = 48,
) -> np.ndarray:
    """Earliest time in [0, t_max] at which each pair's gap falls to ``tolerance`` (inf if none).

    ``gap_at(k, t)`` gives the gaps of pairs ``k`` at times ``t``. A pair still converging after
    ``max_iterations`` reports the time it reached, a safe lower bound: the caller advances to it and
    asks again.
    """
    count = len(speed_bound)
    t = np.zeros(count)
    when = np.full(count, np.inf)
    active = np.arange(count)
    gap = gap_at(active, t)
    for _ in range(max_iterations):
        touching = gap <= tolerance
        when[active[touching]] = t[active[touching]]
        moving = ~touching & (speed_bound[active] > 0.0)
        active, gap = active[moving], gap[moving]
        t_next = t[active] + gap / speed_bound[active]
        within = t_next <= t_max
        active, t_next = active[within], t_next[within]
        if active.size == 0:
            return when
        t[active] = t_next
        gap = gap_at(active, t_next)
    when[active] = t[active]
    return when
