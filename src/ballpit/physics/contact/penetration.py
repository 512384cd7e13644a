"""Penetration removal: overlapping balls are moved apart, by positions only.

No velocity is added, so removing an overlap never launches a ball (docs/architecture.md), and the potential
energy a separation adds against gravity is taken out of the moved balls' kinetic energy, so it never
adds energy either. Each overlapping contact's linearised gap g = n·(x_a − x_b) − offset is driven to
zero by a few Gauss–Seidel sweeps over the contact colours, each ball moved in proportion to its
inverse mass.
"""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.contacts import ContactPoints
from ..core.settings import (
    HOLD_SINK,
    JACOBI_FROM,
    OVERLAP_PER_RADIUS,
    PENETRATION_SWEEPS,
    PENETRATION_TOLERANCE,
    SWEEP_CHUNK,
)
from ..core.state import State, X, with_static
from ..dynamics.model import Model
from . import contact_model, energy_guard
from .ends import Ends
from .rows import ContactRows


def remove_penetration(model: Model, state: State, c: ContactPoints, rows: ContactRows) -> bool:
    """Move overlapping balls apart along the contact normals (positions only), never through a plane;
    whether any ball moved."""
    radius = model.spheres.radius
    tolerance = min(PENETRATION_TOLERANCE, OVERLAP_PER_RADIUS * float(radius.min())) if len(radius) else 0.0
    if not np.count_nonzero(c.gap < -tolerance):
        return False
    x = state.body[:, X]
    pos = with_static(x)
    if len(c) >= JACOBI_FROM:  # all contacts at once per sweep, with mass splitting
        sweeps = 2 * PENETRATION_SWEEPS  # a split ball moves only its share per sweep: twice as many
        separate(c.a, c.b, c.normal, c.gap, rows.inv_mass_a, rows.inv_mass_b, pos, sweeps)
    else:
        _separate_by_colour(c, rows, pos)
    new = keep_sides_of_planes(model, state, x, pos[:-1], deeper=True)
    energy_guard.pay_for_lift(model, state, x, new, partly=True)
    moved = bool(np.count_nonzero(new != x))
    x[:] = new
    return moved


def separate(
    a: np.ndarray,
    b: np.ndarray,
    normal: np.ndarray,
    gap: np.ndarray,
    inv_mass_a: np.ndarray | None,
    inv_mass_b: np.ndarray | None,
    pos: np.ndarray,
    sweeps: int,
    columns: tuple[Ends, np.ndarray] | None = None,
) -> None:
    """Move overlapping balls apart along their normals, all contacts at once per sweep: each
    contact's overlap (−``gap`` at the start, along the fixed normal) is shared between its balls in
    proportion to their split inverse masses. ``pos`` (N+1, 3) changes in place; row N is the world.

    Up to SWEEP_CHUNK contacts a sweep works on (3, K) and (3, 2K) blocks, one gather and one
    ``add_up`` each; beyond, one coordinate at a time, on (K,) and (2K,) rows: the same operations in
    the same order (v_n as ``exact.dot_cols`` sums it, each row added up as ``add_up`` does), without
    the blocks' memory.

    ``columns``, if given, are the contacts' ends as another solve numbered them and each ball's 1/m in
    that numbering, read instead of numbering the ends again and of ``inv_mass_a`` and ``inv_mass_b``
    (the same values: a contact's 1/m is its ball's)."""
    e = Ends(a, b) if columns is None else columns[0]
    k, balls, ends, share = e.k, e.balls, e.ends, e.share
    ea, eb = ends[:k], ends[k:]
    if columns is None:
        split_a, split_b = share[ea] * inv_mass_a, share[eb] * inv_mass_b
    else:  # each ball's n_b·m⁻¹ gathered per end: the same products
        split = share * columns[1]
        split_a, split_b = split.take(ea), split.take(eb)
        del split
    fa, fb = contact_model.separation_parts(split_a, split_b)  # each end's part
    del split_a, split_b
    n = np.ascontiguousarray(normal.T)
    x = np.ascontiguousarray(pos[balls].T)  # (3, M)
    start = _along(e, n, x).copy()  # (not the view of its gather's block)
    move = np.empty((3, 2 * k) if k <= SWEEP_CHUNK else 2 * k)  # the moves of each contact's a, then b
    for _ in range(sweeps):
        now = gap + _along(e, n, x) - start
        deficit = np.maximum(-now, 0.0)
        if k <= SWEEP_CHUNK:
            d = deficit * n
            np.multiply(d, fa, out=move[:, :k])
            np.multiply(d, fb, out=move[:, k:])
            # averaging the split copies of a ball: its moves add up, each with its own share 1/n_b
            summed = e.add_up(move)
            summed /= share
            x += summed
            continue
        for r in range(3):
            d = deficit * n[r]
            np.multiply(d, fa, out=move[:k])
            np.multiply(d, fb, out=move[k:])
            x[r] += e.add_row(move) / share
    pos[balls] = x.T
    pos[-1] = 0.0


def _along(e: Ends, n: np.ndarray, x: np.ndarray) -> np.ndarray:
    """n·(x_a − x_b) per contact of ``e`` from the (3, M) positions ``x``: both ends gathered at once up
    to SWEEP_CHUNK contacts, else SWEEP_CHUNK contacts at a time, a coordinate at a time."""
    k, ea, eb = e.k, e.ends[: e.k], e.ends[e.k :]
    if k <= SWEEP_CHUNK:
        g = x.take(e.ends, axis=1)
        return exact.dot_cols_in_place(np.subtract(g[:, :k], g[:, k:], out=g[:, :k]), n)
    d = np.empty(k)
    for lo in range(0, k, SWEEP_CHUNK):
        part = slice(lo, lo + SWEEP_CHUNK)
        a, b, out = ea[part], eb[part], d[part]
        np.multiply(n[0, part], x[0].take(a) - x[0].take(b), out=out)
        out += n[1, part] * (x[1].take(a) - x[1].take(b))
        out += n[2, part] * (x[2].take(a) - x[2].take(b))
    return d


def _separate_by_colour(c: ContactPoints, rows: ContactRows, pos: np.ndarray) -> None:
    """Gauss–Seidel sweeps over the contact colours; ``pos`` (N+1, 3) changes in place."""
    n = c.normal
    offset = exact.dot_rows(n, pos[c.a] - pos[c.b]) - c.gap
    part_a, part_b = contact_model.separation_parts(rows.inv_mass_a, rows.inv_mass_b)
    for _ in range(PENETRATION_SWEEPS):
        for idx in rows.colours:
            a, b = c.a[idx], c.b[idx]
            gap = exact.dot_rows(n[idx], pos[a] - pos[b]) - offset[idx]
            depth = np.maximum(-gap, 0.0)[:, None] * n[idx]
            pos[a] += depth * part_a[idx, None]
            pos[b] += depth * part_b[idx, None]
        pos[-1] = 0.0


def keep_sides_of_planes(
    model: Model, state: State, old: np.ndarray, new: np.ndarray, deeper: bool = False
) -> np.ndarray:
    """``new`` positions, except that no ball's centre crosses a plane on its way from ``old``, nor
    goes into one (``deeper``: the split step's push-apart) deeper than it touched or overlapped it
    (beyond HOLD_SINK of its radius): such a ball is stopped where it touches the plane (or where it
    was, if it already overlapped it). The soft step keeps its planes by solving every kept plane pair.

    Pushing apart many balls at one point can move a ball far along a normal that no plane contact
    limits (the plane was not within its reach), and planes are two-sided: through one, it would be
    pushed on out the wrong side.
    """
    moved = ((new != old).any(axis=1)).nonzero()[0]
    if moved.size == 0 or model.planes.count == 0:
        return new
    pose, half, radius = state.planes, model.planes.half_size, model.spheres.radius[moved]
    start, path = old[moved], new[moved] - old[moved]
    t = np.ones(len(moved))
    for p in range(model.planes.count):
        d0 = exact.dot_rows(start - pose.center[p], pose.normal[p])
        d1 = d0 + exact.dot_rows(path, pose.normal[p])
        crossing = (d0 >= 0.0) != (d1 >= 0.0)
        # nor is a ball moved into a plane, deeper than it touched or overlapped it, by more than
        # HOLD_SINK of its radius: that plane's contact may not be among the interval's touching
        # ones (it was out of reach before the move), and the ball would fly on into it
        floor = np.minimum(radius, np.abs(d0)) - HOLD_SINK * radius
        into = ~crossing & (np.where(d0 >= 0.0, d1, -d1) < floor) & deeper
        if not (np.count_nonzero(crossing) or np.count_nonzero(into)):
            continue
        k = (crossing | into).nonzero()[0]
        # where the centre crosses, or ends
        through = np.where(
            crossing[k, None], start[k] + (d0[k] / (d0[k] - d1[k]))[:, None] * path[k], new[moved[k]]
        )
        rel = through - pose.center[p]
        inside = (np.abs(exact.dot_rows(rel, pose.axis_u[p])) <= half[p, 0]) & (
            np.abs(exact.dot_rows(rel, pose.axis_v[p])) <= half[p, 1]
        )
        k = k[inside]
        # stop at the signed distance ±min(r, |d0|): touching it, on the side the ball came from
        stop = np.sign(d0[k]) * np.minimum(radius[k], np.abs(d0[k]))
        t[k] = np.minimum(t[k], (d0[k] - stop) / (d0[k] - d1[k]))
    out = new.copy()
    out[moved] = start + t[:, None] * path
    return out
