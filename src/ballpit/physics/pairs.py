"""Kept pairs: the broad phase's candidate pairs, kept from step to step until a ball's path leaves the
box it was paired from.

Boxes are swept over BROAD_PHASE_STEPS steps ahead, so most steps reuse their pairs: only the side
each ball is on of each plane is refreshed (a ball moved by hand may have crossed one). The pairs
expire when the number of balls or planes changes, or when some ball's path for the coming interval
leaves its box or the sphere around its swept path. While a plane moves, the sphere–plane pairs are
found again every step, from the kept boxes and the plane's sweep over the step.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import broadphase, moving_planes
from .integrators import Integrator
from .model import Model
from .state import State, V, X

# Balls closer than this (m) are in contact: the solver holds them, time of impact stops here.
CONTACT_SLOP = 1e-5
# Broad-phase boxes cover this many steps of each ball's path, so most steps reuse the pairs.
BROAD_PHASE_STEPS = 4
# … or as far as a ball travels this fraction of its radius, if that is sooner (but never less than
# the step itself) …
BROAD_PHASE_REACH = 0.2
# … and are grown by this fraction of the ball's radius, so slow balls keep their pairs for longer.
BROAD_PHASE_MARGIN = 0.1


@dataclass
class KeptPairs:
    """Pairs the broad phase found for the coming steps, with the boxes they were found from."""

    lo: np.ndarray  # (N, 3) swept boxes
    hi: np.ndarray
    centre: np.ndarray  # (N, 3) and (N,): a sphere around each ball's swept path, tighter than its box
    reach: np.ndarray
    pair_i: np.ndarray  # sphere–sphere pairs, i < j
    pair_j: np.ndarray
    sphere: np.ndarray  # sphere–plane pairs
    plane: np.ndarray
    side: np.ndarray  # ±1: the side of the plane the ball is on
    counts: tuple[int, int]  # balls and planes in the world when the pairs were found

    def __len__(self) -> int:
        return len(self.pair_i) + len(self.sphere)

    def among(self, awake: np.ndarray | None) -> KeptPairs:
        """The pairs with an awake ball in them (all of them when ``awake`` is None): two sleeping balls,
        or a sleeping ball and a plane, are neither measured nor solved (``sleeping.py``)."""
        if awake is None:
            return self
        balls, spheres = awake[self.pair_i] | awake[self.pair_j], awake[self.sphere]
        return replace(
            self,
            pair_i=self.pair_i[balls],
            pair_j=self.pair_j[balls],
            sphere=self.sphere[spheres],
            plane=self.plane[spheres],
            side=self.side[spheres],
        )

    def escaped(self, model: Model, state: State, accel: np.ndarray, h: float) -> bool:
        """True when some ball's path for the next ``h`` leaves the box or sphere it was paired from."""
        body, radius = state.body, model.spheres.radius
        x = body[:, X]
        path = model.integrator
        end = path.path_end(x, body[:, V], accel, h)
        pad = radius + path.sag(accel, h)
        box_pad = pad[:, None]
        if np.any(np.minimum(x, end) - box_pad < self.lo) or np.any(np.maximum(x, end) + box_pad > self.hi):
            return True
        # the chord's ends inside the sphere keep the whole chord inside (spheres are convex)
        farthest = np.maximum(
            np.linalg.norm(x - self.centre, axis=1), np.linalg.norm(end - self.centre, axis=1)
        )
        return bool(np.any(farthest + pad > self.reach))


class PairCache:
    """The kept pairs between steps. ``for_step`` reuses them while they still cover every path;
    ``renew`` replaces them when a path changes inside a step (a bounce or a contact force).

    While some balls sleep, ``awake`` masks the balls and both hand out only the pairs with an awake
    ball in them (the kept pairs themselves stay whole)."""

    def __init__(self) -> None:
        self.kept: KeptPairs | None = None
        self.awake: np.ndarray | None = None

    def for_step(self, model: Model, state: State, accel: np.ndarray, dt: float) -> KeptPairs:
        """The pairs for a step whose free acceleration is ``accel``: kept ones if they still hold."""
        c = self.kept
        counts = (model.spheres.count, model.planes.count)
        if c is None or c.counts != counts or c.escaped(model, state, accel, dt):
            return self.renew(model, state, dt, BROAD_PHASE_STEPS * dt, accel, accel)
        if model.moving_planes():  # the planes moved since the pairs were found
            c.sphere, c.plane = plane_pairs(model, state, c.lo, c.hi, dt)
        c.side = plane_sides(model, state, c.sphere, c.plane)
        return c.among(self.awake)

    def renew(self, model: Model, state: State, h: float, ahead: float, accel: np.ndarray,
              free: np.ndarray) -> KeptPairs:  # fmt: skip
        """Find pairs afresh and keep them (they cover ``ahead`` seconds, so later steps reuse them)."""
        self.kept = find_pairs(model, state, h, ahead, accel, free)
        return self.kept.among(self.awake)


def plane_sides(model: Model, state: State, sphere: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """±1: which side of each plane each ball's centre is on (+1 on the normal's side or in it)."""
    pose = state.planes
    signed = np.einsum("ij,ij->i", state.body[sphere, 0:3] - pose.center[plane], pose.normal[plane])
    return np.where(signed < 0.0, -1.0, 1.0)


def find_pairs(model: Model, state: State, h: float, ahead: float, accel: np.ndarray,
               free: np.ndarray) -> KeptPairs:  # fmt: skip
    """Candidate pairs from boxes around each ball's swept path.

    Each box covers the next ``h`` seconds under ``accel`` (contact forces included), and beyond it
    up to ``ahead`` seconds of free flight under ``free`` for balls slow enough to travel less than
    BROAD_PHASE_REACH radii in that time: slow balls keep their pairs for several steps while fast
    ones do not drag big boxes through a crowd.
    """
    body, radius = state.body, model.spheres.radius
    path: Integrator = model.integrator
    x, v = body[:, X], body[:, V]
    speed = np.linalg.norm(v, axis=1)
    horizon = np.clip(BROAD_PHASE_REACH * radius / np.maximum(speed, 1e-12), h, max(h, ahead))
    now = path.path_end(x, v, accel, h)
    later = path.path_end(x, v, free, horizon[:, None])
    # a parabola strays at most ⅛·|a|·t² from its chord
    sag = 0.125 * (np.linalg.norm(accel, axis=1) * h * h + np.linalg.norm(free, axis=1) * horizon**2)
    pad = (radius + sag + BROAD_PHASE_MARGIN * radius + CONTACT_SLOP)[:, None]
    lo = np.minimum(np.minimum(x, now), later)
    hi = np.maximum(np.maximum(x, now), later)
    centre = 0.5 * (lo + hi)
    reach = 0.5 * np.linalg.norm(hi - lo, axis=1) + pad[:, 0]
    lo -= pad
    hi += pad
    i, j = broadphase.within_reach(*broadphase.sphere_pairs(lo, hi), centre, reach)
    s, p = plane_pairs(model, state, lo, hi, ahead)
    counts = (model.spheres.count, model.planes.count)
    return KeptPairs(lo, hi, centre, reach, i, j, s, p, plane_sides(model, state, s, p), counts)


def plane_pairs(model: Model, state: State, lo: np.ndarray, hi: np.ndarray,
                h: float) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(sphere, plane) pairs whose boxes reach the plane, as it is or as it moves over ``h``."""
    pose, pl = state.planes, model.planes
    reach = None
    if model.moving_planes():
        reach = lambda p, distance: moving_planes.sweep(model, p, h, distance)  # noqa: E731
    return broadphase.sphere_plane_pairs(
        lo, hi, pose.center, pose.normal, pose.axis_u, pose.axis_v, pl.half_size, reach
    )
