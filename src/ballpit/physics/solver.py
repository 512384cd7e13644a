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

    @property
    def normal_mass(self) -> np.ndarray:
        return 1.0 / (self.inv_mass_a + self.inv_mass_b)

    @property
    def tangent_mass(self) -> np.ndarray:
        ra2 = np.einsum("ij,ij->i", self.arm_a, self.arm_a)
        rb2 = np.einsum("ij,ij->i", self.arm_b, self.arm_b)
        return 1.0 / (self.inv_mass_a + ra2 * self.inv_inertia_a + self.inv_mass_b + rb2 * self.inv_inertia_b)

    @property
    def rolling_mass(self) -> np.ndarray:
        return 1.0 / np.maximum(self.inv_inertia_a + self.inv_inertia_b, 1e-300)


@dataclass
class Impulses:
    """Accumulated impulses per contact: normal (K,), friction (K, 3), rolling (K, 3)."""

    normal: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray

    @staticmethod
    def zeros(count: int) -> Impulses:
        return Impulses(np.zeros(count), np.zeros((count, 3)), np.zeros((count, 3)))

    def scaled(self, factor: float) -> Impulses:
        return Impulses(self.normal * factor, self.friction * factor, self.rolling * factor)


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
    length = np.sqrt(np.einsum("ij,ij->i", vectors, vectors))
    scale = np.where(length > limit, limit / np.where(length > 0, length, 1.0), 1.0)
    return vectors * scale[:, None]


def apply(batch: ContactBatch, idx: np.ndarray, v: np.ndarray, w: np.ndarray, imp: Impulses) -> None:
    """Add the impulses of contacts ``idx`` to the velocities (contacts in idx share no ball)."""
    a, b = batch.a[idx], batch.b[idx]
    linear = imp.normal[idx, None] * batch.normal[idx] + imp.friction[idx]
    v[a] += linear * batch.inv_mass_a[idx, None]
    v[b] -= linear * batch.inv_mass_b[idx, None]
    w[a] += (np.cross(batch.arm_a[idx], imp.friction[idx]) + imp.rolling[idx]) * batch.inv_inertia_a[
        idx, None
    ]
    w[b] -= (np.cross(batch.arm_b[idx], imp.friction[idx]) + imp.rolling[idx]) * batch.inv_inertia_b[
        idx, None
    ]


def warm_start(batch: ContactBatch, v: np.ndarray, w: np.ndarray, imp: Impulses) -> None:
    """Apply impulses carried over from the previous interval before iterating."""
    for idx in batch.colours:
        apply(batch, idx, v, w, imp)


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
    m_n, m_t, m_r = batch.normal_mass, batch.tangent_mass, batch.rolling_mass
    for _ in range(iterations):
        for idx in batch.colours:
            a, b = batch.a[idx], batch.b[idx]
            n, ra, rb = batch.normal[idx], batch.arm_a[idx], batch.arm_b[idx]
            ima, imb = batch.inv_mass_a[idx, None], batch.inv_mass_b[idx, None]
            iia, iib = batch.inv_inertia_a[idx, None], batch.inv_inertia_b[idx, None]
            va, vb, wa, wb = v[a], v[b], w[a], w[b]

            # normal: accumulated impulse stays ≥ 0
            rel = va + np.cross(wa, ra) - vb - np.cross(wb, rb)
            vn = np.einsum("ij,ij->i", rel, n)
            old = imp.normal[idx]
            new = np.maximum(old + m_n[idx] * (target[idx] - vn), 0.0)
            imp.normal[idx] = new
            dp = (new - old)[:, None] * n
            va = va + dp * ima
            vb = vb - dp * imb

            # friction: cancel slip at the contact point, inside the cone |P_t| ≤ μ·P_n
            rel = va + np.cross(wa, ra) - vb - np.cross(wb, rb)
            slip = rel - np.einsum("ij,ij->i", rel, n)[:, None] * n
            old_t = imp.friction[idx]
            new_t = _cap(old_t - m_t[idx, None] * slip, batch.friction[idx] * new)
            imp.friction[idx] = new_t
            dt_ = new_t - old_t
            va = va + dt_ * ima
            vb = vb - dt_ * imb
            wa = wa + np.cross(ra, dt_) * iia
            wb = wb - np.cross(rb, dt_) * iib

            # rolling resistance: oppose relative spin, up to ρ·r·P_n
            old_r = imp.rolling[idx]
            new_r = _cap(old_r - m_r[idx, None] * (wa - wb), batch.rolling[idx] * new)
            imp.rolling[idx] = new_r
            dr = new_r - old_r
            wa = wa + dr * iia
            wb = wb - dr * iib

            v[a], v[b], w[a], w[b] = va, vb, wa, wb
        v[-1] = 0.0
        w[-1] = 0.0
    return imp
