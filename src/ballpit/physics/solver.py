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
solved as one set of array operations; Gauss–Seidel order holds between colours. From JACOBI_FROM
contacts on (a pile), ``solve`` hands the same contact model to ``jacobi.py``, which updates every
contact at once per sweep. A crowded step (strategies.py) hands it every solve, however small: a
few dozen contacts in many colours cost ten times more by colour than at once.

Balls are rows 0…N−1 of the velocity arrays; row N is the static world (planes), with zero inverse
mass, so a sphere–plane contact is a sphere–sphere contact whose second body never moves.
"""

from __future__ import annotations

import numpy as np

from . import exact, jacobi
from .impulses import Impulses, cap, skew
from .rows import ContactRows
from .settings import CONVERGED, JACOBI_FRICTION_EVERY, JACOBI_FROM, JACOBI_SWEEPS


class _Colour:
    """One colour's contacts, gathered once per solve so the sweeps only touch velocities.

    Velocities are rows of one (M, 6) array [v | ω] holding just the balls the solve touches; a
    colour gathers rows ``a`` then ``b`` as one (2, k, 6) block and writes it back in one go.

    With arms r_a = −ρ_a·n and r_b = +ρ_b·n (ρ the radii), the contact-point velocity is
    v_a − v_b − (ρ_a·ω_a + ρ_b·ω_b) × n, and a tangential impulse P turns the balls by
    Δω_a = −ρ_a·I_a⁻¹·(n × P), Δω_b = −ρ_b·I_b⁻¹·(n × P).
    """

    def __init__(self, contacts: ContactRows, idx: np.ndarray, local: np.ndarray) -> None:
        k = len(idx)
        self.idx = idx
        self.rows = local[np.concatenate((idx, idx + len(contacts)))]
        self.n = contacts.normal[idx]
        self.nx = skew(self.n)
        ra, rb = contacts.arm_lengths(idx)
        self.ra, self.rb = ra[:, None], rb[:, None]
        ima, imb = contacts.inv_mass_a[idx], contacts.inv_mass_b[idx]
        iia, iib = contacts.inv_inertia_a[idx], contacts.inv_inertia_b[idx]
        inv_m_n = ima + imb
        self.m_n = 1.0 / inv_m_n
        inv_m_t = ima + ra**2 * iia + imb + rb**2 * iib
        self.m_t = (1.0 / inv_m_t)[:, None]
        self.m_r = (1.0 / np.maximum(iia + iib, 1e-300))[:, None]
        # Coefficients of the update, stacked for a then b: Δv = ±m⁻¹·P, Δω = −ρ·I⁻¹·(n × P_t) ± I⁻¹·R.
        self.lin = np.stack((ima, -imb)).reshape(2, k, 1)
        self.turn = -np.stack((ra * iia, rb * iib)).reshape(2, k, 1)
        self.roll = np.stack((iia, -iib)).reshape(2, k, 1)
        # Bounds on how much a unit of impulse changes a contact's velocity, for the convergence test.
        self.max_inv_m_n = float(inv_m_n.max())
        self.max_inv_m_t = float(inv_m_t.max())
        self.mu = contacts.friction[idx]
        self.rolling = contacts.rolling[idx]
        self.moving = contacts.moving
        self.surface, self.spin = contacts.surface[idx], contacts.spin[idx]
        self.has_friction = bool(self.mu.any())
        self.has_rolling = bool(self.rolling.any())


def warm_start(contacts: ContactRows, v: np.ndarray, w: np.ndarray, imp: Impulses) -> None:
    """Apply impulses carried over from the previous interval before iterating."""
    if len(contacts) == 0:
        return
    n = contacts.normal
    linear = imp.normal[:, None] * n + imp.friction
    turn = np.einsum("kij,kj->ki", skew(n), imp.friction)  # n × P_t
    ra, rb = contacts.arm_lengths()
    rows = len(v)
    for body, sign, im, ii, r in (
        (contacts.a, 1.0, contacts.inv_mass_a, contacts.inv_inertia_a, ra),
        (contacts.b, -1.0, contacts.inv_mass_b, contacts.inv_inertia_b, rb),
    ):
        dv = sign * linear * im[:, None]
        dw = (-r[:, None] * turn + sign * imp.rolling) * ii[:, None]
        for axis in range(3):
            v[:, axis] += np.bincount(body, dv[:, axis], minlength=rows)
            w[:, axis] += np.bincount(body, dw[:, axis], minlength=rows)
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
    balls, local = np.unique(np.concatenate((contacts.a, contacts.b)), return_inverse=True)
    vw = np.hstack((v[balls], w[balls]))
    colours = [_Colour(contacts, idx, local) for idx in contacts.colours]
    targets = [target[c.idx] for c in colours]
    normal = [imp.normal[c.idx] for c in colours]
    friction = [imp.friction[c.idx] for c in colours]
    rolling = [imp.rolling[c.idx] for c in colours]
    for _ in range(iterations):
        change = 0.0  # a bound on the largest velocity change this sweep made at any contact (m/s)
        for k, c in enumerate(colours):
            g = vw[c.rows].reshape(2, -1, 6)
            (va, wa), (vb, wb) = (g[0, :, :3], g[0, :, 3:]), (g[1, :, :3], g[1, :, 3:])
            # contact-point velocity of a relative to b: v_a − v_b − (ρ_a·ω_a + ρ_b·ω_b) × n
            rel = va - vb + np.einsum("kij,kj->ki", c.nx, c.ra * wa + c.rb * wb)
            if c.moving:  # relative to a moving plane's surface
                rel -= c.surface
            vn = exact.dot(rel, c.n)

            # normal: the accumulated impulse stays ≥ 0
            old = normal[k]
            new = np.maximum(old + c.m_n * (targets[k] - vn), 0.0)
            normal[k] = new
            d_n = new - old
            linear = d_n[:, None] * c.n
            change = max(change, float(np.abs(d_n).max()) * c.max_inv_m_n)

            if c.has_friction:
                # friction: cancel slip (the tangential part of rel, which the normal impulse leaves
                # alone), inside the Coulomb cone |P_t| ≤ μ·P_n
                old_t = friction[k]
                new_t = cap(old_t - c.m_t * (rel - vn[:, None] * c.n), c.mu * new)
                friction[k] = new_t
                d_t = new_t - old_t
                linear += d_t
                turn = np.einsum("kij,kj->ki", c.nx, d_t)  # n × ΔP_t
                g[:, :, 3:] += c.turn * turn
                change = max(change, float(np.abs(d_t).max()) * c.max_inv_m_t)

            if c.has_rolling:
                # rolling resistance: oppose relative spin (after the friction turn), up to ρ·r·P_n
                old_r = rolling[k]
                spin = wa - wb - c.spin if c.moving else wa - wb
                new_r = cap(old_r - c.m_r * spin, c.rolling * new)
                rolling[k] = new_r
                g[:, :, 3:] += c.roll * (new_r - old_r)

            g[:, :, :3] += c.lin * linear
            vw[c.rows] = g.reshape(-1, 6)
        if change < CONVERGED:
            break
    v[balls] = vw[:, :3]
    w[balls] = vw[:, 3:]
    v[-1] = 0.0
    w[-1] = 0.0
    for k, c in enumerate(colours):
        imp.normal[c.idx] = normal[k]
        imp.friction[c.idx] = friction[k]
        imp.rolling[c.idx] = rolling[k]
    return imp
