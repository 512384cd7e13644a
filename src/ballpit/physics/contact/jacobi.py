"""Contact impulses for many contacts at once: projected Jacobi with mass splitting.

The colour-by-colour Gauss–Seidel solve (``solver.py``) costs a few dozen NumPy calls per colour per
sweep; a pile has 12–17 colours, so at a thousand balls the calls' fixed cost is most of the step.
Here every contact is updated at once from the same velocities, so a sweep is a fixed number of calls
whatever the colours. The split step's large solves and every solve of the soft step (softstep.py:
its substeps' soft solve and relax, its restitution) are these sweeps.

Plain Jacobi overshoots where several contacts push one ball. Mass splitting (Tonge, Benevolenski
and Voroshilov, "Mass splitting for jitter-free parallel rigid body simulation", SIGGRAPH 2012) gives
each contact a share 1/n_b of a ball with n_b contacts: the contact's effective masses use n_b·m⁻¹ and
n_b·I⁻¹, and averaging the copies of a ball afterwards is the same as adding up every contact's impulse
with the ball's own m⁻¹ and I⁻¹. The iteration then converges to the same solution as Gauss–Seidel and
never overshoots, so a pile rests without jitter.

A normal-only sweep needs only the balls' linear velocities: a sphere's lever arm is parallel to its
contact normal, so spin never changes v_n. It costs about a fifth of a full sweep (normal, friction
and rolling resistance), so a solve may update friction in only some of its sweeps.

The contact model itself (effective masses, the normal impulse, the friction cone and rolling limit,
what an impulse does to the balls) is contact_model.py's, as in ``solver.py``; only the order of the
updates differs.
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.settings import ADD_UP_BINS_UP_TO, CONVERGED
from . import contact_model as model
from .contact_model import Impulses
from .ends import Ends
from .rows import ContactRows


class ContactColumns(Ends):
    """What the sweeps need of the contacts, gathered once per solve, with vectors as (3, K) rows.

    Velocities are the rows of one (6, M) array [v; ω] of just the M balls the contacts touch; ``ends``
    are the columns of each contact's a then b. A sweep gathers both ends with one ``np.take`` and adds
    every contact's impulse to its two balls with one ``np.bincount``. Laid out by component, every
    other operation is on contiguous rows of K numbers, without broadcasting over a short axis.
    Friction and rolling resistance are solved as one (2, 3, K) block: the same update and the same
    cap, with their own effective masses and limits (zero limits where a material has none).
    """

    def __init__(self, contacts: ContactRows) -> None:
        super().__init__(contacts.a, contacts.b)
        k, m = self.k, self.m
        self.ima, self.imb = contacts.inv_mass_a, contacts.inv_mass_b
        self.iia, self.iib = contacts.inv_inertia_a, contacts.inv_inertia_b
        self.ra, self.rb = contacts.arm_lengths()
        self.minus_ra, self.minus_rb = -self.ra, -self.rb
        self.n = np.ascontiguousarray(contacts.normal.T)
        # the friction cone μ·P_n and the rolling limit ρ_roll·P_n, per unit of normal impulse (the rows'
        # own arrays: ``_full_sweep`` forms their (2, K) block for each sweep)
        self.friction, self.rolling = contacts.friction, contacts.rolling
        # each ball's own m⁻¹ and I⁻¹, for adding the summed impulses to its velocity
        inv_mass, inv_inertia = np.zeros(m), np.zeros(m)
        inv_mass[self.ends[:k]], inv_mass[self.ends[k:]] = self.ima, self.imb
        inv_inertia[self.ends[:k]], inv_inertia[self.ends[k:]] = self.iia, self.iib
        self.inverse = np.stack((inv_mass, inv_inertia))  # (2, M): m⁻¹ for v's rows, I⁻¹ for ω's
        # 1/m_n of the unsplit balls, and bounds on how much a unit of impulse changes a contact's
        # velocity, for the convergence test
        inv_n, inv_t, _ = model.inverse_effective_masses(
            self.ima, self.imb, self.iia, self.iib, self.ra, self.rb
        )
        self.whole = inv_n
        self.inv_m_n, self.inv_m_t = float(inv_n.max()), float(inv_t.max())
        self.moving = contacts.moving
        self.surface = np.ascontiguousarray(contacts.surface.T) if self.moving else None
        self.spin = np.ascontiguousarray(contacts.spin.T) if self.moving else None
        # scratch for what each contact adds to its a (columns :K) then its b (K:), and for the slip
        # at the contact point and the relative spin (friction, rolling), kept for every sweep; beyond
        # ADD_UP_BINS_UP_TO entries the pushes are made and added up one row at a time (``apply``), in
        # one row of scratch instead of six (80 bytes a contact less)
        self.push = np.empty((1 if 12 * k > ADD_UP_BINS_UP_TO else 6, 2 * k))
        self.motion = np.empty((2, 3, k))
        self.split()

    def normal_speeds(self, v: np.ndarray) -> np.ndarray:
        """Each contact's v_n = (v_a − v_b)·n from the (≥3, M) velocities ``v`` (spin does not change it
        on spheres), against a moving plane's surface: the contact model's ``normal_speed`` on these
        columns."""
        g = np.take(v[:3], self.ends, axis=1)
        return model.normal_speed(g[:, : self.k], g[:, self.k :], self.n, self.surface)

    def split(self, pushing: np.ndarray | None = None) -> None:
        """Split each ball's mass among its contacts, or among those ``pushing`` only (at least one share
        each): the effective masses ``m_n`` and ``m_tr`` (friction, then rolling, as (2, 1, K))."""
        k = self.k
        if pushing is None:
            share = self.share
        else:
            counts = np.bincount(self.ends, weights=np.concatenate((pushing, pushing)), minlength=self.m)
            share = np.maximum(counts, 1.0)
        sa, sb = share[self.ends[:k]], share[self.ends[k:]]
        m_n, m_t, m_r = model.effective_masses(
            sa * self.ima, sb * self.imb, sa * self.iia, sb * self.iib, self.ra, self.rb
        )
        self.m_n = m_n
        self.m_tr = np.stack((m_t, m_r))[:, None, :]


def solve(
    contacts: ContactRows,
    v: np.ndarray,
    w: np.ndarray,
    target: np.ndarray,
    imp: Impulses,
    iterations: int,
    friction_every: int = 1,
) -> Impulses:
    """Drive every contact's normal speed to ≥ ``target`` with friction and rolling resistance, all
    contacts at once per sweep; ``v`` and ``w`` (N+1, 3) change in place, ``imp`` accumulates.

    Only every ``friction_every``-th sweep (and the last) updates friction and rolling resistance; the
    sweeps between update the normal impulses alone. A normal-only sweep needs just the balls' linear
    velocities (a sphere's lever arm is parallel to its normal, so spin does not move v_n), which makes
    it about a fifth of the cost of a full one. The sweeps stop early once a full one changes no
    contact's velocity by more than CONVERGED."""
    if len(contacts) == 0:
        return imp
    c = ContactColumns(contacts)
    vw = np.ascontiguousarray(np.hstack((v[c.balls], w[c.balls])).T)  # (6, M)
    # accumulated friction (row 0) and rolling-resistance (row 1) impulses
    tangential = np.ascontiguousarray(np.stack((imp.friction, imp.rolling)).transpose(0, 2, 1))
    normal, tangential = sweeps(
        c, vw, imp.normal.copy(), tangential, target, iterations, friction_every=friction_every, converge=True
    )
    v[c.balls] = vw[:3].T
    w[c.balls] = vw[3:].T
    v[-1] = 0.0
    w[-1] = 0.0
    imp.normal[:], imp.friction[:], imp.rolling[:] = normal, tangential[0].T, tangential[1].T
    return imp


def sweeps(
    c: ContactColumns,
    vw: np.ndarray,
    normal: np.ndarray,
    tangential: np.ndarray | None,
    target: np.ndarray,
    count: int,
    *,
    friction_every: int | None = None,
    m_n: np.ndarray | None = None,
    give: np.ndarray | float | None = None,
    converge: bool = False,
) -> tuple[np.ndarray, np.ndarray | None]:
    """``count`` Jacobi sweeps driving each contact's v_n to ≥ ``target``: ``vw`` ((6, M) velocities
    and spins, or (3, M) velocities for normal impulses alone) changes in place; returns the new
    accumulated normal and tangential ((2, 3, K): friction, rolling) impulses. The ``tangential`` given
    (a contiguous (2, 3, K) block) is taken as scratch by a full sweep: its values are not kept.

    Every ``friction_every``-th sweep and the last also update friction and rolling resistance (None:
    normal impulses alone). ``m_n`` and ``give`` make the normal soft (``contact_model.normal_impulse``;
    the soft step); ``converge`` stops after a full sweep that changed no contact velocity by more
    than CONVERGED."""
    m_n = c.m_n if m_n is None else m_n
    for sweep in range(count):
        full = friction_every is not None and ((sweep + 1) % friction_every == 0 or sweep == count - 1)
        if not full:
            normal = _normal_sweep(c, vw, c.push, normal, target, m_n, give)
            continue
        normal, tangential, change = _full_sweep(
            c, vw, c.push, normal, tangential, target, c.motion, m_n, give, converge
        )
        if converge and change < CONVERGED:
            break
    return normal, tangential


def apply(
    c: ContactColumns, vw: np.ndarray, push: np.ndarray, normal: np.ndarray, tangential: np.ndarray
) -> None:
    """Add the impulses ``normal`` (K,) and ``tangential`` (friction, rolling: (2, 3, K)) to both balls
    of every contact (``contact_model``: Δv = ±m⁻¹·(P_n·n + P_t), Δω = I⁻¹·(−ρ·n × P_t ± R));
    ``push`` (6, 2K) is scratch, or (1, 2K) to make and add up the pushes one row at a time."""
    k = c.k
    d_t, d_r = tangential[0], tangential[1]
    if len(push) == 1:
        _apply_by_rows(c, vw, push[0], normal, d_t, d_r)
        return
    # formed in place in ``push`` (the same operations in the same order: no (3, K) temporaries)
    linear, turn = push[:3, :k], push[3:, k:]
    np.multiply(normal, c.n, out=linear)
    linear += d_t
    np.negative(linear, out=push[:3, k:])
    exact.cross_cols(c.n, d_t, out=turn)  # model.turn: n × P_t
    np.multiply(turn, c.minus_ra, out=push[3:, :k])
    push[3:, :k] += d_r
    turn *= c.minus_rb
    turn -= d_r
    total = c.add_up(push)
    by_kind = total.reshape(2, 3, c.m)  # a view: v's three rows, then ω's
    by_kind *= c.inverse[:, None, :]
    vw += total


def _apply_by_rows(
    c: ContactColumns, vw: np.ndarray, row: np.ndarray, normal: np.ndarray, d_t: np.ndarray, d_r: np.ndarray
) -> None:
    """``apply`` one row of pushes at a time in ``row`` (2K,): each row's values, and so its sums per
    ball, are those of the (6, 2K) block."""
    k, n = c.k, c.n
    total = np.empty((6, c.m))
    at_a, at_b = row[:k], row[k:]
    for r in range(3):  # Δv: ±(P_n·n + P_t)
        np.multiply(normal, n[r], out=at_a)
        at_a += d_t[r]
        np.negative(at_a, out=at_b)
        total[r] = c.add_row(row)
    for r in range(3):  # Δω: −ρ·(n × P_t) ± R
        exact.cross_col(n, d_t, r, out=at_b)
        np.multiply(at_b, c.minus_ra, out=at_a)
        at_a += d_r[r]
        at_b *= c.minus_rb
        at_b -= d_r[r]
        total[3 + r] = c.add_row(row)
    by_kind = total.reshape(2, 3, c.m)  # a view: v's three rows, then ω's
    by_kind *= c.inverse[:, None, :]
    vw += total


def _normal_sweep(
    c: ContactColumns,
    vw: np.ndarray,
    push: np.ndarray,
    normal: np.ndarray,
    target: np.ndarray,
    m_n: np.ndarray,
    give: np.ndarray | float | None,
) -> np.ndarray:
    """One sweep of the normal impulses alone; ``vw`` changes in place."""
    k, n = c.k, c.n
    vn = c.normal_speeds(vw)
    new = model.normal_impulse(normal, m_n, target, vn, give)
    d_n = new - normal
    if len(push) == 1:  # one row at a time (``apply``)
        total = np.empty((3, c.m))
        row = push[0]
        for r in range(3):
            np.multiply(d_n, n[r], out=row[:k])
            np.negative(row[:k], out=row[k:])
            total[r] = c.add_row(row)
    else:
        lin = push[:3]
        np.multiply(d_n, n, out=lin[:, :k])
        np.negative(lin[:, :k], out=lin[:, k:])
        total = c.add_up(lin)
    total *= c.inverse[0]
    vw[:3] += total
    return new


def _full_sweep(
    c: ContactColumns,
    vw: np.ndarray,
    push: np.ndarray,
    normal: np.ndarray,
    tangential: np.ndarray,
    target: np.ndarray,
    motion: np.ndarray,
    m_n: np.ndarray,
    give: np.ndarray | float | None,
    measure: bool,
) -> tuple[np.ndarray, np.ndarray, float]:
    """One sweep of normal, friction and rolling impulses, all from the velocities at its start;
    ``vw`` changes in place. Returns the impulses and (when ``measure``) a bound on the largest
    velocity change it made at any contact (m/s)."""
    k, n = c.k, c.n
    ea, eb = c.ends[:k], c.ends[k:]
    # the contact-point velocity (contact_model.contact_velocity) from the balls' velocities gathered a
    # (3, K) part at a time, each dropped once used, not as one (6, 2K) block
    wa, wb = np.take(vw[3:], ea, axis=1), np.take(vw[3:], eb, axis=1)
    np.subtract(wa, wb, out=motion[1])  # the relative spin, for rolling resistance
    lever = model.spin_lever(wa, wb, c.ra, c.rb)
    del wa, wb
    dv = np.take(vw[:3], ea, axis=1)
    dv -= np.take(vw[:3], eb, axis=1)
    rel = model.point_velocity(dv, lever, n, c.surface)
    del lever
    vn = exact.dot_cols(rel, n)
    new = model.normal_impulse(normal, m_n, target, vn, give)
    d_n = new - normal
    # friction cancels slip inside the Coulomb cone; rolling resistance opposes relative spin
    np.multiply(vn, n, out=motion[0])
    np.subtract(rel, motion[0], out=motion[0])
    del dv, rel
    if c.spin is not None:
        motion[1] -= c.spin
    # the new impulses are formed in the slip's scratch and the change in the old impulses' block,
    # which then is the next sweep's scratch: three (2, 3, K) blocks at a time, not four
    candidate = motion
    candidate *= c.m_tr
    np.subtract(tangential, candidate, out=candidate)
    limits = np.empty((2, k))
    np.multiply(c.friction, new, out=limits[0])
    np.multiply(c.rolling, new, out=limits[1])
    new_tr = model.within_limit(candidate, limits)
    del limits
    d_tr = np.subtract(new_tr, tangential, out=tangential)
    c.motion = d_tr
    apply(c, vw, push, d_n, d_tr)
    change = 0.0
    if measure:
        change = max(float(np.abs(d_n).max()) * c.inv_m_n, float(np.abs(d_tr[0]).max()) * c.inv_m_t)
    return new, new_tr, change
