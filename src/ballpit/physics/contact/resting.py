"""The resting solve: constant contact forces over an interval that leave every touching contact not
approaching and not slipping beyond the friction cone at the interval's end.

Solving for end-of-interval velocities and applying the impulses as constant forces keeps the
integrators exact: a resting ball's force cancels gravity, so it reports zero velocity.

The solve is warm-started from the forces of the last interval, looked up by each pair's own identity
(``contacts.pair_keys``), so a contact never picks up another pair's force when balls are added.
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.contacts import ContactPoints, EventLog
from ..core.settings import (
    HELD_ALONG,
    HOLD_LAYERS,
    HOLD_PASSES,
    HOLD_SINK,
    JACOBI_FROM,
    NEW_DIRECTION,
    WARM_START_SPAN,
)
from ..core.state import State, V, W, with_static
from ..dynamics.forces import ConstantPerBall
from ..dynamics.model import Model
from . import solver
from .rows import ContactRows, rows_at_end
from .warm_start import WarmStart


def resting_forces(
    model: Model,
    state: State,
    c: ContactPoints,
    rows: ContactRows,
    lin: np.ndarray,
    ang: np.ndarray,
    h: float,
    dt: float,
    min_normal_speed: np.ndarray,
    warm: WarmStart,
    events: EventLog,
    now: float,
    jacobi_from: int = JACOBI_FROM,
) -> ConstantPerBall | None:
    """Constant contact forces over the next ``h`` seconds that leave each contact's normal speed at
    least ``min_normal_speed`` (0 for a touching contact, −gap/dt for a speculative one) at the
    interval's end.

    ``lin`` and ``ang`` are the free accelerations. The forces warm-start the next solve only when
    ``h`` is at least WARM_START_SPAN of the step ``dt``: the force that stops a slow arrival in the last
    sliver of a step is no force to hold for the next whole step. Warm-started with it, a column of
    balls is pre-stressed: the impulses cancel ball by ball, so the sweeps see nothing to correct until
    the stress reaches the top.
    """
    if len(c) == 0:
        return None
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    v[:-1] += lin * h
    w[:-1] += ang * h
    v_free, w_free = v.copy(), w.copy()
    keys = c.keys()
    imp = warm.impulses(keys, c.normal, h)
    if rows.moving and np.count_nonzero(model.plane_spin()):  # the contacts at the interval's end
        rows = rows_at_end(model, state, c, rows, lin, h, imp)
    solver.warm_start(rows, v, w, imp)
    solver.solve(rows, v, w, min_normal_speed, imp, model.solver_iterations, jacobi_from=jacobi_from)
    hold_by_planes(
        rows,
        c.gap,
        model.spheres.radius,
        with_static(state.body[:, V]),
        v,
        min_normal_speed,
        imp.normal,
        h,
        model.integrator.bend,
    )
    if h >= WARM_START_SPAN * dt:
        warm.keep(keys, imp, h)
    events.add_resting(now, c, keys, imp.normal)
    return ConstantPerBall((v[:-1] - v_free[:-1]) / h, (w[:-1] - w_free[:-1]) / h)


def workless_targets(rows: ContactRows, state: State, bend: float) -> np.ndarray:
    """Each touching contact's least normal speed at the interval's end: 0, or for a contact already
    separating at v_n0 > 0, the closing speed at which it ends the interval where it began.

    A constant force moves a contact along its normal by h·((1 − b/2)·v_n0 + (b/2)·v_n1) on a path of
    bend b (``hold_by_planes``), and the solve's impulse J does that displacement's work. Brought to
    v_n1 = 0, a slowly separating contact that gravity closes rises h·(1 − b/2)·v_n0 under a pushing
    force: work J·v_n0/2 > 0 for RK2 and RK4, energy a closed elastic box gains. Held at
    v_n1 = −v_n0·(2 − b)/b it ends where it began, and the force does no work. Explicit Euler
    (b = 0) moves by v_n0 whatever v_n1 is, so its targets stay 0, and so do a moving plane's
    contacts: the plane does work of its own, and a turning one is not where it was at the end.
    """
    if bend == 0.0:
        return np.zeros(len(rows))
    vn0 = rows.normal_speeds(with_static(state.body[:, V]))
    target = np.minimum(vn0 * ((0.5 * bend - 1.0) / (0.5 * bend)), 0.0)
    if rows.moving:
        target[(rows.surface != 0.0).any(axis=1) | (rows.spin != 0.0).any(axis=1)] = 0.0
    return target


def hold_by_planes(
    rows: ContactRows,
    gap: np.ndarray,
    radius: np.ndarray,
    v_start: np.ndarray,
    v: np.ndarray,
    target: np.ndarray,
    normal: np.ndarray,
    h: float,
    bend: float = 1.0,
) -> None:
    """Planes win: no ball the solve left sinking into a plane it touches by more than HOLD_SINK of its
    radius over the interval is let sink at all, nor is a chain of balls pressing it. ``v_start`` and
    ``v`` (N+1, 3) are the velocities at the interval's start and end (the end changes in place),
    ``normal`` the accumulated normal impulses (changed in place), ``target`` each contact's least
    normal speed at the end, ``bend`` the integrator's (integrators.Integrator.bend).

    Under a constant force a ball moves h·((1 − b/2)·v_n0 + (b/2)·v_n1) along a normal over the
    interval on a path of bend b: the mean of the two speeds for RK2 and RK4, the start speed for
    explicit Euler, the end speed for symplectic Euler. Gauss–Seidel hands momentum through a light ball
    pressed between a heavy ball and a wall at about m_light/m_heavy a sweep, so at a mass ratio of 47
    its sweeps left the light ball sinking a quarter of its radius a step, and the heavy ball pushed it
    through the wall. Such a ball is held:

    1. its plane contacts (and those on sleeping balls: every contact whose far side has no inverse
       mass) are driven to their target, the ball alone moving (impulses only added: a hold pushes);
    2. a ball pressing a held ball meets it as a ball that can move only along what holds it: the held
       ball's inverse mass along the contact normal n is |P·n|²/m, P the projection off the directions
       it is held in (the normals of the planes now pushing it, made orthonormal). The impulse
       J = (target − v_n)/(1/m_a' + 1/m_b') stops the approach, and like any inelastic impulse it adds
       no energy. A ball that pressed a held ball is held in turn, along the normals its held ball
       cannot follow (|P·n|² ≤ ½), and the balls pressing it are met the same way, layer by layer
       (a heavy ball on a medium one on a light one against a wall);
    3. the whole impulse J·n acts on both balls, so a held ball is pushed towards what holds it: the
       layers' contacts are driven to their target again from the top down, and last the planes of
       every ball the hold moved (planes win). They take off a held ball the part of J they bear, so
       the kept impulses balance (the next interval's warm start pushes the held ball into its planes
       and its planes back).
    """
    static = (rows.inv_mass_b == 0.0) & (rows.inv_mass_a > 0.0)
    if not np.count_nonzero(static):
        return
    vn0, vn1 = rows.normal_speeds(v_start), rows.normal_speeds(v)
    r = radius[rows.a]
    if bend == 1.0:
        sink = 0.5 * h * (vn0 + vn1)
    else:
        sink = h * ((1.0 - 0.5 * bend) * vn0 + (0.5 * bend) * vn1)
    deeper = static & (gap + sink < np.minimum(gap, 0.0) - HOLD_SINK * r)
    if not np.count_nonzero(deeper):
        return
    balls = len(v)
    held = np.zeros(balls, bool)
    held[rows.a[deeper]] = True
    planes = (static & held[rows.a]).nonzero()[0]
    _push_off_planes(rows, v, target, normal, planes)
    moved = _hold_in_layers(rows, static, held, planes[normal[planes] > 0.0], v, target, normal)
    last = (static & moved[rows.a]).nonzero()[0]
    for _ in range(HOLD_PASSES):  # one is exact against square walls; a few for planes at an angle
        _push_off_planes(rows, v, target, normal, last)


def _hold_in_layers(
    rows: ContactRows,
    static: np.ndarray,
    held: np.ndarray,
    pushing: np.ndarray,
    v: np.ndarray,
    target: np.ndarray,
    normal: np.ndarray,
) -> np.ndarray:
    """Steps 2 and 3 of ``hold_by_planes``: the balls pressing the ``held`` ones (held by the plane
    contacts ``pushing``), layer by layer, then the layers again from the top down. ``held`` grows in
    place; returns which balls the hold moved."""
    balls = len(v)
    # the directions each held ball is held in, made orthonormal (at most three): first the normals of
    # the planes pushing it
    slot = np.full(balls, -1)
    slot[held.nonzero()[0]] = np.arange(np.count_nonzero(held))
    basis = np.zeros((np.count_nonzero(held), 3, 3))
    count = np.zeros(len(basis), np.intp)
    for group in rows.subset(pushing).colours:  # one contact per ball in each colour
        _hold_along(basis, count, slot[rows.a[pushing[group]]], rows.normal[pushing[group]])
    moved = held.copy()
    newest, done, layers = held.copy(), static.copy(), []
    for _ in range(HOLD_LAYERS):
        pressed = (~done & (newest[rows.a] | newest[rows.b])).nonzero()[0]
        if pressed.size == 0:
            break
        done[pressed] = True
        layers.append(pressed)
        j = _press(rows, pressed, held, basis, slot, v, target, normal, moved)
        # the balls that pressed a held ball are held in turn, along the normals it cannot follow
        a, b, nk = rows.a[pressed], rows.b[pressed], rows.normal[pressed]
        new_a = (j > 0.0) & ~held[a] & held[b] & (_free_part(basis[slot[b]], nk) <= 0.5)
        new_b = (j > 0.0) & ~held[b] & held[a] & (_free_part(basis[slot[a]], nk) <= 0.5)
        fresh = np.zeros(balls, bool)
        fresh[a[new_a]] = True
        fresh[b[new_b]] = True
        if not np.count_nonzero(fresh):
            break
        grown = fresh.nonzero()[0]
        slot[grown] = len(basis) + np.arange(len(grown))
        basis = np.concatenate((basis, np.zeros((len(grown), 3, 3))))
        count = np.concatenate((count, np.zeros(len(grown), np.intp)))
        ends = np.concatenate((a[new_a], b[new_b]))
        normals = np.concatenate((nk[new_a], nk[new_b]))
        joining = pressed[np.concatenate((new_a.nonzero()[0], new_b.nonzero()[0]))]
        for group in rows.subset(joining).colours:  # one contact per ball in each colour
            _hold_along(basis, count, slot[ends[group]], normals[group])
        held |= fresh
        newest = fresh
    for pressed in reversed(layers[:-1] if len(layers) > 1 else []):  # from the top down
        _press(rows, pressed, held, basis, slot, v, target, normal, moved)
    return moved


def _free_part(basis: np.ndarray, n: np.ndarray) -> np.ndarray:
    """|P·n|²: how much of each unit normal ``n`` a held ball (held along the rows of ``basis``) can
    follow."""
    u = _off(basis, n)
    return exact.dot_rows(u, u)


def _hold_along(basis: np.ndarray, count: np.ndarray, k: np.ndarray, n: np.ndarray) -> None:
    """Add the directions ``n`` (one per row; the rows ``k`` of ``basis`` all different) to the held
    directions, made orthonormal, where they are not already within them."""
    u = _off(basis[k], n)
    length = exact.norm_rows(u)
    ok = (length > NEW_DIRECTION) & (count[k] < 3)
    k = k[ok]
    basis[k, count[k]] = u[ok] / length[ok, None]
    count[k] += 1


def _press(
    rows: ContactRows,
    pressed: np.ndarray,
    held: np.ndarray,
    basis: np.ndarray,
    slot: np.ndarray,
    v: np.ndarray,
    target: np.ndarray,
    normal: np.ndarray,
    moved: np.ndarray,
) -> np.ndarray:
    """Drive the contacts ``pressed`` up to their target, colour by colour, a held end meeting the
    impulse with its inverse mass along the normal only (|P·n|²/m); the whole impulse acts on both
    balls. Returns each contact's impulse (the balls it moved are marked in ``moved``)."""
    n = rows.normal
    out = np.zeros(len(pressed))
    sub = rows.subset(pressed)
    for group in sub.colours:
        idx = pressed[group]
        a, b, nk = rows.a[idx], rows.b[idx], n[idx]
        # each end's normal speed change per unit impulse: 1/m, or |P·n|²/m for a held ball
        pa = np.where(held[a, None], _off(basis[slot[a]], nk), nk)
        pb = np.where(held[b, None], _off(basis[slot[b]], nk), nk)
        dot = exact.dot_rows
        inverse = dot(pa, pa) * rows.inv_mass_a[idx] + dot(pb, pb) * rows.inv_mass_b[idx]
        closing = np.maximum(target[idx] - dot(v[a] - v[b], nk), 0.0)
        # both ends held along n (rounding leaves |P·n|² of 1e-17, not 0): nothing can give
        free = inverse > HELD_ALONG * (rows.inv_mass_a[idx] + rows.inv_mass_b[idx])
        j = np.where(free, closing / np.where(free, inverse, 1.0), 0.0)
        normal[idx] += j
        out[group] = j
        # a held end moves only along what holds it (P·n): what holds it takes the rest
        v[a] += (j * rows.inv_mass_a[idx])[:, None] * pa
        v[b] -= (j * rows.inv_mass_b[idx])[:, None] * pb
        moved[a[j > 0.0]] = True
        moved[b[j > 0.0]] = True
    v[-1] = 0.0
    return out


def _off(basis: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Each row of ``n`` (K, 3) less its parts along the rows of ``basis`` (K, 3, 3; orthonormal rows,
    or zero rows), taken one after another."""
    u = n.copy()
    for j in range(3):
        e = basis[:, j]
        u = u - exact.dot_rows(u, e)[:, None] * e
    return u


def _push_off_planes(
    rows: ContactRows, v: np.ndarray, target: np.ndarray, normal: np.ndarray, idx: np.ndarray
) -> None:
    """Drive the contacts ``idx`` (each against a body of no inverse mass) up to their target normal
    speed by moving their ball alone, colour by colour; impulses are only added."""
    if idx.size == 0:
        return
    for group in rows.subset(idx).colours:
        k = idx[group]
        a = rows.a[k]
        j = np.maximum(target[k] - rows.normal_speeds(v, k), 0.0) / rows.inv_mass_a[k]
        normal[k] += j
        v[a] += (j * rows.inv_mass_a[k])[:, None] * rows.normal[k]
