"""The crowded step as a frame of substeps: Box2D v3's soft step (E. Catto, "Solver2D", 2024;
Box2D v3 ``solver.c``, ``contact_solver.c``).

Box2D's stages, one function each, each timed into the profile under its ``profile.Stage``: once per
frame (one ``World.step``) ``prepare_contacts`` builds the rows of the speculative contacts measured
(anchors, effective masses, mixed materials, the relative normal velocity at the frame's start). Then
``substeps`` times, with h = dt / substeps:

1. ``integrate_velocities``: v += a·h under the force terms (gravity, drag);
2. ``warm_start``: apply the accumulated impulses again;
3. ``solve`` with a soft bias (below);
4. ``integrate_positions``: x += v·h (symplectic Euler, as Box2D: a ball held by a contact moves
   exactly as the solve leaves its velocity, so a resting ball stays put);
5. ``relax``: solve again without the bias, so the push-out moves positions but leaves no velocity.

Then ``restitution`` and ``store_impulses``, and what the substeps left overlapping deeper than the
slop is moved apart by positions (separate.py).

A contact's separation inside the frame is the one measured at its start plus the balls' moved
positions along the normal, s = s₀ + n·(Δx_a − Δx_b), not a new narrow phase. A contact with s > 0 is
speculative: it may close by at most s this substep, v_n ≥ −s/h. One that overlaps is a soft spring
(Catto, "Soft constraints", GDC 2011): with ω = 2π·f, ζ the damping ratio,

    a₁ = 2ζ + h·ω,  a₂ = h·ω·a₁,  a₃ = 1/(1 + a₂)
    bias rate = ω/a₁,  mass scale = a₂·a₃,  impulse scale = a₃
    ΔP = m_n·(mass scale)·(target − v_n) − (impulse scale)·P,  target = min(−(bias rate)·s, MAX_PUSH)

After the last substep one restitution pass bounces the contacts that closed faster than the
threshold at the frame's start, and the impulses are kept for the next frame's warm start. Balls that
touch no contact of the frame are left to the world's integrator (free flight keeps its textbook
accuracy); see step/plan.py and step/soft.py for when a frame is taken this way at all and how its
result is checked.

Every sweep updates all contacts at once (projected Jacobi with mass splitting, ``jacobi.py``, over
the contact model of contact_model.py): a substep costs a fixed number of array passes, however many
colours a pile would need. Each ball's mass is split only among its contacts that can push this
substep: a speculative contact still far from closing takes no share, so it does not soften the ones
that carry the load.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..core import exact, quaternion
from ..core.contacts import ContactPoints
from ..core.profile import Stage, StepProfile
from ..core.settings import LEVEL, MAX_PUSH, PUSH_AHEAD, RELAX_SWEEPS, SOLVE_SWEEPS
from ..core.state import Q, State, V, W, X
from ..dynamics.forces import ForceTerm, column_accelerations
from ..dynamics.model import Model
from . import impacts, jacobi, separate
from .contact_model import Impulses
from .soft_frame import SoftFrame
from .warm_start import WarmStart

# the contact rows' columns no stage reads once the impulses are stored (``store_impulses``)
_ROWS_DONE = (
    "radius_a",
    "radius_b",
    "arms",
    "inv_inertia_a",
    "inv_inertia_b",
    "restitution",
    "friction",
    "rolling",
)


@dataclass
class Frame:
    """What a soft frame leaves for the checks and the record: per contact the total normal impulse
    over the frame and the least separation seen; per ball touched (``balls``, world rows) the
    farthest it got from where it started and the largest move in one substep, and the box around
    the positions it passed."""

    balls: np.ndarray
    impulse: np.ndarray
    least_separation: np.ndarray
    farthest: np.ndarray
    largest_move: np.ndarray
    lo: np.ndarray  # (3, M) the lowest coordinates each ball had at a substep's end
    hi: np.ndarray


def frame(
    model: Model,
    state: State,
    c: ContactPoints,
    forces: list[ForceTerm],
    dt: float,
    threshold: float,
    warm: WarmStart,
    substeps: int,
    profile: StepProfile,
    before_write: Callable[[], np.ndarray] | None = None,
) -> Frame:
    """Advance the balls the contacts ``c`` touch by ``dt`` in ``substeps`` substeps (their states
    change in place; planes and other balls do not move here). ``warm`` gives and keeps the impulses;
    ``threshold`` is the restitution threshold (m/s). Each stage is timed into ``profile``.
    ``before_write`` is called just before the balls' states first change (the step's undo copies
    them then, ``Checkpoint.keep_balls``) and returns the balls' block as it was, read only."""
    with profile.stage(Stage.PREPARE_CONTACTS):
        f = SoftFrame(model, state, c, forces, dt, warm, substeps)
    for i in range(substeps):
        with profile.stage(Stage.INTEGRATE_VELOCITIES):
            integrate_velocities(f)
        with profile.stage(Stage.WARM_START):
            warm_start(f)
        with profile.stage(Stage.SOFT_SOLVE):
            solve(f, i)
        with profile.stage(Stage.INTEGRATE_POSITIONS):
            integrate_positions(f)
        with profile.stage(Stage.RELAX):
            relax(f, i)
    with profile.stage(Stage.RESTITUTION):
        added = restitution(f, model, state, threshold)
    with profile.stage(Stage.STORE_IMPULSES):
        store_impulses(f, model, state, warm, added, before_write)
    with profile.stage(Stage.SEPARATE):
        s = separate.move_apart(f, model, state)
        separate.planes_win(f, model, state)
        separate.hold_apart(f, state, warm, s)
    return Frame(f.k_balls, f.total, f.least, f.farthest, f.largest, f.lo, f.hi)


def integrate_velocities(f: SoftFrame) -> None:
    """v += a·h, ω += α·h under the force terms (gravity, drag)."""
    live = f.live
    lin, ang = column_accelerations(f.terms, f.constant, f.x[:, live], f.vw[:, live], f.q)
    f.vw[:3, live] += lin * f.h
    f.vw[3:, live] += ang * f.h


def warm_start(f: SoftFrame) -> None:
    """Apply the accumulated impulses again."""
    jacobi.apply(f.k, f.vw, f.k.push, f.normal, f.tangential)


def solve(f: SoftFrame, i: int) -> None:
    """The soft-biased solve of substep ``i``: a speculative contact (s > 0) may close by at most s, an
    overlapping one is a soft spring pushing at most MAX_PUSH (module docstring). Each ball's mass is
    split among the contacts that can push this substep: pressed already, or closing faster than their
    gap."""
    k, vw, h = f.k, f.vw, f.h
    s = f.separation(i * h)
    # s + PUSH_AHEAD·min(v_n, 0)·h < 0; v_n is also the first sweep's (the velocities are the same
    # then), handed over in a list that the sweeps empty, so that no frame holds it after that sweep
    speeds = [k.normal_speeds(vw)]
    ahead = np.minimum(speeds[0], 0.0)
    ahead *= PUSH_AHEAD
    ahead *= h
    np.add(s, ahead, out=ahead)
    pushing = ahead < 0.0
    pushing |= f.normal > 0.0
    del ahead
    k.split(pushing)
    del pushing
    speculative = s > 0.0
    # target = −s/h where speculative, else min(−(bias rate)·(s − apart), MAX_PUSH)
    target = s - f.apart
    rate = f.soft("bias_rate")
    target *= np.negative(rate, out=rate)
    del rate
    np.minimum(target, MAX_PUSH, out=target)
    np.divide(s, -h, out=target, where=speculative)
    del s
    # the sweeps' m_n·scale and give·m_n·(1/m_n unsplit), each formed in its own array
    m_n = f.soft("mass_scale")
    np.copyto(m_n, 1.0, where=speculative)
    m_n *= k.m_n
    give = f.soft("impulse_scale")
    np.copyto(give, 0.0, where=speculative)
    del speculative
    give *= k.m_n
    give *= k.whole
    terms = [target, m_n, give]  # the sweeps let go of them before the last adds its changes
    del target, m_n, give
    f.sweeps(terms, SOLVE_SWEEPS, speeds=speeds)


def integrate_positions(f: SoftFrame) -> None:
    """x += v·h and q ← normalise(q + h·½·(ω, 0)⊗q); then what the checks need: each ball's largest move
    in a substep, how far it got from where it started, and the box around where it has been."""
    live = f.live
    x = f.x[:, live]
    before = x.copy()
    x += f.vw[:3, live] * f.h
    f.moved()
    quaternion.turn(f.q, f.vw[3:, live], f.h)
    moved = np.subtract(x, before, out=before)  # its squares then formed in place (norm_cols)
    length = np.empty(x.shape[1])
    np.maximum(f.largest[live], exact.norm_cols(moved, moved, length), out=f.largest[live])
    np.subtract(x, f.start(), out=moved)
    np.maximum(f.farthest[live], exact.norm_cols(moved, moved, length), out=f.farthest[live])
    np.minimum(f.lo, x, out=f.lo)
    np.maximum(f.hi, x, out=f.hi)


def relax(f: SoftFrame, i: int) -> None:
    """Solve again without the bias, so the push-out moves positions but leaves no velocity; the least
    separation seen, and the substep's impulses added to the frame's."""
    s = f.separation((i + 1) * f.h, keep=True)  # the next substep's solve (or moving apart) reads it too
    np.minimum(f.least, s, out=f.least)
    target = np.empty(len(s))
    target.fill(0.0)
    np.divide(s, -f.h, out=target, where=s > 0.0)  # −s/h where speculative
    del s
    # the soft update with mass scale 1 and no give, ΔP = m_n·(target − v_n): m_n·1 is m_n, and a give
    # of 0·P takes nothing from a finite P (and P − 0 is P), so the split m_n alone, with no (K,) arrays
    # of m_n·1 and 0·m_n·(1/m_n)
    terms = [target]
    del target
    f.sweeps(terms, RELAX_SWEEPS)
    f.total += f.normal


def restitution(f: SoftFrame, model: Model, state: State, threshold: float) -> np.ndarray:
    """The frame's impacts, by the rule of the split step (impacts in waves, ``impacts.waves_from``):
    when a contact that pushed during the frame closed faster than ``threshold`` at its start, the
    waves are run from those starting normal speeds over the contacts that pushed, and the contacts
    they struck, with the pushing ones beside them, are driven to the normal speeds the waves left,
    v_n ≥ max(v_n,waves, 0). So a contact alone in its wave leaves at −e·v_n₀ (Box2D's restitution), and
    a touching chain struck inside a pile passes the impulse ball by ball. The solve starts from the
    last substep's normal impulses (which it may take back, never below zero); normal impulses only, to
    convergence (``impacts.normal_solve``). Returns the impulse added per contact (also in ``total``)."""
    rows, k, normal, pressed = f.rows, f.k, f.normal, f.total > 0.0
    added = np.zeros(len(normal))
    vn_start = f.start_speeds(state)
    if (pressed & (vn_start < -threshold) & (rows.restitution > 0.0)).any():
        rows.recall_masses()  # the waves' Gauss–Seidel solves read them per contact
        after, struck = impacts.waves_from(model, rows, k, f.vw, vn_start, threshold, pressed)
        # the pressed contacts beside a struck one take part too: a ball the waves left still holds on them
        touched = np.zeros(k.m, bool)
        touched[k.ends[: k.k][struck]] = True
        touched[k.ends[k.k :][struck]] = True
        if k.balls[-1] == rows.static:
            touched[-1] = False
        near = struck | (pressed & (touched[k.ends[: k.k]] | touched[k.ends[k.k :]]))
        bouncing = np.flatnonzero(near)
        start = normal[bouncing]
        acc = impacts.normal_solve(rows, k, f.vw, bouncing, start, np.maximum(after[bouncing], 0.0))
        added[bouncing] = acc - start
    f.total += added
    return added


def store_impulses(
    f: SoftFrame,
    model: Model,
    state: State,
    warm: WarmStart,
    added: np.ndarray,
    before_write: Callable[[], np.ndarray] | None = None,
) -> None:
    """Keep the impulses for the next frame's warm start, and write the balls back into the state
    (calling ``before_write`` first).

    A level contact (its normal within LEVEL of square to gravity: it holds up no weight) that the
    restitution ``added`` to keeps no more warm start than it came with: its last substep's impulse was
    the impact's compression, which warm-started again would push apart the balls the waves left
    still."""
    g, n = model.gravity, f.n
    level = np.abs(exact.dot_cols(g, n)) <= LEVEL * exact.norm_rows(g)
    bounced = (added != 0.0) & level
    kept = np.where(bounced, np.minimum(f.normal, f.came_with(warm)), f.normal) if bounced.any() else f.normal
    # what follows needs of the solve only each contact's 1/m_n: its columns and scratch go now, before
    # the undo copies the balls and the warm start makes its own sorted copies of the impulses
    f.whole = f.k.whole
    f.inv_mass = f.k.inverse[0].copy()  # each ball's 1/m, as moving apart reads it
    f.k = None
    # the warm start's sorted copies first, and the frame's (2, 3, K) block let go, before the undo
    # copies the balls (104 bytes a ball): the copy then takes the block's room instead of more heap
    tangential, f.tangential = f.tangential, None
    f.kept_order = warm.keep(f.keys(), Impulses(kept, tangential[0].T, tangential[1].T), f.h)
    del tangential, kept
    f.keep_start(before_write() if before_write is not None else None)
    body, idx, live = state.body, f.idx, f.live
    body[idx, X] = f.x[:, live].T
    body[idx, V] = f.vw[:3, live].T
    body[idx, W] = f.vw[3:, live].T
    body[idx, Q] = f.q
    f.vw = f.q = None
    # what moving apart reads of the rows: the bodies, the inverse masses and the planes' surfaces
    f.rows = replace(f.rows, **dict.fromkeys(_ROWS_DONE))
