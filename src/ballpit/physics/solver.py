"""Contact impulses: a projected Gauss–Seidel (sequential impulse) solver, vectorised by colour.

Each contact has three parts, solved in turn with accumulated-impulse clamping (Catto, "Iterative
Dynamics with Temporal Coherence", GDC 2005; Box2D's contact_solver.c):

- normal: P_n ≥ 0 drives the approach speed v_n to a target (−e·v_n for a bounce, 0 for rest);
  effective mass 1/(1/m_a + 1/m_b), since a sphere's lever arm is parallel to the normal;
- friction: a tangential impulse that stops slip at the contact point, capped by the Coulomb cone
  |P_t| ≤ μ·P_n. For a sphere the lever arm r is perpendicular to any tangent t, so the effective
  mass is isotropic: 1/(1/m_a + r_a²/I_a + 1/m_b + r_b²/I_b);
- rolling resistance: an angular impulse opposing relative spin, capped by ρ·r·P_n. On level
  ground it slows a rolling ball at (5/7)·ρ·g.

Contacts that share no ball are independent, so they are grouped into colours and each colour is
solved as one set of array operations; Gauss–Seidel order holds between colours.

Balls are rows 0…N−1 of the velocity arrays; row N is the static world (planes), with zero inverse
mass, so a sphere–plane contact is a sphere–sphere contact whose second body never moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A sweep that changes no contact velocity by more than this (m/s) ends the iterations early.
CONVERGED = 1e-9


@dataclass
class ContactBatch:
    """Per-contact arrays the solver needs; built once per interval from the narrow phase."""

    a: np.ndarray  # first ball
    b: np.ndarray  # second ball, or the static row N for a plane
    normal: np.ndarray  # (K, 3), towards a
    arm_a: np.ndarray  # (K, 3) centre of a → contact point
    arm_b: np.ndarray  # (K, 3) centre of b → contact point (zero for planes)
    inv_mass_a: np.ndarray
    inv_mass_b: np.ndarray
    inv_inertia_a: np.ndarray
    inv_inertia_b: np.ndarray
    restitution: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray  # rolling resistance ρ·r (m): angular impulse per unit normal impulse
    colours: list[np.ndarray]

    def __len__(self) -> int:
        return len(self.a)

    def subset(self, mask: np.ndarray, static: int) -> ContactBatch:
        """The contacts where ``mask`` holds, coloured afresh."""
        fields = {k: v[mask] for k, v in vars(self).items() if k != "colours"}
        return ContactBatch(**fields, colours=colour(fields["a"], fields["b"], static))


@dataclass
class Impulses:
    """Accumulated impulses per contact: normal (K,), friction (K, 3), rolling (K, 3)."""

    normal: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray

    @staticmethod
    def zeros(count: int) -> Impulses:
        return Impulses(np.zeros(count), np.zeros((count, 3)), np.zeros((count, 3)))


def colour(a: np.ndarray, b: np.ndarray, static: int) -> list[np.ndarray]:
    """Split contacts into groups in which no ball appears twice (the static row may repeat).

    Each round takes every contact whose priority is the lowest among the contacts on both its balls
    (Luby's independent sets); priorities are a fixed hash of the index, so colouring is deterministic.
    """
    remaining = np.arange(len(a))
    priority = (remaining.astype(np.uint64) * np.uint64(2654435761)) % np.uint64(4294967291)
    order = np.argsort(priority, kind="stable")
    rank = np.empty(len(a), np.int64)
    rank[order] = np.arange(len(a))
    colours = []
    lowest = np.empty(static + 1, np.int64)
    while remaining.size:
        ra, rb = a[remaining], b[remaining]
        r = rank[remaining]
        lowest.fill(len(a))
        np.minimum.at(lowest, ra, r)
        dynamic_b = rb != static
        np.minimum.at(lowest, rb[dynamic_b], r[dynamic_b])
        chosen = (lowest[ra] == r) & (~dynamic_b | (lowest[rb] == r))
        colours.append(remaining[chosen])
        remaining = remaining[~chosen]
    return colours


def _cap(vectors: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """Scale each row down to length ≤ limit (the friction cone and the rolling-resistance limit)."""
    length2 = np.einsum("ij,ij->i", vectors, vectors)
    over = length2 > limit * limit
    if not over.any():
        return vectors
    scale = np.where(over, limit / np.sqrt(np.where(over, length2, 1.0)), 1.0)
    return vectors * scale[:, None]


def skew(n: np.ndarray) -> np.ndarray:
    """Matrices [n]× with [n]×·s = n × s, so a batch of cross products is one einsum."""
    k = np.zeros((len(n), 3, 3))
    k[:, 0, 1], k[:, 0, 2] = -n[:, 2], n[:, 1]
    k[:, 1, 0], k[:, 1, 2] = n[:, 2], -n[:, 0]
    k[:, 2, 0], k[:, 2, 1] = -n[:, 1], n[:, 0]
    return k


class _Colour:
    """One colour's contacts, gathered once per solve so the iterations only touch velocities.

    With arms r_a = −ρ_a·n and r_b = +ρ_b·n (ρ the radii), the contact-point velocity is
    v_a − v_b − (ρ_a·ω_a + ρ_b·ω_b) × n, and a tangential impulse P turns the balls by
    Δω_a = −ρ_a·I_a⁻¹·(n × P), Δω_b = −ρ_b·I_b⁻¹·(n × P).
    """

    def __init__(self, batch: ContactBatch, idx: np.ndarray) -> None:
        self.idx = idx
        self.a, self.b = batch.a[idx], batch.b[idx]
        self.n = batch.normal[idx]
        self.nx = skew(self.n)
        ra = np.sqrt(np.einsum("ij,ij->i", batch.arm_a[idx], batch.arm_a[idx]))
        rb = np.sqrt(np.einsum("ij,ij->i", batch.arm_b[idx], batch.arm_b[idx]))
        self.ra, self.rb = ra[:, None], rb[:, None]
        self.ima, self.imb = batch.inv_mass_a[idx, None], batch.inv_mass_b[idx, None]
        self.iia, self.iib = batch.inv_inertia_a[idx, None], batch.inv_inertia_b[idx, None]
        self.turn_a, self.turn_b = self.ra * self.iia, self.rb * self.iib
        self.inv_m_n = batch.inv_mass_a[idx] + batch.inv_mass_b[idx]
        self.m_n = 1.0 / self.inv_m_n
        self.m_t = 1.0 / (self.ima + ra[:, None] ** 2 * self.iia + self.imb + rb[:, None] ** 2 * self.iib)
        self.m_r = 1.0 / np.maximum(self.iia + self.iib, 1e-300)
        self.mu = batch.friction[idx]
        self.roll = batch.rolling[idx]
        self.has_friction = bool(self.mu.any())
        self.has_rolling = bool(self.roll.any())


def warm_start(batch: ContactBatch, v: np.ndarray, w: np.ndarray, imp: Impulses) -> None:
    """Apply impulses carried over from the previous interval before iterating."""
    if len(batch) == 0:
        return
    n = batch.normal
    linear = imp.normal[:, None] * n + imp.friction
    turn = np.einsum("kij,kj->ki", skew(n), imp.friction)  # n × P_t
    ra = np.sqrt(np.einsum("ij,ij->i", batch.arm_a, batch.arm_a))[:, None]
    rb = np.sqrt(np.einsum("ij,ij->i", batch.arm_b, batch.arm_b))[:, None]
    rows = len(v)
    for body, sign, im, ii, r in (
        (batch.a, 1.0, batch.inv_mass_a, batch.inv_inertia_a, ra),
        (batch.b, -1.0, batch.inv_mass_b, batch.inv_inertia_b, rb),
    ):
        dv = sign * linear * im[:, None]
        dw = (-r * turn + sign * imp.rolling) * ii[:, None]
        for axis in range(3):
            v[:, axis] += np.bincount(body, dv[:, axis], minlength=rows)
            w[:, axis] += np.bincount(body, dw[:, axis], minlength=rows)
    v[-1] = 0.0
    w[-1] = 0.0


def solve(
    batch: ContactBatch,
    v: np.ndarray,
    w: np.ndarray,
    target: np.ndarray,
    imp: Impulses,
    iterations: int,
) -> Impulses:
    """Projected Gauss–Seidel: drive every contact's normal speed to ≥ ``target`` with friction and
    rolling resistance; ``v`` and ``w`` (N+1, 3) change in place, ``imp`` accumulates."""
    if len(batch) == 0:
        return imp
    colours = [_Colour(batch, idx) for idx in batch.colours]
    targets = [target[c.idx] for c in colours]
    normal = [imp.normal[c.idx] for c in colours]
    friction = [imp.friction[c.idx] for c in colours]
    rolling = [imp.rolling[c.idx] for c in colours]
    for _ in range(iterations):
        change = 0.0  # the largest velocity change this sweep made at any contact (m/s)
        for k, c in enumerate(colours):
            va, vb, wa, wb = v[c.a], v[c.b], w[c.a], w[c.b]
            # contact-point velocity of a relative to b: v_a − v_b − (ρ_a·ω_a + ρ_b·ω_b) × n
            spin = c.ra * wa + c.rb * wb
            rel = va - vb + np.einsum("kij,kj->ki", c.nx, spin)
            vn = np.einsum("ij,ij->i", rel, c.n)

            # normal: the accumulated impulse stays ≥ 0
            old = normal[k]
            new = np.maximum(old + c.m_n * (targets[k] - vn), 0.0)
            normal[k] = new
            linear = (new - old)[:, None] * c.n
            change = max(change, float(np.max(np.abs(new - old) * c.inv_m_n)))

            if c.has_friction:
                # friction: cancel slip (the tangential part of rel, which the normal impulse leaves
                # alone), inside the Coulomb cone |P_t| ≤ μ·P_n
                slip = rel - vn[:, None] * c.n
                old_t = friction[k]
                new_t = _cap(old_t - c.m_t * slip, c.mu * new)
                friction[k] = new_t
                d_t = new_t - old_t
                turn = np.einsum("kij,kj->ki", c.nx, d_t)  # n × ΔP_t
                wa = wa - c.turn_a * turn
                wb = wb - c.turn_b * turn
                linear += d_t
                change = max(change, float(np.max(np.abs(d_t) / c.m_t)))

            if c.has_rolling:
                # rolling resistance: oppose relative spin, up to ρ·r·P_n
                old_r = rolling[k]
                new_r = _cap(old_r - c.m_r * (wa - wb), c.roll * new)
                rolling[k] = new_r
                d_r = new_r - old_r
                wa = wa + c.iia * d_r
                wb = wb - c.iib * d_r

            v[c.a] = va + c.ima * linear
            v[c.b] = vb - c.imb * linear
            w[c.a] = wa
            w[c.b] = wb
        v[-1] = 0.0
        w[-1] = 0.0
        if change < CONVERGED:
            break
    for k, c in enumerate(colours):
        imp.normal[c.idx] = normal[k]
        imp.friction[c.idx] = friction[k]
        imp.rolling[c.idx] = rolling[k]
    return imp
