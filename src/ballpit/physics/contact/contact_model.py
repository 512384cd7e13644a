"""The contact model, written once: how an impulse at a contact changes two balls' motion, and how
each part of it is bounded. Every solve builds on these functions (solver.py: Gauss–Seidel colour by
colour; jacobi.py: every contact at once, which the soft step's substeps and restitution also run;
impacts.py: bounces in waves); the solves differ only in the order they update the contacts.

A contact joins ball a to b (another ball, or the static row N for a plane) along its unit normal n,
pointing towards a. With ρ_a and ρ_b the radii (ρ_b = 0 on a plane), the lever arms are r_a = −ρ_a·n
and r_b = +ρ_b·n (Catto, "Iterative Dynamics with Temporal Coherence", GDC 2005; Box2D's
contact_solver.c):

- contact-point velocity of a relative to b: v_a − v_b + n × (ρ_a·ω_a + ρ_b·ω_b), less the surface
  velocity of a moving plane under the point;
- normal impulse P_n ≥ 0, effective mass m_n = 1/(1/m_a + 1/m_b): a sphere's lever arm is parallel to
  n, so spin never changes the normal speed v_n;
- friction P_t in the tangent plane, inside the Coulomb cone |P_t| ≤ μ·P_n, with the isotropic
  effective mass m_t = 1/(1/m_a + ρ_a²/I_a + 1/m_b + ρ_b²/I_b) (r is perpendicular to any tangent);
- rolling resistance R, an angular impulse opposing relative spin, |R| ≤ ρ_roll·P_n, with
  m_r = 1/(1/I_a + 1/I_b); on level ground it slows a rolling ball at (5/7)·ρ_roll·g;
- an impulse changes the balls by Δv_a = (P_n·n + P_t)/m_a, Δω_a = (−ρ_a·n × P_t + R)/I_a, and the
  opposite on b: Δv_b = −(P_n·n + P_t)/m_b, Δω_b = (−ρ_b·n × P_t − R)/I_b;
- a soft normal (Catto, "Soft constraints", GDC 2011; the soft step) gives way in proportion to the
  impulse it carries: ΔP_n = m_n·s·(target − v_n) − k·P_n, with mass scale s and impulse scale k.

Material mixing (e = e_a·e_b, μ = √(μ_a·μ_b), ρ_roll = √(ρ_a·ρ_b) times the rolling radius) is done once
per contact in rows.py. Per-contact vectors here are (3, K) columns, one contact a column, and every
sum over x, y, z is taken from first to last, so each solve gives the same bits on any CPU (exact.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..core import exact
from ..core.settings import NO_ZERO_DIVIDE


@dataclass
class Impulses:
    """Accumulated impulses per contact, as the warm start keeps them: normal (K,), friction (K, 3),
    rolling (K, 3)."""

    normal: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray

    @staticmethod
    def zeros(count: int) -> Impulses:
        return Impulses(np.zeros(count), np.zeros((count, 3)), np.zeros((count, 3)))


@dataclass(frozen=True)
class Softness:
    """A soft constraint's coefficients for a substep h (softstep.py's docstring has the formulas)."""

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


def inverse_effective_masses(
    inv_mass_a: np.ndarray,
    inv_mass_b: np.ndarray,
    inv_inertia_a: np.ndarray,
    inv_inertia_b: np.ndarray,
    arm_a: np.ndarray,
    arm_b: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """1/m_n, 1/m_t and 1/m_r of contacts whose balls have these inverse masses and inertias (each
    already multiplied by the ball's number of contacts where the mass is split, jacobi.py) and
    lever-arm lengths: how much a unit impulse changes the normal speed, the slip and the spin."""
    inv_n = inv_mass_a + inv_mass_b
    inv_t = inv_mass_a + arm_a**2 * inv_inertia_a + inv_mass_b + arm_b**2 * inv_inertia_b
    inv_r = np.maximum(inv_inertia_a + inv_inertia_b, NO_ZERO_DIVIDE)
    return inv_n, inv_t, inv_r


def effective_masses(
    inv_mass_a: np.ndarray,
    inv_mass_b: np.ndarray,
    inv_inertia_a: np.ndarray,
    inv_inertia_b: np.ndarray,
    arm_a: np.ndarray,
    arm_b: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The normal, tangential (friction) and angular (rolling resistance) effective masses m_n, m_t
    and m_r (see ``inverse_effective_masses``)."""
    inv_n, inv_t, inv_r = inverse_effective_masses(
        inv_mass_a, inv_mass_b, inv_inertia_a, inv_inertia_b, arm_a, arm_b
    )
    return 1.0 / inv_n, 1.0 / inv_t, 1.0 / inv_r


def contact_velocity(
    v_a: np.ndarray,
    w_a: np.ndarray,
    v_b: np.ndarray,
    w_b: np.ndarray,
    n: np.ndarray,
    arm_a: np.ndarray,
    arm_b: np.ndarray,
    surface: np.ndarray | None = None,
) -> np.ndarray:
    """The contact point's velocity of a relative to b, v_a − v_b + n × (ρ_a·ω_a + ρ_b·ω_b), less the
    ``surface`` velocity of a moving plane (all (3, K); ρ the lever-arm lengths, (K,))."""
    return point_velocity(v_a - v_b, spin_lever(w_a, w_b, arm_a, arm_b), n, surface)


def spin_lever(
    w_a: np.ndarray, w_b: np.ndarray, arm_a: np.ndarray, arm_b: np.ndarray, in_place: bool = False
) -> np.ndarray:
    """ρ_a·ω_a + ρ_b·ω_b: what the spins add to the contact point's velocity, crossed with n (formed
    in ``w_a``'s and ``w_b``'s own arrays, used up, when ``in_place``)."""
    if in_place:
        w_a *= arm_a
        w_a += np.multiply(w_b, arm_b, out=w_b)
        return w_a
    lever = arm_a * w_a
    lever += arm_b * w_b
    return lever


def point_velocity(
    dv: np.ndarray,
    lever: np.ndarray | None,
    n: np.ndarray,
    surface: np.ndarray | None = None,
    turn: np.ndarray | None = None,
) -> np.ndarray:
    """``contact_velocity`` from the relative velocity ``dv`` = v_a − v_b (changed in place and
    returned) and the ``spin_lever``: dv + n × lever − surface (n × lever given as ``turn`` if it was
    formed already; ``lever`` is then not read)."""
    dv += exact.cross_cols(n, lever) if turn is None else turn
    if surface is not None:
        dv -= surface
    return dv


def normal_speed(
    v_a: np.ndarray,
    v_b: np.ndarray,
    n: np.ndarray,
    surface: np.ndarray | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Each contact's normal speed v_n = (v_a − v_b)·n (negative: closing), against a moving plane's
    ``surface``; spin never changes it on spheres (a lever arm is parallel to n). With ``out`` ((3, K),
    may be ``v_a``) the difference and the sums are formed in it, and v_n is its first row."""
    if out is None:
        v_n = exact.dot_cols(v_a - v_b, n)
    else:
        v_n = exact.dot_cols_in_place(np.subtract(v_a, v_b, out=out), n)
    if surface is not None:
        v_n -= exact.dot_cols(surface, n)
    return v_n


def normal_impulse(
    accumulated: np.ndarray,
    m_n: np.ndarray,
    target: np.ndarray,
    v_n: np.ndarray,
    give: np.ndarray | float | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """The new accumulated normal impulse that drives v_n towards ``target``, kept ≥ 0 (a contact
    pushes, never pulls): P + m_n·(target − v_n), less ``give``·P for a soft contact (m_n then carries
    the mass scale, ``give`` is the impulse scale k). With ``out`` the impulses are formed in it and
    ``v_n`` is used up as scratch (the same operations)."""
    if out is None:
        new = accumulated + m_n * (target - v_n)
        if give is not None:
            new -= give * accumulated
    else:
        change = np.subtract(target, v_n, out=v_n)
        change *= m_n
        new = np.add(accumulated, change, out=out)
        if give is not None:
            new -= np.multiply(give, accumulated, out=change)
    return np.maximum(new, 0.0, out=new)


def within_limit(candidate: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """``candidate`` impulses (vectors along the second-to-last axis of length 3: (3, K) or stacked
    (2, 3, K)) scaled down to length ≤ ``limit``: the friction cone μ·P_n, or the rolling limit.
    ``candidate`` is scaled in place (every caller passes a temporary) and returned."""
    x, y, z = candidate[..., 0, :], candidate[..., 1, :], candidate[..., 2, :]
    length = x * x + y * y + z * z
    length += NO_ZERO_DIVIDE
    np.sqrt(length, out=length)
    scale = np.minimum(limit / length, 1.0)
    candidate *= scale[..., None, :]
    return candidate


class StickTerms(NamedTuple):
    """What ``stick`` needs of a contact that its masses and lever arms fix (``stick_terms``)."""

    lean: np.ndarray  # c·m_r: the friction impulse a unit of n × spin asks for, times D
    c: np.ndarray  # ρ_a/I_a − ρ_b/I_b
    d: np.ndarray  # D
    inv_r: np.ndarray  # 1/m_r


def stick_terms(
    inv_mass_a: np.ndarray,
    inv_mass_b: np.ndarray,
    inv_inertia_a: np.ndarray,
    inv_inertia_b: np.ndarray,
    arm_a: np.ndarray,
    arm_b: np.ndarray,
) -> StickTerms:
    """``stick``'s c, D and 1/m_r of contacts with these inverse masses, inertias and lever-arm lengths,
    formed once for every sweep of a solve."""
    inv_r = np.maximum(inv_inertia_a + inv_inertia_b, NO_ZERO_DIVIDE)
    c = arm_a * inv_inertia_a - arm_b * inv_inertia_b
    reach = arm_a + arm_b
    d = (inv_mass_a + inv_mass_b) + inv_inertia_a * inv_inertia_b * reach * reach / inv_r
    return StickTerms(c / inv_r, c, d, inv_r)


def stick(
    slip: np.ndarray, spin: np.ndarray, n: np.ndarray, terms: StickTerms
) -> tuple[np.ndarray, np.ndarray]:
    """The friction impulse P and rolling impulse R that together stop a contact's ``slip`` (its
    tangential contact-point velocity) and relative ``spin``: the two solved as one block, before the
    friction cone and the rolling limit are applied (``terms``: the contacts' ``stick_terms``).

    Solved one after the other, each undoes part of the other: friction turns the ball, rolling
    resistance stops the turn, which leaves slip again, and a lone ball coming to rest keeps 5/7 of its
    slip a sweep (its velocity never reaches zero). From the changes an impulse makes (the module's
    formulas), with c = ρ_a/I_a − ρ_b/I_b and 1/m_r = 1/I_a + 1/I_b:

        Δslip = P/m_t + c·(n × R),    Δspin = −c·(n × P) + R/m_r.

    Setting them to −slip and −spin: R = m_r·(c·(n × P) − spin), and P·D = c·m_r·(n × spin) − slip with
    D = 1/m_t − c²·m_r = 1/m_a + 1/m_b + (ρ_a + ρ_b)²/(I_a·I_b·(1/I_a + 1/I_b)), which is at least
    1/m_a + 1/m_b (written so: against a plane, D is 1/m_a exactly).
    """
    p = block_friction(slip, spin, n, terms)
    return p, block_rolling(p, spin, n, terms)


def block_friction(slip: np.ndarray, spin: np.ndarray, n: np.ndarray, terms: StickTerms) -> np.ndarray:
    """``stick``'s friction impulse P = (c·m_r·(n × spin) − slip)/D."""
    p = exact.cross_cols(n, spin)
    p *= terms.lean
    p -= slip
    p /= terms.d
    return p


def block_rolling(p: np.ndarray, spin: np.ndarray, n: np.ndarray, terms: StickTerms) -> np.ndarray:
    """``stick``'s rolling impulse R = m_r·(c·(n × P) − spin), from its friction impulse ``p``."""
    r = exact.cross_cols(n, p)
    r *= terms.c
    r -= spin
    r /= terms.inv_r
    return r


def separation_parts(inv_mass_a: np.ndarray, inv_mass_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How an overlap moving apart by positions is shared: a moves along n by its part of the overlap
    and b by its (negative) part, each in proportion to its inverse mass (split, in jacobi.py), so the
    lighter ball moves farther and a plane (inverse mass 0) not at all."""
    total = inv_mass_a + inv_mass_b
    return inv_mass_a / total, -inv_mass_b / total


def turn(n: np.ndarray, tangential: np.ndarray) -> np.ndarray:
    """n × P_t: what a tangential impulse at the contact turns each ball by, times −ρ/I."""
    return exact.cross_cols(n, tangential)
