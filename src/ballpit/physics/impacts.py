"""Impacts: contacts arriving faster than the restitution threshold leave at e times their approach
speed (Newton's impact law, v_n' = −e·v_n), solved over the island of contacts around them.

The touching contacts within BOUNCE_HOPS balls of an arriving one take part, so a ball landing on a
stack pushes through it, and momentum passes down a line of touching balls (Newton's cradle).
Contacts arriving slower than the threshold just stop (target v_n' = 0).
"""

from __future__ import annotations

import numpy as np

from . import solver
from .contacts import ContactPoints, EventLog
from .model import Model
from .rows import ContactRows
from .solver import Impulses
from .state import State, V, W, with_static

# The bounce is solved over the contacts within this many balls of an arriving one.
BOUNCE_HOPS = 3
# A bounce is solved afresh (no warm start, nothing to hold at rest): Jacobi sweeps per iteration.
BOUNCE_JACOBI_SWEEPS = 1
# Normal speeds (m/s) below this count as not approaching (rounding, not an impact).
APPROACH_SPEED = 1e-6


def bounce(model: Model, state: State, c: ContactPoints, rows: ContactRows, threshold: float,
           allowance: np.ndarray, events: EventLog, now: float, *, arrivals_only: bool,
           seeds_among: np.ndarray | None = None, jacobi_from: int = solver.JACOBI_FROM) -> None:  # fmt: skip
    """Bounce the contacts that arrive, with their island; velocities change in place.

    ``allowance`` (m/s) is how fast each contact may close without being stopped: zero for a
    touching contact, gap/dt for a speculative one, which therefore arrives only faster than that and
    otherwise keeps closing at that speed. With ``arrivals_only`` only arrivals faster than the
    threshold start an island; otherwise any approach does (and the slow ones in it just stop).
    ``seeds_among``, when given, is where islands may start (other contacts only join them).
    """
    if len(c) == 0:
        return
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    ra, rb = rows.arm_a, rows.arm_b
    va, vb, wa, wb = (np.take(u, ends, axis=0) for u in (v, w) for ends in (c.a, c.b))
    rel = va + np.cross(wa, ra) - vb - np.cross(wb, rb)
    if rows.moving:  # relative to a moving plane's surface
        rel -= rows.surface
    vn = np.einsum("ij,ij->i", rel, c.normal)
    approaching = vn < -(allowance + APPROACH_SPEED)
    arriving = approaching & (-vn > threshold)
    seeds = arriving if arrivals_only else approaching
    if seeds_among is not None:
        seeds = seeds & seeds_among
    if not seeds.any():
        return
    # The island around the impacts: contacts within BOUNCE_HOPS balls of a seed.
    n = model.spheres.count
    involved = np.zeros(n + 1, bool)
    near = seeds
    for _ in range(BOUNCE_HOPS):
        involved[c.a[near]] = True
        involved[c.b[near]] = True
        involved[n] = False
        near = involved[c.a] | involved[c.b]
    island = rows.subset(near)
    target = np.where(arriving[near], -island.restitution * vn[near], -allowance[near])
    imp = solver.solve(island, v, w, target, Impulses.zeros(len(island)), model.solver_iterations,
                       jacobi_sweeps=BOUNCE_JACOBI_SWEEPS, jacobi_from=jacobi_from)  # fmt: skip
    body = state.body
    body[:, V] = v[:-1]
    body[:, W] = w[:-1]
    hit = c.subset(near)
    events.add(now, hit, hit.keys(), imp.normal)
