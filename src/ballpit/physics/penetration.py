"""Penetration removal: overlapping balls are moved apart, by positions only.

No velocity is added, so removing an overlap never launches a ball (docs/architecture.md), and the potential
energy a separation adds against gravity is taken out of the moved balls' kinetic energy, so it never
adds energy either. Each overlapping contact's linearised gap g = n·(x_a − x_b) − offset is driven to
zero by a few Gauss–Seidel sweeps over the contact colours, each ball moved in proportion to its
inverse mass.
"""

from __future__ import annotations

import numpy as np

from . import contact_model, exact, jacobi
from .contacts import ContactPoints
from .model import Model
from .rows import ContactRows
from .settings import HOLD_SINK, JACOBI_FROM, OVERLAP_PER_RADIUS, OVERLAP_TOLERANCE, PENETRATION_SWEEPS
from .state import State, V, X, with_static


def remove_penetration(model: Model, state: State, c: ContactPoints, rows: ContactRows) -> bool:
    """Move overlapping balls apart along the contact normals (positions only), never through a plane;
    whether any ball moved."""
    radius = model.spheres.radius
    tolerance = min(OVERLAP_TOLERANCE, OVERLAP_PER_RADIUS * float(radius.min())) if len(radius) else 0.0
    if not np.any(c.gap < -tolerance):
        return False
    x = state.body[:, X]
    pos = with_static(x)
    if len(c) >= JACOBI_FROM:  # all contacts at once per sweep, with mass splitting
        sweeps = 2 * PENETRATION_SWEEPS  # a split ball moves only its share per sweep: twice as many
        jacobi.separate(c.a, c.b, c.normal, c.gap, rows.inv_mass_a, rows.inv_mass_b, pos, sweeps)
    else:
        _separate_by_colour(c, rows, pos)
    new = keep_sides_of_planes(model, state, x, pos[:-1], deeper=True)
    pay_for_lift(model, state, x, new, partly=True)
    moved = bool((new != x).any())
    x[:] = new
    return moved


def _separate_by_colour(c: ContactPoints, rows: ContactRows, pos: np.ndarray) -> None:
    """Gauss–Seidel sweeps over the contact colours; ``pos`` (N+1, 3) changes in place."""
    n = c.normal
    offset = exact.dot(n, pos[c.a] - pos[c.b]) - c.gap
    part_a, part_b = contact_model.separation_parts(rows.inv_mass_a, rows.inv_mass_b)
    for _ in range(PENETRATION_SWEEPS):
        for idx in rows.colours:
            a, b = c.a[idx], c.b[idx]
            gap = exact.dot(n[idx], pos[a] - pos[b]) - offset[idx]
            depth = np.maximum(-gap, 0.0)[:, None] * n[idx]
            pos[a] += depth * part_a[idx, None]
            pos[b] += depth * part_b[idx, None]
        pos[-1] = 0.0


def pay_for_lift(model: Model, state: State, old: np.ndarray, new: np.ndarray, partly: bool = False) -> None:
    """Take the potential energy a separation adds, ΔU = −Σ m·g·Δx, out of the moved balls' kinetic
    energy (their velocities scaled by √(1 − ΔU/K)), so removing overlaps never adds energy.

    Moving positions alone lifts balls against gravity: in a closed elastic box that once made the
    total energy creep up by 1e-5 every few seconds (nphysics #69 and haxball #2157 report the same).
    A lowering separation is left alone: energy lost there stays lost.

    When the moved balls' kinetic energy cannot pay for the whole lift, ``partly`` moves them only the
    part of the way it pays for, K/ΔU (``new`` changes in place), and stops them: the split step then
    leaves a resting overlap the soft step held (within its slop) as it is, instead of lifting a ball
    at rest out of it for nothing (pile.toml gained up to 1.7e-5 J a step that way, #24). Without it
    the balls are moved all the way (the soft step's push-outs, and planes that win).
    """
    moved = np.flatnonzero((new != old).any(axis=1))
    if moved.size == 0:
        return
    mass = model.spheres.mass[moved]
    lift = -exact.total(mass * exact.dot(new[moved] - old[moved], model.gravity))
    if lift <= 0.0:
        return
    v = state.body[moved, V]
    kinetic = 0.5 * exact.total(mass * exact.dot(v, v))
    if partly and kinetic < lift:
        new[moved] = old[moved] + (kinetic / lift) * (new[moved] - old[moved])
    scale = np.sqrt(max(0.0, 1.0 - lift / kinetic)) if kinetic > 0.0 else 0.0
    state.body[moved, V] = v * scale


def keep_sides_of_planes(model: Model, state: State, old: np.ndarray, new: np.ndarray,
                         deeper: bool = False) -> np.ndarray:  # fmt: skip
    """``new`` positions, except that no ball's centre crosses a plane on its way from ``old``, nor
    goes into one (``deeper``: the split step's push-apart) deeper than it touched or overlapped it
    (beyond HOLD_SINK of its radius): such a ball is stopped where it touches the plane (or where it
    was, if it already overlapped it). The soft step keeps its planes by solving every kept plane pair.

    Pushing apart many balls at one point can move a ball far along a normal that no plane contact
    limits (the plane was not within its reach), and planes are two-sided: through one, it would be
    pushed on out the wrong side.
    """
    moved = np.flatnonzero((new != old).any(axis=1))
    if moved.size == 0 or model.planes.count == 0:
        return new
    pose, half, radius = state.planes, model.planes.half_size, model.spheres.radius[moved]
    start, path = old[moved], new[moved] - old[moved]
    t = np.ones(len(moved))
    for p in range(model.planes.count):
        d0 = exact.dot(start - pose.center[p], pose.normal[p])
        d1 = d0 + exact.dot(path, pose.normal[p])
        crossing = (d0 >= 0.0) != (d1 >= 0.0)
        # nor is a ball moved into a plane, deeper than it touched or overlapped it, by more than
        # HOLD_SINK of its radius: that plane's contact may not be among the interval's touching
        # ones (it was out of reach before the move), and the ball would fly on into it (#25)
        floor = np.minimum(radius, np.abs(d0)) - HOLD_SINK * radius
        into = ~crossing & (np.where(d0 >= 0.0, d1, -d1) < floor) & deeper
        if not (crossing.any() or into.any()):
            continue
        k = np.flatnonzero(crossing | into)
        # where the centre crosses, or ends
        through = np.where(
            crossing[k, None], start[k] + (d0[k] / (d0[k] - d1[k]))[:, None] * path[k], new[moved[k]]
        )
        rel = through - pose.center[p]
        inside = (np.abs(exact.dot(rel, pose.axis_u[p])) <= half[p, 0]) & (
            np.abs(exact.dot(rel, pose.axis_v[p])) <= half[p, 1]
        )
        k = k[inside]
        # stop at the signed distance ±min(r, |d0|): touching it, on the side the ball came from
        stop = np.sign(d0[k]) * np.minimum(radius[k], np.abs(d0[k]))
        t[k] = np.minimum(t[k], (d0[k] - stop) / (d0[k] - d1[k]))
    out = new.copy()
    out[moved] = start + t[:, None] * path
    return out
