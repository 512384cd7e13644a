"""After a soft frame's substeps: what they left overlapping is moved apart by positions alone.

Three named steps, in this order (softstep.frame runs them):

1. ``move_apart``: contacts overlapping deeper than the slop go back to 0.8 of it, each ball moved in
   proportion to its inverse mass (Jacobi sweeps, penetration.separate), never through a plane, the lift
   paid out of the balls' speed (energy_guard.pay_for_lift). An overlap the frame began with is moved
   only as far as MAX_PUSH would have moved it in the frame: a heap of balls created at one point is
   pushed apart, never launched by a jump of positions.
2. ``planes_win``: a ball the frame left deeper in a plane than it started is moved back out along
   the plane's normal.
3. ``hold_apart``: how far each soft spring is held apart for the next frame's warm start
   (``WarmStart.apart``).
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.settings import (
    MAX_PUSH,
    PENETRATION_TOLERANCE,
    SEPARATE_REACH,
    SEPARATE_SWEEPS,
    SLOP,
    SLOP_RETURN,
)
from ..core.state import State, X, with_static
from ..dynamics.model import Model
from . import energy_guard, penetration
from .ends import Ends
from .soft_frame import SoftFrame
from .warm_start import WarmStart


def move_apart(f: SoftFrame, model: Model, state: State) -> np.ndarray:
    """Move the contacts of the frame ``f`` that overlap deeper than the slop back to 0.8 of it (the
    module's step 1), so they are not caught again next frame; returns each contact's separation
    before (at the frame's end)."""
    c, rows, dt, body = f.c, f.rows, f.dt, state.body
    n_balls = model.spheres.count
    s = f.separation(dt)
    slop = SLOP * np.where(
        f.on_plane,
        model.spheres.radius[c.a],
        np.minimum(*(model.spheres.radius[e] for e in (c.a, np.minimum(c.b, n_balls - 1)))),
    )
    made = s - np.minimum(c.gap + MAX_PUSH * dt, -slop)
    if not (made < -PENETRATION_TOLERANCE).any():
        return s
    made = np.where(made < 0.0, s - np.minimum(c.gap + MAX_PUSH * dt, -SLOP_RETURN * slop), made)
    del slop
    part = np.flatnonzero(made < -SEPARATE_REACH * made.min())
    pos = with_static(body[:, X])
    # the contacts ``part``; every contact (a settled pile) as the frame holds them, not copies, and
    # numbered as the frame's solve numbered their balls, with each ball's 1/m
    every = len(part) == len(made)
    if every:
        del part
        columns = Ends.numbered(f.k_balls, f.k_ends), f.ball_inverse_mass()
        inv_mass_a = inv_mass_b = None
    else:
        rows.recall_masses()
        columns, inv_mass_a, inv_mass_b = None, rows.inv_mass_a[part], rows.inv_mass_b[part]
    take = (lambda a: a) if every else (lambda a: a[part])
    # the normals laid out as (3, K) columns, as separate reads them (``c.normal`` is)
    normals = c.normal if every else np.take(c.normal.T, part, axis=1).T
    penetration.separate(
        take(c.a), take(c.b), normals, take(made), inv_mass_a, inv_mass_b, pos, SEPARATE_SWEEPS, columns
    )
    del columns
    del normals, made
    new = penetration.keep_sides_of_planes(model, state, body[:, X], pos[:-1])
    energy_guard.pay_for_lift(model, state, body[:, X], new)
    # s + n·(Δx_a − Δx_b), summed ((s + d₀n₀) + d₁n₁) + d₂n₂, a coordinate at a time: three (K,)
    # arrays alive, not the moves of both ends as (K, 3) rows (216 bytes a ball at 100,000 balls)
    moved = np.ascontiguousarray(with_static(new - body[:, X]).T)  # (3, N + 1)
    least = None
    for k, column in enumerate(moved):
        term = np.take(column, c.a)
        term -= np.take(column, c.b)
        term *= c.normal[:, k]
        if least is None:
            least = np.add(s, term, out=term)
        else:
            least += term
    np.minimum(f.least, least, out=f.least)
    body[:, X] = new
    return s


def planes_win(f: SoftFrame, model: Model, state: State) -> None:
    """Planes win: a ball the frame ``f`` left deeper in a plane than it started is moved back out along
    the plane's normal (positions only, paying for the lift as penetration.py does). Shared among all
    of a ball's contacts, the masses split many ways, the solve cannot always hold a crowd off a floor."""
    c, rows, least, dt = f.c, f.rows, f.least, f.dt
    on = np.flatnonzero(rows.b == model.spheres.count)
    if on.size == 0:
        return
    body = state.body
    start = np.zeros((len(body), 3))
    start[f.idx] = f.start().T
    a, nrm = c.a[on], c.normal[on]
    d = body[a, 0:3] - start[a]
    s = c.gap[on] + d[:, 0] * nrm[:, 0] + d[:, 1] * nrm[:, 1] + d[:, 2] * nrm[:, 2]
    if rows.moving:  # the plane's surface moves on over the frame too
        u = rows.surface[on]
        s -= exact.dot_rows(u, nrm) * dt
    deficit = np.maximum(np.minimum(c.gap[on], -SLOP * model.spheres.radius[a]) - s, 0.0)
    if not (deficit > PENETRATION_TOLERANCE).any():
        return
    new = body[:, X].copy()
    lift = np.zeros((len(body), 3))
    np.add.at(lift, a, deficit[:, None] * nrm)
    new += lift
    energy_guard.pay_for_lift(model, state, body[:, X], new)
    body[:, X] = new
    least[on] = np.minimum(least[on], s + deficit)


def hold_apart(f: SoftFrame, state: State, warm: WarmStart, s: np.ndarray) -> None:
    """What the springs hold apart for the next frame: the moving apart by positions since the frame's
    end (``s``, each contact's separation then), up to the overlap each contact's load needs,
    s_eq = P·(1/m_a + 1/m_b)·(impulse scale)/((mass scale)·(bias rate))."""
    f.x[:, f.live] = state.body[f.idx, X].T
    f.moved()
    s_end = f.separation(f.dt)
    s_eq = f.normal * f.whole * f.soft("impulse_scale") / (f.soft("mass_scale") * f.soft("bias_rate"))
    held = np.minimum(f.apart + np.maximum(s_end - s, 0.0), s_eq + s_end)
    warm.keep_apart(np.where(s_end < 0.0, np.maximum(held, 0.0), 0.0), f.kept_order)
