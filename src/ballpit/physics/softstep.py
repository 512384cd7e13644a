"""The crowded step as a frame of substeps: Box2D v3's soft step (E. Catto, "Solver2D", 2024;
Box2D v3 ``solver.c``, ``contact_solver.c``).

Once per frame (one ``World.step``) the speculative contacts are measured and their rows built
(anchors, effective masses, mixed materials, the relative normal velocity at the frame's start). Then
``substeps`` times, with h = dt / substeps:

1. integrate velocities: v += a·h under the force terms (gravity, drag);
2. warm start: apply the accumulated impulses again;
3. solve with a soft bias (below);
4. integrate positions: x += v·h (symplectic Euler, as Box2D: a ball held by a contact moves exactly
   as the solve leaves its velocity, so a resting ball stays put);
5. relax: solve again without the bias, so the push-out moves positions but leaves no velocity.

A contact's separation inside the frame is the one measured at its start plus the balls' moved
positions along the normal, s = s₀ + n·(Δx_a − Δx_b), not a new narrow phase. A contact with s > 0 is
speculative: it may close by at most s this substep, v_n ≥ −s/h. One that overlaps is a soft spring
(Catto, "Soft constraints", GDC 2011): with ω = 2π·f, ζ the damping ratio,

    a₁ = 2ζ + h·ω,  a₂ = h·ω·a₁,  a₃ = 1/(1 + a₂)
    bias rate = ω/a₁,  mass scale = a₂·a₃,  impulse scale = a₃
    ΔP = m_n·(mass scale)·(target − v_n) − (impulse scale)·P,  target = min(−(bias rate)·s, MAX_PUSH)

After the last substep one restitution pass (``restitution_pass``) bounces the contacts that closed
faster than the threshold at the frame's start, and the impulses are kept for the next frame's warm
start. Balls that touch no contact of the frame are left to the world's integrator (free flight keeps
its textbook accuracy); see step/plan.py and step/soft.py for when a frame is taken this way at all and
how its result is checked.

Every sweep updates all contacts at once (projected Jacobi with mass splitting, ``jacobi.py``, over
the contact model of contact_model.py): a substep costs a fixed number of array passes, however many
colours a pile would need. Each ball's mass is split only among its contacts that can push this
substep: a speculative contact still far from closing takes no share, so it does not soften the ones
that carry the load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import energy_guard, impacts, jacobi, penetration, quaternion
from .contact_model import Impulses, dot
from .contacts import ContactPoints
from .forces import ConstantPerBall, ForceTerm, constant_acceleration
from .rows import ContactRows, contact_rows
from .settings import (
    CONTACT_HERTZ,
    DAMPING_RATIO,
    LEVEL,
    MAX_PUSH,
    RELAX_SWEEPS,
    SEPARATE_SWEEPS,
    SLOP,
    SOLVE_SWEEPS,
)
from .state import Q, V, W, X, with_static


@dataclass(frozen=True)
class Softness:
    """A soft constraint's coefficients for a substep h (see the module docstring)."""

    bias_rate: float
    mass_scale: float
    impulse_scale: float


def softness(hertz: float, zeta: float, h: float) -> Softness:
    """Box2D's ``b2MakeSoft``: the spring of frequency ``hertz`` and damping ratio ``zeta`` over h."""
    if hertz == 0.0:
        return Softness(0.0, 1.0, 0.0)
    omega = 2.0 * math.pi * hertz
    a1 = 2.0 * zeta + h * omega
    a2 = h * omega * a1
    a3 = 1.0 / (1.0 + a2)
    return Softness(omega / a1, a2 * a3, a3)


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


def frame(model, state, c: ContactPoints, forces: list[ForceTerm], dt: float, threshold: float, warm,
          substeps: int) -> Frame:  # fmt: skip
    """Advance the balls the contacts ``c`` touch by ``dt`` in ``substeps`` substeps (their
    states change in place; planes and other balls do not move here). ``warm`` (resting.WarmStart) gives
    and keeps the impulses; ``threshold`` is the restitution threshold (m/s)."""
    h = dt / substeps
    n_balls = model.spheres.count
    rows = contact_rows(model, state, c)
    k = jacobi.Contacts(rows)
    body = state.body
    balls = k.balls
    m_dyn = int(np.searchsorted(balls, n_balls))  # the static row N, if there, is the last column
    idx = balls[:m_dyn]
    live = slice(0, m_dyn)
    m = k.m
    x = np.zeros((3, m))
    x[:, live] = body[idx, X].T
    x0 = x.copy()
    vw = np.zeros((6, m))
    vw[:3, live] = body[idx, V].T
    vw[3:, live] = body[idx, W].T
    q = body[idx, Q].copy()
    terms = compact_terms(forces, idx, n_balls)
    constant = constant_acceleration(terms)

    kc = k.k
    n = k.n
    ends_a, ends_b = k.ends[:kc], k.ends[kc:]
    on_plane = rows.b == n_balls
    # the surface's own speed along the normal (moving planes), to move their side of s
    surface_n = dot(k.surface, n) if k.surface is not None else None
    hertz = min(CONTACT_HERTZ, 0.25 / h)
    ball_soft, plane_soft = softness(hertz, DAMPING_RATIO, h), softness(2.0 * hertz, DAMPING_RATIO, h)

    def soft(name: str) -> np.ndarray:  # each contact's coefficient, made when used (not kept: K floats)
        return np.where(on_plane, getattr(plane_soft, name), getattr(ball_soft, name))

    vn_start = _normal_speed(k, vw)  # recorded at the frame's start, for the restitution pass

    keys = c.keys()
    imp = warm.impulses(keys, c.normal, h)
    apart = warm.apart_of(keys)
    normal = imp.normal.copy()
    tangential = np.ascontiguousarray(np.stack((imp.friction, imp.rolling)).transpose(0, 2, 1))
    came_with = imp.normal  # the warm start's normal impulses; its friction and rolling are in tangential
    del imp
    total = np.zeros(kc)
    least = c.gap.copy()
    farthest, largest = np.zeros(m), np.zeros(m)
    lo, hi = x[:, live].copy(), x[:, live].copy()

    for i in range(substeps):
        # 1. integrate velocities
        lin, ang = _accelerations(terms, constant, x[:, live], vw[:, live], q)
        vw[:3, live] += lin * h
        vw[3:, live] += ang * h
        # 2. warm start
        jacobi.apply(k, vw, k.push, normal, tangential)
        # 3. solve with the soft bias
        s = _separation(c.gap, n, x, x0, ends_a, ends_b, surface_n, i * h)
        # the contacts that can push this substep: pressed already, or closing faster than their gap
        k.split((normal > 0.0) | (s + 2.0 * np.minimum(_normal_speed(k, vw), 0.0) * h < 0.0))
        speculative = s > 0.0
        target = np.where(speculative, -s / h, np.minimum(-soft("bias_rate") * (s - apart), MAX_PUSH))
        scale = np.where(speculative, 1.0, soft("mass_scale"))
        give = np.where(speculative, 0.0, soft("impulse_scale"))
        normal, tangential = _soft_sweeps(k, vw, normal, tangential, target, scale, give, SOLVE_SWEEPS)
        del scale, give
        # 4. integrate positions (and orientations)
        before = x[:, live].copy()
        x[:, live] += vw[:3, live] * h
        _turn(q, vw[3:, live], h)
        # 5. relax: no bias, so the push-out leaves no velocity behind
        s = _separation(c.gap, n, x, x0, ends_a, ends_b, surface_n, (i + 1) * h)
        np.minimum(least, s, out=least)
        target = np.where(s > 0.0, -s / h, 0.0)
        normal, tangential = _soft_sweeps(k, vw, normal, tangential, target, 1.0, 0.0, RELAX_SWEEPS)
        total += normal
        # what the checks need: how far each ball got, and where
        moved = x[:, live] - before
        np.maximum(largest[live], _length(moved), out=largest[live])
        del before, moved
        np.maximum(farthest[live], _length(x[:, live] - x0[:, live]), out=farthest[live])
        np.minimum(lo, x[:, live], out=lo)
        np.maximum(hi, x[:, live], out=hi)

    added = restitution_pass(model, rows, k, vw, normal, vn_start, threshold, total > 0.0)
    total += added
    # a level contact (normal within LEVEL of square to gravity: it holds up no weight) that the impacts
    # changed keeps no more warm start than it came with: its last substep's impulse was the impact's
    # compression, which warm-started again would push apart the balls the waves left still (#24)
    g = model.gravity
    level = np.abs(g[0] * n[0] + g[1] * n[1] + g[2] * n[2]) <= LEVEL * math.sqrt(
        g[0] * g[0] + g[1] * g[1] + g[2] * g[2]
    )
    kept = np.where((added != 0.0) & level, np.minimum(normal, came_with), normal)
    del came_with, added, level, vn_start
    warm.keep(keys, Impulses(kept, tangential[0].T.copy(), tangential[1].T.copy()), h)
    body[idx, X] = x[:, live].T
    body[idx, V] = vw[:3, live].T
    body[idx, W] = vw[3:, live].T
    body[idx, Q] = q
    # what follows needs of the solve only each contact's 1/m_n: its scratch and impulses go now, so
    # that moving overlaps apart does not hold them too (the peak memory of a settled pile)
    whole = k.whole
    del k, kept, tangential, vw, q, lin, ang, target, speculative
    # what the substeps left overlapping is moved apart by positions alone (penetration.py)
    # (an overlap the frame began with only as far as MAX_PUSH would have moved it in the frame: a
    # heap of balls created at one point is pushed apart, never launched by a jump of positions)
    s = _separation(c.gap, n, x, x0, ends_a, ends_b, surface_n, dt)
    slop = SLOP * np.where(
        on_plane,
        model.spheres.radius[c.a],
        np.minimum(*(model.spheres.radius[e] for e in (c.a, np.minimum(c.b, n_balls - 1)))),
    )
    made = s - np.minimum(c.gap + MAX_PUSH * dt, -slop)
    if (made < -penetration.OVERLAP_TOLERANCE).any():
        # those deeper than the slop go back to 0.8 of it, so they are not caught again next frame
        made = np.where(made < 0.0, s - np.minimum(c.gap + MAX_PUSH * dt, -0.8 * slop), made)
        # only the contacts a move of up to twice the deepest deficit could reach take part: the others,
        # farther apart than that, cannot be closed by moving these apart
        part = np.flatnonzero(made < -2.0 * made.min())
        pos = with_static(body[:, X])
        normals = np.take(c.normal.T, part, axis=1).T  # laid out as (3, K) columns, as separate reads them
        jacobi.separate(c.a[part], c.b[part], normals, made[part], rows.inv_mass_a[part],
                        rows.inv_mass_b[part], pos, SEPARATE_SWEEPS)  # fmt: skip
        del normals
        new = penetration.keep_sides_of_planes(model, state, body[:, X], pos[:-1])
        energy_guard.pay_for_lift(model, state, body[:, X], new)
        moved = new - body[:, X]
        ma, mb = with_static(moved)[c.a], with_static(moved)[c.b]
        d = ma - mb
        np.minimum(least, s + d[:, 0] * c.normal[:, 0] + d[:, 1] * c.normal[:, 1] + d[:, 2] * c.normal[:, 2],
                   out=least)  # fmt: skip
        body[:, X] = new
    _out_of_planes(model, state, c, rows, least, x0, idx, dt)
    # what the springs hold apart for the next frame: the moving apart by positions, up to the overlap
    # each contact's load needs, s_eq = P·(1/m_a + 1/m_b)·(impulse scale)/((mass scale)·(bias rate))
    x[:, live] = body[idx, X].T
    s_end = _separation(c.gap, n, x, x0, ends_a, ends_b, surface_n, dt)
    s_eq = normal * whole * soft("impulse_scale") / (soft("mass_scale") * soft("bias_rate"))
    held = np.minimum(apart + np.maximum(s_end - s, 0.0), s_eq + s_end)
    warm.keep_apart(keys, np.where(s_end < 0.0, np.maximum(held, 0.0), 0.0))
    return Frame(balls, total, least, farthest, largest, lo, hi)


def _out_of_planes(model, state, c: ContactPoints, rows: ContactRows, least: np.ndarray, x0: np.ndarray,
                   idx: np.ndarray, dt: float) -> None:  # fmt: skip
    """Planes win: a ball the frame left deeper in a plane than it started is moved back out along the
    plane's normal (positions only, paying for the lift as penetration.py does). Shared among all of a
    ball's contacts, the masses split many ways, the solve cannot always hold a crowd off a floor."""
    on = np.flatnonzero(rows.b == model.spheres.count)
    if on.size == 0:
        return
    body = state.body
    start = np.zeros((len(body), 3))
    start[idx] = x0[:, : len(idx)].T
    a, nrm = c.a[on], c.normal[on]
    d = body[a, 0:3] - start[a]
    s = c.gap[on] + d[:, 0] * nrm[:, 0] + d[:, 1] * nrm[:, 1] + d[:, 2] * nrm[:, 2]
    if rows.moving:  # the plane's surface moves on over the frame too
        u = rows.surface[on]
        s -= (u[:, 0] * nrm[:, 0] + u[:, 1] * nrm[:, 1] + u[:, 2] * nrm[:, 2]) * dt
    deficit = np.maximum(np.minimum(c.gap[on], -SLOP * model.spheres.radius[a]) - s, 0.0)
    if not (deficit > penetration.OVERLAP_TOLERANCE).any():
        return
    new = body[:, X].copy()
    lift = np.zeros((len(body), 3))
    np.add.at(lift, a, deficit[:, None] * nrm)
    new += lift
    energy_guard.pay_for_lift(model, state, body[:, X], new)
    body[:, X] = new
    least[on] = np.minimum(least[on], s + deficit)


def restitution_pass(model, rows: ContactRows, k: jacobi.Contacts, vw: np.ndarray, normal: np.ndarray,
                     vn_start: np.ndarray, threshold: float, pressed: np.ndarray) -> np.ndarray:  # fmt: skip
    """The frame's impacts, by the rule of the split step (impacts in waves, ``impacts.waves_from``):
    when a contact that pushed during the frame (``pressed``) closed faster than ``threshold`` at its
    start (``vn_start``), the waves are run from those starting normal speeds over the pressed
    contacts, and the contacts they struck, with the pressed ones beside them, are driven to the normal
    speeds the waves left, v_n ≥ max(v_n,waves, 0). So a contact alone in its wave leaves at −e·v_n₀
    (Box2D's restitution), and a touching chain struck inside a pile passes the impulse ball by ball.
    The solve starts from the last substep's normal impulse ``normal`` (which it may take back, never
    below zero); normal impulses only, to convergence (``impacts.normal_solve``). ``vw`` changes in
    place; returns the impulse added per contact."""
    added = np.zeros(len(normal))
    if not (pressed & (vn_start < -threshold) & (rows.restitution > 0.0)).any():
        return added
    after, struck = impacts.waves_from(model, rows, k, vw, vn_start, threshold, pressed)
    # the pressed contacts beside a struck one take part too: a ball the waves left still holds on them
    touched = np.zeros(k.m, bool)
    touched[k.ends[: k.k][struck]] = True
    touched[k.ends[k.k :][struck]] = True
    if k.balls[-1] == rows.static:
        touched[-1] = False
    near = struck | (pressed & (touched[k.ends[: k.k]] | touched[k.ends[k.k :]]))
    bouncing = np.flatnonzero(near)
    start = normal[bouncing]
    acc = impacts.normal_solve(rows, k, vw, bouncing, start, np.maximum(after[bouncing], 0.0))
    added[bouncing] = acc - start
    return added


def compact_terms(forces: list[ForceTerm], idx: np.ndarray, n_balls: int) -> list[ForceTerm]:
    """The force terms for the balls ``idx`` alone: per-ball constant terms (a sleeping ball's hold)
    cut down to their rows."""
    terms: list[ForceTerm] = []
    for term in forces:
        if isinstance(term, ConstantPerBall) and len(term.lin) == n_balls:
            term = ConstantPerBall(term.lin[idx], term.ang[idx])
        terms.append(term)
    return terms


def _accelerations(terms, constant, x: np.ndarray, vw: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, ...]:
    """Linear and angular accelerations (3, M) of the balls under the force terms, at this state."""
    if constant is not None:
        lin, ang = constant
        return lin.T, ang.T
    state = np.empty((x.shape[1], 13))
    state[:, X], state[:, V], state[:, Q], state[:, W] = x.T, vw[:3].T, q, vw[3:].T
    lin, ang = np.zeros((len(state), 3)), np.zeros((len(state), 3))
    for term in terms:
        term.add(state, lin, ang)
    return lin.T, ang.T


def _normal_speed(k: jacobi.Contacts, vw: np.ndarray) -> np.ndarray:
    """Each contact's relative normal speed v_n = (v_a − v_b)·n (spin does not change it on spheres),
    against a moving plane's surface."""
    return jacobi.normal_speeds(k, vw, k.n, k.surface)


def _length(a: np.ndarray) -> np.ndarray:
    return np.sqrt(dot(a, a))


def _soft_sweeps(k: jacobi.Contacts, vw: np.ndarray, normal: np.ndarray, tangential: np.ndarray,
                 target: np.ndarray, scale: np.ndarray | float, give: np.ndarray | float,
                 sweeps: int) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """``sweeps`` Jacobi sweeps of the soft normal update ΔP = m_n·scale·(target − v_n) − give·P (P ≥ 0);
    the last one also updates friction (the Coulomb cone |P_t| ≤ μ·P_n) and rolling resistance
    (|R| ≤ ρ·r·P_n). ``vw`` changes in place; returns the new accumulated impulses.

    The spring's give, −give·P, is the unsplit contact's: ΔP = m_split·(scale·(target − v_n) −
    give·P/m_whole), so a ball's share of a crowd does not make its contacts softer."""
    return jacobi.sweeps(k, vw, normal, tangential, target, sweeps, friction_every=sweeps,
                         m_n=k.m_n * scale, give=give * k.m_n * k.whole)  # fmt: skip


def _separation(s0: np.ndarray, n: np.ndarray, x: np.ndarray, x0: np.ndarray, ends_a: np.ndarray,
                ends_b: np.ndarray, surface_n: np.ndarray | None, t: float) -> np.ndarray:  # fmt: skip
    """s = s₀ + n·(Δx_a − Δx_b): the separation from the balls' moved positions (and a moving plane's
    surface, moved by its speed along n for ``t``)."""
    d = x - x0
    s = s0 + dot(np.take(d, ends_a, axis=1) - np.take(d, ends_b, axis=1), n)
    if surface_n is not None:
        s -= surface_n * t
    return s


def _turn(q: np.ndarray, w: np.ndarray, h: float) -> None:
    """q ← normalise(q + h·½·(ω, 0)⊗q), in place (``w`` is (3, M))."""
    dq = np.empty_like(q)
    quaternion.derivative(q, w.T, dq)
    q += h * dq
    quaternion.normalize(q, out=q)
