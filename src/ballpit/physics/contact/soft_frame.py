"""A soft frame's contacts and the balls they touch, as the stages of the soft step share them
(softstep.py, separate.py): Box2D's prepare contacts."""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.contacts import ContactPoints
from ..core.settings import CONTACT_HERTZ, DAMPING_RATIO, PLANE_STIFFNESS, SOFT_RATE_CAP, SWEEP_CHUNK
from ..core.state import Q, State, V, W, X
from ..dynamics.forces import ForceTerm, constant_acceleration, forces_of
from ..dynamics.model import Model
from . import jacobi
from .contact_model import softness
from .rows import contact_rows
from .warm_start import WarmStart


class SoftFrame:
    """A soft frame's contacts and the balls they touch, as the stages share them (Box2D's prepare
    contacts): the contacts ``c``, their ``rows`` and solve columns ``k`` (jacobi.py); the M balls'
    positions ``x`` (from ``start``), velocities and spins ``vw`` ((3, M) and (6, M) columns; the static
    row N, if there, is the last column) and orientations ``q``; the accumulated impulses; and what the
    checks need (``total``, ``least``, ``farthest``, ``largest``, ``lo``, ``hi``).

    ``store_impulses`` lets go of the solve's columns and scratch (``k``, ``vw``, ``q``, the tangential
    impulses), so that moving overlaps apart does not hold them too (the peak memory of a settled
    pile)."""

    def __init__(
        self,
        model: Model,
        state: State,
        c: ContactPoints,
        forces: list[ForceTerm],
        dt: float,
        warm: WarmStart,
        substeps: int,
    ) -> None:
        self.c, self.dt = c, dt
        self.h = h = dt / substeps
        n_balls = model.spheres.count
        # the frame's two (2, 3, K) impulse blocks made first, while the heap still has the room the
        # previous frame's left whole (made after the rows and columns, they found no hole that fits)
        kc = len(c)
        self.tangential = np.zeros((2, 3, kc))
        motion = np.empty((2, 3, kc))
        self.rows = contact_rows(model, state, c)
        k = self.k = jacobi.ContactColumns(self.rows, split=False, motion=motion)  # each substep splits
        del motion
        self.rows.forget_radii()  # the solve reads the arms' lengths (``k.ra``, ``k.rb``) alone
        if len(c) > SWEEP_CHUNK:  # and each ball's inverse mass and inertia (``k.inverse``)
            self.rows.forget_masses()
        body = state.body
        self.k_balls = k.balls
        m_dyn = int(np.searchsorted(k.balls, n_balls))  # the static row N, if there, is the last column
        self.idx, self.live = k.balls[:m_dyn], slice(0, m_dyn)
        idx, live, m = self.idx, self.live, k.m
        x = self.x = np.zeros((3, m))
        x[:, live] = body[idx, X].T
        # x₀, the positions the frame started from, is read from the balls' block, which the frame
        # leaves as it found it until ``store_impulses`` writes the balls back (``keep_start``): 24 bytes
        # a ball not held twice while the substeps solve
        self._body, self._x0 = body, None
        vw = self.vw = np.zeros((6, m))
        vw[:3, live] = body[idx, V].T
        vw[3:, live] = body[idx, W].T
        self.q = body[idx, Q].copy()
        self.terms = forces_of(forces, idx, n_balls)
        self.constant = constant_acceleration(self.terms)
        kc = k.k
        self.n = k.n
        self.k_ends = k.ends
        self.ends_a, self.ends_b = k.ends[:kc], k.ends[kc:]
        self.on_plane = self.rows.b == n_balls
        # the surface's own speed along the normal (moving planes), to move their side of s
        self.surface_n = exact.dot_cols(k.surface, k.n) if k.surface is not None else None
        hertz = min(CONTACT_HERTZ, SOFT_RATE_CAP / h)
        self.ball_soft, self.plane_soft = (
            softness(hertz, DAMPING_RATIO, h),
            softness(PLANE_STIFFNESS * hertz, DAMPING_RATIO, h),
        )
        # the pairs' keys, the warm start's normal impulses and the normal speeds at the frame's start
        # are found again when needed (``keys``, ``came_with``, ``start_speeds``), not held through the
        # substeps (24 bytes a contact each)
        keys = c.keys()
        at = warm.lookup(keys)
        self.normal = warm.impulses(keys, c.normal, h, self.tangential, at).normal
        self.apart = warm.apart_of(keys, at)
        del at
        self.total = np.zeros(kc)
        self.least = c.gap.copy()
        self.farthest, self.largest = np.zeros(m), np.zeros(m)
        self.lo, self.hi = x[:, live].copy(), x[:, live].copy()
        self._kept: tuple[float, np.ndarray] | None = None  # a separation kept for its next reader
        self.kept_order: np.ndarray | None = None  # how the warm start sorted the pairs (store_impulses)
        # what moving apart reads of the solve once it has let go of it (store_impulses): each contact's
        # unsplit 1/m_n and each ball's 1/m
        self.whole: np.ndarray | None = None
        self.inv_mass: np.ndarray | None = None

    def sweeps(self, terms: list, count: int, speeds: list[np.ndarray] | None = None) -> None:
        """``count`` Jacobi sweeps of the soft normal update (``jacobi.sweeps``, friction and rolling in
        the last), from the frame's impulses to its new ones. ``terms`` holds the target and, for a soft
        update, m_n and give (``jacobi.sweeps``): it is emptied, and they are let go once the last sweep
        has found its changes, before it adds them to the balls (three K arrays fewer at the solve's
        peak, when the caller holds them nowhere else). ``speeds``, if given, holds the contacts' normal
        speeds now (the first sweep's: taken and used up). The sweeps take the old impulses as scratch,
        and the frame lets go of them first, so that the old normal impulses go after the first sweep
        instead of being held through the rest (K floats)."""
        target, m_n, give = (*terms, None, None)[:3]
        terms.clear()
        k, vw = self.k, self.vw
        normal, _ = jacobi.sweeps(
            k, vw, self._handed_over(), None, target, count - 1, m_n=m_n, give=give, speeds=speeds
        )
        motion = k.motion
        new, _ = jacobi.full_changes(
            k, vw, normal, self.tangential, target, motion, k.m_n if m_n is None else m_n, give, False
        )
        del target, m_n, give
        self.tangential = jacobi.add_changes(k, vw, k.push, normal, self.tangential, motion)
        self.normal = new

    def _handed_over(self) -> np.ndarray:
        """The normal impulses, no longer held by the frame."""
        normal, self.normal = self.normal, None
        return normal

    def start(self) -> np.ndarray:
        """x₀ of the balls (the (3, M) live columns; read only): where each ball started the frame."""
        if self._x0 is not None:
            return self._x0
        if len(self.idx) == len(self._body):  # every ball: the block's own columns, not a gather
            return self._body[:, X].T
        return self._body[self.idx, X].T

    def keep_start(self, before: np.ndarray | None = None) -> None:
        """Before the balls' block changes: read x₀ (``start``) from ``before``, a copy of the block as
        the frame found it that nothing changes (the undo's: no third copy of the positions), or else
        keep a copy of x₀ of its own."""
        if before is not None:
            self._body = before
        elif self._x0 is None:
            self._x0 = self.start().copy()

    def ball_inverse_mass(self) -> np.ndarray:
        """Each ball's 1/m, by the solve's columns (``k.inverse``, or kept once it let go of them)."""
        return self.inv_mass if self.inv_mass is not None else self.k.inverse[0]

    def keys(self) -> np.ndarray:
        """The pairs' keys (``ContactPoints.keys``)."""
        return self.c.keys()

    def came_with(self, warm: WarmStart) -> np.ndarray:
        """The normal impulses the frame was warm-started with, from ``warm`` as it was then (before
        ``store_impulses`` keeps the frame's)."""
        return warm.normal_impulses(self.keys(), self.h)

    def start_speeds(self, state: State) -> np.ndarray:
        """Each contact's normal speed at the frame's start, from the balls' velocities in ``state``
        (not yet written back): the same columns and the same sums as the frame's own velocities then."""
        v = np.zeros((3, self.k.m))
        v[:, self.live] = state.body[self.idx, V].T
        return self.k.normal_speeds(v)

    def soft(self, name: str) -> np.ndarray:
        """Each contact's soft coefficient ``name`` (a ``Softness`` field), made when used (K floats)."""
        return np.where(self.on_plane, getattr(self.plane_soft, name), getattr(self.ball_soft, name))

    def separation(self, t: float, keep: bool = False) -> np.ndarray:
        """s = s₀ + n·(Δx_a − Δx_b): each contact's separation from the balls' moved positions (and a
        moving plane's surface, moved by its speed along n for ``t``). Read-only for its callers.

        With ``keep`` it is kept for the next call at the same ``t`` (which takes it, instead of forming
        it again) until the balls move (``moved``): a substep's relax and the next substep's solve (or
        the frame's moving apart) read the separation at the same positions."""
        kept, self._kept = self._kept, None
        if kept is not None and kept[0] == t:
            return kept[1]
        s = self._separation(t)
        if keep:
            self._kept = (t, s)
        return s

    def moved(self) -> None:
        """The balls' positions ``x`` changed: a kept separation no longer holds."""
        self._kept = None

    def _separation(self, t: float) -> np.ndarray:
        """``separation``, formed."""
        d = np.empty_like(self.x)
        np.subtract(self.x[:, self.live], self.start(), out=d[:, self.live])
        d[:, self.live.stop :] = 0.0  # the static column stays at 0 (x₀ there was 0 too)
        k = len(self.ends_a)
        if k <= SWEEP_CHUNK:  # both ends gathered at once, their difference and its sums in place
            g = d.take(self.k_ends, axis=1)
            s = self.c.gap + exact.dot_cols_in_place(np.subtract(g[:, :k], g[:, k:], out=g[:, :k]), self.n)
        else:  # SWEEP_CHUNK contacts at a time: the (3, chunk) gathers of a chunk, not of all
            s = np.empty(k)
            for lo in range(0, k, SWEEP_CHUNK):
                part = slice(lo, min(lo + SWEEP_CHUNK, k))
                moved = np.take(d, self.ends_a[part], axis=1) - np.take(d, self.ends_b[part], axis=1)
                np.add(self.c.gap[part], exact.dot_cols(moved, self.n[:, part]), out=s[part])
        if self.surface_n is not None:
            s -= self.surface_n * t
        return s
