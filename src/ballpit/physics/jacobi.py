"""Contact impulses for many contacts at once: projected Jacobi with mass splitting.

The colour-by-colour Gauss–Seidel solve (``solver.py``) costs a few dozen NumPy calls per colour per
sweep; a pile has 12–17 colours, so at a thousand balls the calls' fixed cost is most of the step.
Here every contact is updated at once from the same velocities, so a sweep is a fixed number of calls
whatever the colours.

Plain Jacobi overshoots where several contacts push one ball. Mass splitting (Tonge, Benevolenski
and Voroshilov, "Mass splitting for jitter-free parallel rigid body simulation", SIGGRAPH 2012) gives
each contact a share 1/n_b of a ball with n_b contacts: the contact's effective masses use n_b·m⁻¹ and
n_b·I⁻¹, and averaging the copies of a ball afterwards is the same as adding up every contact's impulse
with the ball's own m⁻¹ and I⁻¹. The iteration then converges to the same solution as Gauss–Seidel and
never overshoots, so a pile rests without jitter.

A normal-only sweep needs only the balls' linear velocities: a sphere's lever arm is parallel to its
contact normal, so spin never changes v_n. It costs about a fifth of a full sweep (normal, friction
and rolling resistance), so a solve may update friction in only some of its sweeps.

The contact model (normal, Coulomb friction, rolling resistance; targets, accumulated impulses and
their clamps) is exactly the one in ``solver.py``; only the order of the updates differs.
"""

from __future__ import annotations

import numpy as np

from .impulses import Impulses, skew
from .rows import ContactRows
from .settings import CONVERGED, SORT_ENDS_FROM


class _Ends:
    """Both ends of K contacts as columns of a compact array of the M balls they touch: ``ends`` holds
    each contact's a then b, ``share`` each ball's number of contacts (its mass is split that many
    ways), and ``add_up`` adds per-end values back per ball with one ``np.bincount``."""

    def __init__(self, a: np.ndarray, b: np.ndarray, rows: int) -> None:
        self.k = len(a)
        ab = np.concatenate((a, b))
        rows_in_world = int(ab.max(initial=-1)) + 1
        if len(ab) * SORT_ENDS_FROM < rows_in_world:  # few contacts in a big world: sorting them is cheaper
            self.balls, self.ends = np.unique(ab, return_inverse=True)
        else:  # the same compact numbering (balls in increasing order) from a table over the world
            present = np.zeros(rows_in_world, bool)
            present[ab] = True
            self.balls = np.flatnonzero(present)
            self.ends = np.take(np.cumsum(present) - 1, ab)
        self.m = len(self.balls)
        self.share = np.bincount(self.ends, minlength=self.m).astype(float)
        # where each of the (rows, 2K) per-end entries lands in the flattened (rows, M) per-ball array
        self.scatter = (np.arange(rows)[:, None] * self.m + self.ends[None, :]).ravel()

    def add_up(self, values: np.ndarray) -> np.ndarray:
        """(rows, 2K) values per contact end, summed per ball: (rows, M). Fewer rows than the ends were
        built for sum into the first ones."""
        rows = len(values)
        scatter = self.scatter[: rows * 2 * self.k]
        summed = np.bincount(scatter, weights=values.ravel(), minlength=rows * self.m)
        return summed.reshape(rows, self.m)


class _Contacts(_Ends):
    """What the sweeps need of the contacts, gathered once per solve, with vectors as (3, K) rows.

    Velocities are the rows of one (6, M) array [v; ω] of just the M balls the contacts touch; ``ends``
    are the columns of each contact's a then b. A sweep gathers both ends with one ``np.take`` and adds
    every contact's impulse to its two balls with one ``np.bincount``. Laid out by component, every
    other operation is on contiguous rows of K numbers, without broadcasting over a short axis.
    Friction and rolling resistance are solved as one (2, 3, K) block: the same update and the same
    cap, with their own effective masses and limits (zero limits where a material has none).
    """

    def __init__(self, contacts: ContactRows) -> None:
        super().__init__(contacts.a, contacts.b, 6)  # rows v and ω
        k, m, share = self.k, self.m, self.share
        sa, sb = share[self.ends[:k]], share[self.ends[k:]]
        ima, imb = contacts.inv_mass_a, contacts.inv_mass_b
        iia, iib = contacts.inv_inertia_a, contacts.inv_inertia_b
        ra, rb = contacts.arm_lengths()
        self.minus_ra, self.minus_rb = -ra, -rb
        self.arms = np.concatenate((ra, rb))  # each end's lever arm ρ, in the order of ``ends``
        self.n = np.ascontiguousarray(contacts.normal.T)
        self.nx = np.ascontiguousarray(skew(contacts.normal).transpose(1, 2, 0))  # (3, 3, K): [n]×
        # effective masses of the split bodies (each ball's m⁻¹ and I⁻¹ times its number of contacts):
        # normal, then tangential (friction) and angular (rolling resistance) stacked as (2, 1, K)
        self.m_n = 1.0 / (sa * ima + sb * imb)
        m_t = 1.0 / ((sa * ima + ra**2 * (sa * iia)) + sb * imb + rb**2 * (sb * iib))
        m_r = 1.0 / np.maximum(sa * iia + sb * iib, 1e-300)
        self.m_tr = np.stack((m_t, m_r))[:, None, :]
        # the friction cone μ·P_n and the rolling limit ρ·r·P_n, per unit of normal impulse
        self.limits = np.stack((contacts.friction, contacts.rolling))
        # each ball's own m⁻¹ and I⁻¹, for adding the summed impulses to its velocity
        inv_mass, inv_inertia = np.zeros(m), np.zeros(m)
        inv_mass[self.ends[:k]], inv_mass[self.ends[k:]] = ima, imb
        inv_inertia[self.ends[:k]], inv_inertia[self.ends[k:]] = iia, iib
        self.inverse = np.repeat(np.stack((inv_mass, inv_inertia)), 3, axis=0)  # (6, M)
        # bounds on how much a unit of impulse changes a contact's velocity, for the convergence test
        self.inv_m_n = float((ima + imb).max())
        self.inv_m_t = float((ima + ra**2 * iia + imb + rb**2 * iib).max())
        self.moving = contacts.moving
        self.surface = np.ascontiguousarray(contacts.surface.T)
        self.spin = np.ascontiguousarray(contacts.spin.T)


def solve(contacts: ContactRows, v: np.ndarray, w: np.ndarray, target: np.ndarray, imp: Impulses,
          iterations: int, friction_every: int = 1) -> Impulses:  # fmt: skip
    """Drive every contact's normal speed to ≥ ``target`` with friction and rolling resistance, all
    contacts at once per sweep; ``v`` and ``w`` (N+1, 3) change in place, ``imp`` accumulates.

    Only every ``friction_every``-th sweep (and the last) updates friction and rolling resistance; the
    sweeps between update the normal impulses alone. A normal-only sweep needs just the balls' linear
    velocities (a sphere's lever arm is parallel to its normal, so spin does not move v_n), which makes
    it about a fifth of the cost of a full one."""
    if len(contacts) == 0:
        return imp
    c = _Contacts(contacts)
    k = c.k
    vw = np.ascontiguousarray(np.hstack((v[c.balls], w[c.balls])).T)  # (6, M)
    push = np.zeros((6, 2 * k))  # what each contact adds to its a (columns :k) and its b (columns k:)
    normal = imp.normal.copy()
    # accumulated friction (row 0) and rolling-resistance (row 1) impulses
    tangential = np.ascontiguousarray(np.stack((imp.friction, imp.rolling)).transpose(0, 2, 1))
    motion = np.empty((2, 3, k))  # slip at the contact point, and relative spin
    for sweep in range(iterations):
        full = (sweep + 1) % friction_every == 0 or sweep == iterations - 1
        if full:
            normal, tangential, change = _full_sweep(c, vw, push, normal, tangential, target, motion)
        else:
            normal, change = _normal_sweep(c, vw, push, normal, target)
        if full and change < CONVERGED:
            break
    v[c.balls] = vw[:3].T
    w[c.balls] = vw[3:].T
    v[-1] = 0.0
    w[-1] = 0.0
    imp.normal[:], imp.friction[:], imp.rolling[:] = normal, tangential[0].T, tangential[1].T
    return imp


def _normal_sweep(c: _Contacts, vw: np.ndarray, push: np.ndarray, normal: np.ndarray,
                  target: np.ndarray) -> tuple[np.ndarray, float]:  # fmt: skip
    """One sweep of the normal impulses alone; ``vw`` changes in place."""
    k, n = c.k, c.n
    g = np.take(vw[:3], c.ends, axis=1)
    vn = np.einsum("ij,ij->j", g[:, :k] - g[:, k:], n)
    if c.moving:  # relative to a moving plane's surface
        vn -= np.einsum("ij,ij->j", c.surface, n)
    new = np.maximum(normal + c.m_n * (target - vn), 0.0)
    d_n = new - normal
    lin = push[:3]
    np.multiply(d_n, n, out=lin[:, :k])
    np.negative(lin[:, :k], out=lin[:, k:])
    total = c.add_up(lin)
    total *= c.inverse[:3]
    vw[:3] += total
    return new, float(np.abs(d_n).max()) * c.inv_m_n


def _full_sweep(c: _Contacts, vw: np.ndarray, push: np.ndarray, normal: np.ndarray, tangential: np.ndarray,
                target: np.ndarray, motion: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:  # fmt: skip
    """One sweep of normal, friction and rolling impulses; ``vw`` changes in place."""
    k, n, nx = c.k, c.n, c.nx
    g = np.take(vw, c.ends, axis=1)
    va, wa, vb, wb = g[:3, :k], g[3:, :k], g[:3, k:], g[3:, k:]
    # contact-point velocity of a relative to b: v_a − v_b + n × (ρ_a·ω_a + ρ_b·ω_b)
    arm_spin = g[3:] * c.arms
    rel = va - vb
    rel += np.einsum("ijk,jk->ik", nx, arm_spin[:, :k] + arm_spin[:, k:])
    if c.moving:  # relative to a moving plane's surface
        rel -= c.surface
    vn = np.einsum("ij,ij->j", rel, n)

    # normal: the accumulated impulse stays ≥ 0
    new = np.maximum(normal + c.m_n * (target - vn), 0.0)
    d_n = new - normal
    linear = d_n * n
    change = float(np.abs(d_n).max()) * c.inv_m_n

    # friction cancels slip inside the Coulomb cone |P_t| ≤ μ·P_n; rolling resistance opposes
    # relative spin up to ρ·r·P_n
    np.multiply(vn, n, out=motion[0])
    np.subtract(rel, motion[0], out=motion[0])
    np.subtract(wa, wb, out=motion[1])
    if c.moving:
        motion[1] -= c.spin
    candidate = tangential - c.m_tr * motion
    length = np.einsum("ijk,ijk->ik", candidate, candidate)
    length += 1e-300  # no 0/0 at zero
    np.sqrt(length, out=length)
    scale = np.minimum(c.limits * new / length, 1.0)
    new_tr = candidate * scale[:, None, :]
    d_tr = new_tr - tangential
    d_t, d_r = d_tr[0], d_tr[1]
    linear += d_t
    turn = np.einsum("ijk,jk->ik", nx, d_t)  # n × ΔP_t
    push_a, push_b = push[3:, :k], push[3:, k:]
    np.multiply(turn, c.minus_ra, out=push_a)
    push_a += d_r
    np.multiply(turn, c.minus_rb, out=push_b)
    push_b -= d_r
    change = max(change, float(np.abs(d_t).max()) * c.inv_m_t)

    push[:3, :k] = linear
    np.negative(linear, out=push[:3, k:])
    total = c.add_up(push)
    total *= c.inverse
    vw += total
    return new, new_tr, change


def separate(a: np.ndarray, b: np.ndarray, normal: np.ndarray, gap: np.ndarray, inv_mass_a: np.ndarray,
             inv_mass_b: np.ndarray, pos: np.ndarray, sweeps: int) -> None:  # fmt: skip
    """Move overlapping balls apart along their normals, all contacts at once per sweep: each
    contact's overlap (−``gap`` at the start, along the fixed normal) is shared between its balls in
    proportion to their split inverse masses. ``pos`` (N+1, 3) changes in place; row N is the world."""
    e = _Ends(a, b, 3)  # rows x, y, z
    k, balls, ends, share = e.k, e.balls, e.ends, e.share
    wa, wb = share[ends[:k]] * inv_mass_a, share[ends[k:]] * inv_mass_b
    fa, fb = wa / (wa + wb), -wb / (wa + wb)  # each end's part of the contact's correction
    n = np.ascontiguousarray(normal.T)
    x = np.ascontiguousarray(pos[balls].T)  # (3, M)
    start = np.einsum("ij,ij->j", n, np.take(x, ends[:k], axis=1) - np.take(x, ends[k:], axis=1))
    move = np.zeros((3, 2 * k))
    for _ in range(sweeps):
        g = np.take(x, ends, axis=1)
        now = gap + np.einsum("ij,ij->j", n, g[:, :k] - g[:, k:]) - start
        d = np.maximum(-now, 0.0) * n
        np.multiply(d, fa, out=move[:, :k])
        np.multiply(d, fb, out=move[:, k:])
        # averaging the split copies of a ball: its moves add up, each with its own share 1/n_b
        x += e.add_up(move) / share
    pos[balls] = x.T
    pos[-1] = 0.0
