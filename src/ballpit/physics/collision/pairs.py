"""Kept pairs: the broad phase's candidate pairs, kept from step to step until a ball's path leaves the
box it was paired from.

Boxes are swept over BROAD_PHASE_STEPS steps ahead, so most steps reuse their pairs: only the side
each ball is on of each plane is refreshed (a ball moved by hand may have crossed one). The pairs
expire when the number of balls or planes changes, or when some ball's path for the coming interval
leaves its box or the sphere around its swept path. While a plane moves, the sphere–plane pairs are
found again every step, from the kept boxes and the plane's sweep over the step; those of planes
that stood still then and now are kept (``refresh_moving``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..core import exact
from ..core.settings import BROAD_PHASE_MARGIN, BROAD_PHASE_REACH, BROAD_PHASE_STEPS, ESCAPE_CHUNK, TINY
from ..core.state import State, V, X, shallow_copy
from ..dynamics import moving_planes
from ..dynamics.integrators import Integrator
from ..dynamics.model import Model
from . import broadphase


@dataclass
class KeptPairs:
    """Pairs the broad phase found for the coming steps, with the boxes they were found from."""

    lo: np.ndarray  # (N, 3) swept boxes (as found: views of the (3, N) columns, ``_columns``)
    hi: np.ndarray
    centre: np.ndarray  # (N, 3) and (N,): a sphere around each ball's swept path, tighter than its box
    reach: np.ndarray
    pair_i: np.ndarray  # sphere–sphere pairs, i < j (int32 while the balls' rows fit: ``find_pairs``)
    pair_j: np.ndarray
    sphere: np.ndarray  # sphere–plane pairs
    plane: np.ndarray
    side: np.ndarray  # ±1: the side of the plane the ball is on
    counts: tuple[int, int]  # balls and planes in the world when the pairs were found
    # (P,) the planes that stood still when their sphere–plane pairs were found (None: not known)
    still: np.ndarray | None = None
    # lo, hi and centre as contiguous (3, N) columns for ``escaped``, made when first needed (``among``
    # hands them on with the boxes)
    _columns: tuple[np.ndarray, ...] | None = field(default=None, repr=False, compare=False)

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
        """True when some ball's path for the next ``h`` leaves the box or sphere it was paired from.

        The path's pad and bend come from the integrator (``sag``, ``path_acceleration``); each value
        compared is formed by the same operations as ``Integrator.path_end`` and ``np.linalg.norm`` over
        rows (which sums the three squares in order), but on contiguous columns, ESCAPE_CHUNK balls at a
        time: the scratch stays in the cache, and the test stops at the first chunk with an escape.
        """
        body, radius, path = state.body, model.spheres.radius, model.integrator
        if self._columns is None:  # the boxes and spheres as contiguous (3, N) columns, made once
            self._columns = tuple(np.ascontiguousarray(a.T) for a in (self.lo, self.hi, self.centre))
        lo, hi, centre = self._columns
        n = len(body)
        if n and not np.count_nonzero(accel != accel[0]):
            # One acceleration for all (gravity, drag-free flight): a single column. A row that differs
            # from the first only in the sign of a zero moves ``end`` by a signed zero at most, which
            # none of the comparisons below can tell apart.
            accel = accel[:1]
        pad = radius + path.sag(exact.norm_rows(accel), h)
        lift = path.path_offset(accel, h).T  # ½h²·b: the path's bend (0 if straight)
        shared = lift.shape[1] == 1
        size = min(n, ESCAPE_CHUNK)
        x, end, d, e = np.empty((4, 3, size))  # scratch, one allocation
        far, tmp = np.empty((2, size))
        for start in range(0, n, ESCAPE_CHUNK):
            rows = slice(start, start + ESCAPE_CHUNK)
            m = min(ESCAPE_CHUNK, n - start)
            xs, ends, ds, es, fars, tmps = x[:, :m], end[:, :m], d[:, :m], e[:, :m], far[:m], tmp[:m]
            pads = pad[rows]
            np.copyto(xs, body[rows, X].T)
            np.multiply(body[rows, V].T, h, out=ends)
            ends += xs  # x + v·h
            ends += lift if shared else lift[:, rows]  # … + ½h²·b
            # the box around the chord, grown by pad, inside the kept box
            np.minimum(xs, ends, out=ds)
            ds -= pads
            if np.count_nonzero(ds < lo[:, rows]):
                return True
            np.maximum(xs, ends, out=ds)
            ds += pads
            if np.count_nonzero(ds > hi[:, rows]):
                return True
            # the chord's ends inside the sphere keep the whole chord inside (spheres are convex)
            np.subtract(xs, centre[:, rows], out=ds)
            exact.norm_cols(ds, es, fars)
            np.subtract(ends, centre[:, rows], out=ds)
            exact.norm_cols(ds, es, tmps)
            np.maximum(fars, tmps, out=fars)
            fars += pads
            if np.count_nonzero(fars > self.reach[rows]):
                return True
        return False


class PairCache:
    """The kept pairs between steps. ``for_step`` reuses them while they still cover every path;
    ``renew`` replaces them when a path changes inside a step (a bounce or a contact force).

    Both hand out only the pairs with a ball of ``awake`` in them (every pair when it is None: no ball
    sleeps); the kept pairs themselves stay whole."""

    def __init__(self) -> None:
        self.kept: KeptPairs | None = None

    def checkpoint(self) -> PairCache:
        """What ``restore`` needs to put the kept pairs back. Found pairs are replaced, never changed in
        place (but for their sides and plane pairs, which ``for_step`` refreshes on a copy's fields
        alike), so this shares their arrays."""
        saved = PairCache()
        saved.kept = None if self.kept is None else shallow_copy(self.kept)
        return saved

    def restore(self, saved: PairCache) -> None:
        """Put back the kept pairs of ``saved`` (a ``checkpoint``; it stays usable)."""
        self.kept = None if saved.kept is None else shallow_copy(saved.kept)

    def for_step(
        self, model: Model, state: State, accel: np.ndarray, dt: float, awake: np.ndarray | None
    ) -> KeptPairs:
        """The pairs for a step whose free acceleration is ``accel``: kept ones if they still hold."""
        c = self.kept
        counts = (model.spheres.count, model.planes.count)
        if c is None or c.counts != counts or c.escaped(model, state, accel, dt):
            return self.renew(model, state, dt, BROAD_PHASE_STEPS * dt, accel, accel, awake)
        if model.moving_planes():  # the planes moved since the pairs were found
            refresh_moving(model, state, c, dt)
        c.side = plane_sides(model, state, c.sphere, c.plane)
        return c.among(awake)

    def renew(
        self,
        model: Model,
        state: State,
        h: float,
        ahead: float,
        accel: np.ndarray,
        free: np.ndarray,
        awake: np.ndarray | None,
    ) -> KeptPairs:
        """Find pairs afresh and keep them (they cover ``ahead`` seconds, so later steps reuse them)."""
        self.kept = find_pairs(model, state, h, ahead, accel, free)
        return self.kept.among(awake)


def refresh_moving(model: Model, state: State, c: KeptPairs, h: float) -> None:
    """Find again the sphere–plane pairs of ``c`` for the planes that move now or moved when their
    pairs were found, from the kept boxes and each plane's sweep over ``h``.

    The others stood still then and now, so finding theirs again from the same boxes would give the
    same pairs; they are kept, and the result is the same pairs in the same order (plane by plane) as
    finding every plane's again.
    """
    still = ~model.moving_plane_mask()
    again = ~still if c.still is None else ~(still & c.still)
    if again.all():
        c.sphere, c.plane = plane_pairs(model, state, c.lo, c.hi, h)
    else:
        keep = ~again[c.plane]
        s, p = plane_pairs(model, state, c.lo, c.hi, h, planes=np.flatnonzero(again))
        sphere, plane = np.concatenate((c.sphere[keep], s)), np.concatenate((c.plane[keep], p))
        order = np.argsort(plane, kind="stable")  # plane by plane, each plane's balls as found
        c.sphere, c.plane = sphere[order], plane[order]
    c.still = still


def plane_sides(model: Model, state: State, sphere: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """±1: which side of each plane each ball's centre is on (+1 on the normal's side or in it)."""
    pose = state.planes
    signed = np.einsum("ij,ij->i", state.body[sphere, 0:3] - pose.center[plane], pose.normal[plane])
    return np.where(signed < 0.0, -1.0, 1.0)


def find_pairs(
    model: Model, state: State, h: float, ahead: float, accel: np.ndarray, free: np.ndarray
) -> KeptPairs:
    """Candidate pairs from boxes around each ball's swept path.

    Each box covers the next ``h`` seconds under ``accel`` (contact forces included), and beyond it
    up to ``ahead`` seconds of free flight under ``free`` for balls slow enough to travel less than
    BROAD_PHASE_REACH radii in that time: slow balls keep their pairs for several steps while fast
    ones do not drag big boxes through a crowd.

    The paths are ``Integrator.path_end`` on contiguous (3, N) columns, and their lengths are
    ``np.linalg.norm`` over rows as ``exact.norm_cols`` forms it on columns (three squares summed in
    order).
    """
    body, radius = state.body, model.spheres.radius
    path: Integrator = model.integrator
    n = len(body)
    x, v = np.ascontiguousarray(body[:, X].T), np.ascontiguousarray(body[:, V].T)
    accel_t, free_t = accel.T, free.T
    scratch = np.empty((3, n))
    speed = exact.norm_cols(v, scratch, np.empty(n))
    horizon = np.clip(BROAD_PHASE_REACH * radius / np.maximum(speed, TINY), h, max(h, ahead))
    now = path.path_end(x, v, accel_t, h)
    later = path.path_end(x, v, free_t, horizon)
    # how far the paths can stray from their chords, over this step and over the horizon
    free_norm = exact.norm_cols(free_t, scratch, np.empty(n))
    accel_norm = free_norm if accel is free else exact.norm_cols(accel_t, scratch, np.empty(n))
    sag = path.cover_sag(accel_norm, h) + path.cover_sag(free_norm, horizon)
    pad = radius + sag + BROAD_PHASE_MARGIN * radius + model.contact_slop()
    lo = np.minimum(x, now)
    np.minimum(lo, later, out=lo)
    hi = np.maximum(x, now, out=now)
    np.maximum(hi, later, out=hi)
    centre = lo + hi
    centre *= 0.5
    np.subtract(hi, lo, out=scratch)
    reach = exact.norm_cols(scratch, scratch, np.empty(n))
    reach *= 0.5
    reach += pad
    lo -= pad
    hi += pad
    rows = tuple(np.ascontiguousarray(c.T) for c in (lo, hi, centre))  # (N, 3), for the broad phase
    i, j = broadphase.within_reach(*broadphase.sphere_pairs(rows[0], rows[1]), rows[2], reach)
    if n < 2**31:  # kept for many steps: 4 bytes a ball index, not 8 (the narrow phase widens them)
        i, j = i.astype(np.int32), j.astype(np.int32)
    s, p = plane_pairs(model, state, rows[0], rows[1], ahead)
    del rows  # kept as views of the columns: one copy of the boxes, not two (72 bytes a ball)
    counts = (model.spheres.count, model.planes.count)
    sides = plane_sides(model, state, s, p)
    still = ~model.moving_plane_mask()
    return KeptPairs(
        lo.T, hi.T, centre.T, reach, i, j, s, p, sides, counts, still=still, _columns=(lo, hi, centre)
    )


def plane_pairs(
    model: Model, state: State, lo: np.ndarray, hi: np.ndarray, h: float, planes: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(sphere, plane) pairs whose boxes reach the plane, as it is or as it moves over ``h``, for the
    ``planes`` given (all when None)."""
    pose, pl = state.planes, model.planes
    reach = None
    if model.moving_planes():
        reach = lambda p, distance: moving_planes.sweep(model, p, h, distance)  # noqa: E731
    return broadphase.sphere_plane_pairs(
        lo, hi, pose.center, pose.normal, pose.axis_u, pose.axis_v, pl.half_size, reach, planes
    )
