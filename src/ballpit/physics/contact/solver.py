"""Contact impulses: a projected Gauss–Seidel (sequential impulse) solve, vectorised by colour.

Each contact's normal impulse, friction and rolling resistance are updated in turn with
accumulated-impulse clamping, by the contact model (contact_model.py); Gauss–Seidel order holds
between colours. Contacts that share no ball are independent, so they are grouped into colours
(rows.py) and each colour is one set of array operations. From JACOBI_FROM contacts on (a pile),
``solve`` hands the same contact model to ``jacobi.py``, which updates every contact at once per sweep.

Balls are rows 0…N−1 of the velocity arrays; row N is the static world (planes), with zero inverse
mass, so a sphere–plane contact is a sphere–sphere contact whose second body never moves.
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.settings import CONVERGED, JACOBI_FRICTION_EVERY, JACOBI_FROM, JACOBI_SWEEPS
from . import contact_model as model
from . import jacobi
from .contact_model import Impulses
from .ends import Ends
from .rows import ContactRows

_SIX = np.arange(6)
# (Maxima here are np.maximum.reduce: ndarray.max's Python wrapper costs more than a few contacts' max.)


class _Colour:
    """One colour's contacts, gathered once per solve so the sweeps only touch velocities.

    Velocities are the columns of one (6, M) array [v; ω] holding just the balls the solve touches; a
    colour gathers its a and b columns with one ``np.take`` each and writes them back in one go.
    """

    def __init__(self, contacts: ContactRows, idx: np.ndarray, ends: np.ndarray) -> None:
        k = len(contacts)
        self.idx = idx
        self.a, self.b = ends[idx], ends[k + idx]
        self.n = np.ascontiguousarray(contacts.normal[idx].T)
        self.ra, self.rb = contacts.arm_lengths(idx)
        self.ima, self.imb = contacts.inv_mass_a[idx], contacts.inv_mass_b[idx]
        self.iia, self.iib = contacts.inv_inertia_a[idx], contacts.inv_inertia_b[idx]
        inverse = model.inverse_effective_masses(self.ima, self.imb, self.iia, self.iib, self.ra, self.rb)
        self.m_n, self.m_t, self.m_r = (1.0 / part for part in inverse)
        # what a unit of tangential impulse turns each ball by (Δω = −ρ·I⁻¹·(n × P_t))
        self.turn_a, self.turn_b = -(self.ra * self.iia), -(self.rb * self.iib)
        # bounds on how much a unit of impulse changes a contact's velocity, for the convergence test
        self.max_inv_m_n, self.max_inv_m_t = (
            float(np.maximum.reduce(inverse[0])),
            float(np.maximum.reduce(inverse[1])),
        )
        self.mu = contacts.friction[idx]
        self.rolling = contacts.rolling[idx]
        self.surface = np.ascontiguousarray(contacts.surface[idx].T) if contacts.moving else None
        self.spin = np.ascontiguousarray(contacts.spin[idx].T) if contacts.moving else None
        self.has_friction = bool(np.count_nonzero(self.mu))
        self.has_rolling = bool(np.count_nonzero(self.rolling))
        # how a unit of friction's turn changes the relative spin (c = ρ_a/I_a − ρ_b/I_b), and a bound
        # on the surface speed a unit of rolling impulse changes (|ΔΩ|·ρ), for the convergence test
        self.lever = self.ra * self.iia - self.rb * self.iib
        self.max_roll = float(np.maximum.reduce(self.iia * self.ra + self.iib * self.rb))
        # friction and rolling resistance solved as one block where both hold (``model.stick``)
        stick = None
        if self.has_friction and self.has_rolling:
            stick = model.stick_terms(self.ima, self.imb, self.iia, self.iib, self.ra, self.rb)
        # The factors the sweeps multiply into (3, K) vectors, as (3, K) rows holding the same values
        # (made in one go): a (K,) factor broadcast over three rows costs a NumPy call about three
        # times a plain one.
        factors = [self.ra, self.rb, self.ima, self.imb, self.iia, self.iib]
        factors += [self.m_t, self.m_r, self.turn_a, self.turn_b, self.lever, *(stick or ())]
        rows = np.repeat(np.array(factors)[:, None, :], 3, axis=1)
        self.ra, self.rb, self.ima, self.imb, self.iia, self.iib = rows[:6]
        self.m_t, self.m_r, self.turn_a, self.turn_b, self.lever = rows[6:11]
        self.stick = None if stick is None else model.StickTerms(*rows[11:])


def warm_start(contacts: ContactRows, v: np.ndarray, w: np.ndarray, imp: Impulses) -> None:
    """Apply impulses carried over from the previous interval before iterating."""
    if len(contacts) == 0:
        return
    n = contacts.normal.T
    friction, rolling = imp.friction.T, imp.rolling.T
    linear = imp.normal * n + friction
    turn = model.turn(n, friction)
    ra, rb = contacts.arm_lengths()
    rows, k = len(v), len(contacts)
    change = np.empty((k, 6))  # each contact's [Δv Δω] on one of its bodies, a row each
    for body, sign, im, ii, r in (
        (contacts.a, 1.0, contacts.inv_mass_a, contacts.inv_inertia_a, ra),
        (contacts.b, -1.0, contacts.inv_mass_b, contacts.inv_inertia_b, rb),
    ):
        change[:, :3] = (sign * linear * im).T
        change[:, 3:] = ((-r * turn + sign * rolling) * ii).T
        # one bincount for all six columns (bin 6·ball + column): each bin sums its contacts in their
        # order from zero, as a bincount per column does
        bins = (body[:, None] * 6 + _SIX).ravel()
        sums = np.bincount(bins, change.ravel(), minlength=6 * rows).reshape(rows, 6)
        v += sums[:, :3]
        w += sums[:, 3:]
    v[-1] = 0.0
    w[-1] = 0.0


def solve(
    contacts: ContactRows,
    v: np.ndarray,
    w: np.ndarray,
    target: np.ndarray,
    imp: Impulses,
    iterations: int,
    jacobi_sweeps: int = JACOBI_SWEEPS,
    friction_every: int = JACOBI_FRICTION_EVERY,
    jacobi_from: int = JACOBI_FROM,
) -> Impulses:
    """Projected Gauss–Seidel: drive every contact's normal speed to ≥ ``target`` with friction and
    rolling resistance; ``v`` and ``w`` (N+1, 3) change in place, ``imp`` accumulates. From
    ``jacobi_from`` contacts on, ``jacobi_sweeps`` Jacobi sweeps stand for each iteration, and only every
    ``friction_every``-th of them updates friction (see ``jacobi.solve``)."""
    if len(contacts) == 0:
        return imp
    if len(contacts) >= jacobi_from:
        return jacobi.solve(contacts, v, w, target, imp, jacobi_sweeps * iterations, friction_every)
    # Work on a compact copy of just the balls these contacts touch: an island's solve costs what
    # the island does, not what the world does.
    ends = Ends(contacts.a, contacts.b)
    vw = np.ascontiguousarray(np.concatenate((v[ends.balls], w[ends.balls]), axis=1).T)  # (6, M)
    colours = [_Colour(contacts, idx, ends.ends) for idx in contacts.colours]
    targets = [target[c.idx] for c in colours]
    normal = [imp.normal[c.idx] for c in colours]
    friction = [np.ascontiguousarray(imp.friction[c.idx].T) for c in colours]
    rolling = [np.ascontiguousarray(imp.rolling[c.idx].T) for c in colours]
    # with no friction and no rolling resistance anywhere no sweep turns a ball: each colour's n × lever
    # is the same in every sweep, formed once (``_sweep_smooth``)
    smooth = not any(c.has_friction or c.has_rolling for c in colours)
    turns = [_spin_turn(c, vw) for c in colours] if smooth else None
    for _ in range(iterations):
        change = 0.0  # a bound on the largest velocity change this sweep made at any contact (m/s)
        for k, c in enumerate(colours):
            if turns is not None:
                found = _sweep_smooth(c, vw, turns[k], targets[k], normal, k)
            else:
                found = _sweep_colour(c, vw, targets[k], normal, friction, rolling, k)
            change = max(change, found)
        if change < CONVERGED:
            break
    v[ends.balls] = vw[:3].T
    w[ends.balls] = vw[3:].T
    v[-1] = 0.0
    w[-1] = 0.0
    for k, c in enumerate(colours):
        imp.normal[c.idx] = normal[k]
        imp.friction[c.idx] = friction[k].T
        imp.rolling[c.idx] = rolling[k].T
    return imp


def _spin_turn(c: _Colour, vw: np.ndarray) -> np.ndarray:
    """n × (ρ_a·ω_a + ρ_b·ω_b) of the colour ``c``: what the balls' spins add to its contact-point
    velocities (``contact_model.contact_velocity``), by the same operations."""
    w = vw[3:]
    return exact.cross_cols(c.n, model.spin_lever(w.take(c.a, axis=1), w.take(c.b, axis=1), c.ra, c.rb))


def _sweep_smooth(
    c: _Colour, vw: np.ndarray, turn: np.ndarray, target: np.ndarray, normal: list, k: int
) -> float:
    """``_sweep_colour`` of a solve with no friction and no rolling resistance: the normal impulse
    alone, which never turns a ball, so the spins' ``turn`` (``_spin_turn``) is formed once a solve.
    The same operations on the velocities as ``_sweep_colour``'s, and the same bound returned."""
    v = vw[:3]
    va, vb = v.take(c.a, axis=1), v.take(c.b, axis=1)
    rel = model.point_velocity(va - vb, None, c.n, c.surface, turn)
    d_n, linear = _normal_update(c, exact.dot_cols_in_place(rel, c.n), target, normal, k)
    va += c.ima * linear
    vb -= c.imb * linear
    v[:, c.a] = va
    v[:, c.b] = vb
    return float(np.maximum.reduce(np.abs(d_n), axis=None)) * c.max_inv_m_n


def _normal_update(
    c: _Colour, vn: np.ndarray, target: np.ndarray, normal: list, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """The colour's new normal impulses from its normal speeds ``vn``, into ``normal[k]``; returns
    their change d_n and the linear impulse d_n·n it adds."""
    old = normal[k]
    new = model.normal_impulse(old, c.m_n, target, vn)
    normal[k] = new
    d_n = new - old
    return d_n, d_n * c.n


def _sweep_colour(
    c: _Colour, vw: np.ndarray, target: np.ndarray, normal: list, friction: list, rolling: list, k: int
) -> float:
    """One colour's update, in Gauss–Seidel order within each contact: normal impulse, then friction,
    then rolling resistance (from the spin friction left). Returns a bound on the largest velocity
    change it made (m/s)."""
    ga, gb = vw.take(c.a, axis=1), vw.take(c.b, axis=1)
    va, wa, vb, wb = ga[:3], ga[3:], gb[:3], gb[3:]
    rel = model.contact_velocity(va, wa, vb, wb, c.n, c.ra, c.rb, c.surface)
    vn = exact.dot_cols(rel, c.n)
    d_n, linear = _normal_update(c, vn, target, normal, k)
    new = normal[k]
    change = float(np.maximum.reduce(np.abs(d_n), axis=None)) * c.max_inv_m_n

    if c.has_friction and c.has_rolling:
        # friction and rolling resistance together: where both stay within their limits the block
        # stops slip and relative spin at once (a ball coming to rest stops); elsewhere one after the
        # other, as below
        slip = rel - vn * c.n
        spin = wa - wb if c.spin is None else wa - wb - c.spin
        old_t, old_r = friction[k], rolling[k]
        cone, limit = c.mu * new, c.rolling * new
        p = model.block_friction(slip, spin, c.n, c.stick)
        block_t = old_t + p
        held = exact.dot_cols(block_t, block_t) <= cone**2
        if np.count_nonzero(held):  # the block's rolling impulse matters only where its friction holds
            block_r = old_r + model.block_rolling(p, spin, c.n, c.stick)
            held &= exact.dot_cols(block_r, block_r) <= limit**2
        new_t = model.within_limit(old_t - c.m_t * slip, cone)
        d_t = new_t - old_t
        turn = model.turn(c.n, d_t)
        spin -= c.lever * turn  # the relative spin after that friction's turn
        new_r = model.within_limit(old_r - c.m_r * spin, limit)
        if np.count_nonzero(held):  # (else the friction and its turn stay as found)
            new_t, new_r = np.where(held, block_t, new_t), np.where(held, block_r, new_r)
            d_t = new_t - old_t
            turn = model.turn(c.n, d_t)
        friction[k], rolling[k] = new_t, new_r
        d_r = new_r - old_r
        linear += d_t
        wa += c.turn_a * turn + c.iia * d_r
        wb += c.turn_b * turn - c.iib * d_r
        change = max(
            change,
            float(np.maximum.reduce(np.abs(d_t), axis=None)) * c.max_inv_m_t,
            float(np.maximum.reduce(np.abs(d_r), axis=None)) * c.max_roll,
        )
    elif c.has_friction:
        # friction cancels slip (the tangential part of rel, which the normal impulse leaves alone)
        old_t = friction[k]
        new_t = model.within_limit(old_t - c.m_t * (rel - vn * c.n), c.mu * new)
        friction[k] = new_t
        d_t = new_t - old_t
        linear += d_t
        turn = model.turn(c.n, d_t)
        wa += c.turn_a * turn
        wb += c.turn_b * turn
        change = max(change, float(np.maximum.reduce(np.abs(d_t), axis=None)) * c.max_inv_m_t)
    elif c.has_rolling:
        # rolling resistance opposes relative spin, up to ρ_roll·P_n
        old_r = rolling[k]
        spin = wa - wb if c.spin is None else wa - wb - c.spin
        new_r = model.within_limit(old_r - c.m_r * spin, c.rolling * new)
        rolling[k] = new_r
        d_r = new_r - old_r
        wa += c.iia * d_r
        wb -= c.iib * d_r
        change = max(change, float(np.maximum.reduce(np.abs(d_r), axis=None)) * c.max_roll)

    va += c.ima * linear
    vb -= c.imb * linear
    vw[:, c.a] = ga
    vw[:, c.b] = gb
    return change
