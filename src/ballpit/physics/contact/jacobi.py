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
from ..core.settings import CONVERGED, SWEEP_CHUNK
from . import contact_model as model
from .columns import ContactColumns
from .contact_model import Impulses
from .rows import ContactRows


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
    speeds: list[np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """``count`` Jacobi sweeps driving each contact's v_n to ≥ ``target``: ``vw`` ((6, M) velocities
    and spins, or (3, M) velocities for normal impulses alone) changes in place; returns the new
    accumulated normal and tangential ((2, 3, K): friction, rolling) impulses. The ``normal`` and
    ``tangential`` given (a contiguous (2, 3, K) block) are taken as scratch by a full sweep: their
    values are not kept.

    Every ``friction_every``-th sweep and the last also update friction and rolling resistance (None:
    normal impulses alone). ``m_n`` and ``give`` make the normal soft (``contact_model.normal_impulse``;
    the soft step); ``converge`` stops after a full sweep that changed no contact velocity by more
    than CONVERGED. ``speeds``, if the caller has formed them, holds the contacts' normal speeds from ``vw``
    as given (``c.normal_speeds``): a first sweep of normal impulses alone takes them out of the list and
    uses them up instead of forming them, and nothing holds them after it."""
    m_n = c.m_n if m_n is None else m_n
    vn = speeds.pop() if speeds else None
    for sweep in range(count):
        full = friction_every is not None and ((sweep + 1) % friction_every == 0 or sweep == count - 1)
        if not full:
            normal = _normal_sweep(c, vw, c.push, normal, target, m_n, give, vn)
            vn = None
            continue
        vn = None
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
    _turns(turn, push[3:, :k], c.ra, c.rb, d_r)
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
    at_a, at_b = row[:k], row[k:]
    for r in range(3):  # Δv: ±(P_n·n + P_t)
        np.multiply(normal, n[r], out=at_a)
        at_a += d_t[r]
        np.negative(at_a, out=at_b)
        _add_row(c, vw[r], row, c.inverse[0])
    for r in range(3):  # Δω: −ρ·(n × P_t) ± R
        exact.cross_col(n, d_t, r, out=at_b)
        _turns(at_b, at_a, c.ra, c.rb, d_r[r])
        _add_row(c, vw[3 + r], row, c.inverse[1])


def _add_row(c: ContactColumns, into: np.ndarray, row: np.ndarray, inverse: np.ndarray) -> None:
    """Add one row of pushes per contact end, summed per ball and times each ball's m⁻¹ or I⁻¹, to
    ``into``: a row of the (rows, M) sums at a time, not the whole block."""
    summed = c.add_row(row)
    summed *= inverse
    into += summed


def _turns(turn: np.ndarray, at_a: np.ndarray, ra: np.ndarray, rb: np.ndarray, d_r: np.ndarray) -> None:
    """Δω's pushes from ``turn`` = n × P_t: −ρ_a·turn + R into ``at_a``, and −ρ_b·turn − R into
    ``turn`` itself. Formed as R − ρ_a·turn and −(ρ_b·turn + R), the same values as (−ρ_a)·turn + R and
    (−ρ_b)·turn − R (negation is exact), without keeping the negated radii (16 bytes a contact)."""
    np.multiply(turn, ra, out=at_a)
    np.subtract(d_r, at_a, out=at_a)
    turn *= rb
    turn += d_r
    np.negative(turn, out=turn)


def _normal_sweep(
    c: ContactColumns,
    vw: np.ndarray,
    push: np.ndarray,
    normal: np.ndarray,
    target: np.ndarray,
    m_n: np.ndarray,
    give: np.ndarray | float | None,
    vn: np.ndarray | None = None,
) -> np.ndarray:
    """One sweep of the normal impulses alone; ``vw`` changes in place. ``vn``: the normal speeds from
    ``vw``, if formed already (used up as scratch)."""
    k, n = c.k, c.n
    if vn is None:
        vn = c.normal_speeds(vw)
    new = model.normal_impulse(normal, m_n, target, vn, give, out=np.empty(k))
    d_n = np.subtract(new, normal, out=vn)  # in v_n's array, used up
    del vn
    if len(push) == 1:  # one row at a time (``apply``)
        row = push[0]
        for r in range(3):
            np.multiply(d_n, n[r], out=row[:k])
            np.negative(row[:k], out=row[k:])
            _add_row(c, vw[r], row, c.inverse[0])
        return new
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
    velocity change it made at any contact (m/s).

    The new impulses are formed SWEEP_CHUNK contacts at a time (``_full_chunk``) into ``motion``
    (the new tangential impulses) and the changes into the old impulses' blocks, which then is the
    next sweep's ``motion``: two (2, 3, K) blocks, the old and new normal impulses, and the
    temporaries of one chunk."""
    new, change = full_changes(c, vw, normal, tangential, target, motion, m_n, give, measure)
    return new, add_changes(c, vw, push, normal, tangential, motion), change


def full_changes(
    c: ContactColumns,
    vw: np.ndarray,
    normal: np.ndarray,
    tangential: np.ndarray,
    target: np.ndarray,
    motion: np.ndarray,
    m_n: np.ndarray,
    give: np.ndarray | float | None,
    measure: bool,
) -> tuple[np.ndarray, float]:
    """The first half of ``_full_sweep``: the new normal impulses (returned), the new tangential
    impulses into ``motion`` and the changes into the old ones' arrays, ``normal`` and ``tangential``,
    none yet added to the balls (``add_changes``); with the largest velocity change (when ``measure``)."""
    k = c.k
    new = np.empty(k)
    d_n = normal  # each chunk's changes where its old impulses were, once read
    change = 0.0
    for lo in range(0, k, SWEEP_CHUNK):
        part = slice(lo, min(lo + SWEEP_CHUNK, k))
        found = _full_chunk(c, vw, normal, tangential, target, motion, m_n, give, part, new, d_n, measure)
        change = max(change, found)
    return new, change


def add_changes(
    c: ContactColumns, vw: np.ndarray, push: np.ndarray, d_n: np.ndarray, d_t: np.ndarray, motion: np.ndarray
) -> np.ndarray:
    """The second half of ``_full_sweep``: add the changes ``d_n`` and ``d_t`` (``full_changes``) to the
    balls; ``d_t``'s block becomes the next full sweep's scratch. Returns the new tangential impulses
    (``motion``)."""
    c.motion = d_t
    apply(c, vw, push, d_n, d_t)
    return motion


def _full_chunk(
    c: ContactColumns,
    vw: np.ndarray,
    normal: np.ndarray,
    tangential: np.ndarray,
    target: np.ndarray,
    motion: np.ndarray,
    m_n: np.ndarray,
    give: np.ndarray | float | None,
    part: slice,
    new: np.ndarray,
    d_n: np.ndarray,
    measure: bool,
) -> float:
    """``_full_sweep`` for the contacts ``part``: their new normal impulses into ``new`` and the
    changes into ``d_n``; their new tangential impulses into ``motion`` and the changes into
    ``tangential``. Returns the largest velocity change among them (when ``measure``)."""
    k = c.k
    n = c.n[:, part]
    ea, eb = c.ends[:k][part], c.ends[k:][part]
    ra, rb = c.ra[part], c.rb[part]
    slip, spin = motion[0][:, part], motion[1][:, part]
    # the contact-point velocity (contact_model.contact_velocity) from the balls' velocities gathered a
    # (3, chunk) part at a time, each dropped once used
    if k <= SWEEP_CHUNK:  # one chunk: both ends' velocities and spins in one gather
        both = vw.take(c.ends, axis=1)
        wa, wb, dv, vb = both[3:, :k], both[3:, k:], both[:3, :k], both[:3, k:]
    else:
        wa, wb = vw[3:].take(ea, axis=1), vw[3:].take(eb, axis=1)
        dv = vb = None
    np.subtract(wa, wb, out=spin)  # the relative spin, for rolling resistance
    lever = model.spin_lever(wa, wb, ra, rb, in_place=True)  # in wa's array
    if dv is None:
        dv, vb = vw[:3].take(ea, axis=1), vw[:3].take(eb, axis=1, out=wb)
    dv -= vb
    turn = exact.cross_cols(n, lever, out=wb)
    del wa, wb, vb
    rel = model.point_velocity(dv, lever, n, None if c.surface is None else c.surface[:, part], turn)
    del lever, turn
    vn = exact.dot_cols(rel, n)
    old = normal[part]
    fresh = model.normal_impulse(old, _part(m_n, part), _part(target, part), vn, _part(give, part))
    new[part] = fresh
    np.subtract(fresh, old, out=d_n[part])
    # friction cancels slip inside the Coulomb cone; rolling resistance opposes relative spin
    np.multiply(vn, n, out=slip)
    np.subtract(rel, slip, out=slip)
    del dv, rel
    if c.spin is not None:
        spin -= c.spin[:, part]
    # the new impulses are formed in the slip's scratch, the change in the old impulses' block
    candidate = motion[:, :, part]
    candidate *= c.tangent_masses(part)
    before = tangential[:, :, part]
    np.subtract(before, candidate, out=candidate)
    limits = np.empty((2, len(vn)))
    np.multiply(c.friction[part], fresh, out=limits[0])
    np.multiply(c.rolling[part], fresh, out=limits[1])
    model.within_limit(candidate, limits)
    np.subtract(candidate, before, out=before)
    if not measure:
        return 0.0
    return max(float(np.abs(d_n[part]).max()) * c.inv_m_n, float(np.abs(before[0]).max()) * c.inv_m_t)


def _part(x: np.ndarray | float | None, part: slice) -> np.ndarray | float | None:
    """The contacts ``part`` of a per-contact array; a number (or None) stands for every contact."""
    return x[part] if isinstance(x, np.ndarray) and x.ndim else x
