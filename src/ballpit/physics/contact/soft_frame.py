"""A soft frame's contacts and the balls they touch, as the stages of the soft step share them
(softstep.py, separate.py): Box2D's prepare contacts."""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.contacts import ContactPoints
from ..core.settings import CONTACT_HERTZ, DAMPING_RATIO, PLANE_STIFFNESS, SOFT_RATE_CAP
from ..core.state import Q, State, V, W, X
from ..dynamics.forces import ForceTerm, constant_acceleration, forces_of
from ..dynamics.model import Model
from . import jacobi
from .contact_model import softness
from .resting import WarmStart
from .rows import contact_rows


class SoftFrame:
    """A soft frame's contacts and the balls they touch, as the stages share them (Box2D's prepare
    contacts): the contacts ``c``, their ``rows`` and solve columns ``k`` (jacobi.py); the M balls'
    positions ``x`` (from ``x0``), velocities and spins ``vw`` ((3, M) and (6, M) columns; the static
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
        self.rows = contact_rows(model, state, c)
        k = self.k = jacobi.ContactColumns(self.rows)
        body = state.body
        self.k_balls = k.balls
        m_dyn = int(np.searchsorted(k.balls, n_balls))  # the static row N, if there, is the last column
        self.idx, self.live = k.balls[:m_dyn], slice(0, m_dyn)
        idx, live, m = self.idx, self.live, k.m
        x = self.x = np.zeros((3, m))
        x[:, live] = body[idx, X].T
        self.x0 = x.copy()
        vw = self.vw = np.zeros((6, m))
        vw[:3, live] = body[idx, V].T
        vw[3:, live] = body[idx, W].T
        self.q = body[idx, Q].copy()
        self.terms = forces_of(forces, idx, n_balls)
        self.constant = constant_acceleration(self.terms)
        kc = k.k
        self.n = k.n
        self.ends_a, self.ends_b = k.ends[:kc], k.ends[kc:]
        self.on_plane = self.rows.b == n_balls
        # the surface's own speed along the normal (moving planes), to move their side of s
        self.surface_n = exact.dot_cols(k.surface, k.n) if k.surface is not None else None
        hertz = min(CONTACT_HERTZ, SOFT_RATE_CAP / h)
        self.ball_soft, self.plane_soft = (
            softness(hertz, DAMPING_RATIO, h),
            softness(PLANE_STIFFNESS * hertz, DAMPING_RATIO, h),
        )
        self.vn_start = k.normal_speeds(vw)  # recorded at the frame's start, for the restitution pass
        self.keys = c.keys()
        imp = warm.impulses(self.keys, c.normal, h)
        self.apart = warm.apart_of(self.keys)
        self.normal = imp.normal.copy()
        self.tangential = np.ascontiguousarray(np.stack((imp.friction, imp.rolling)).transpose(0, 2, 1))
        self.came_with = (
            imp.normal
        )  # the warm start's normal impulses; its friction and rolling are in tangential
        self.total = np.zeros(kc)
        self.least = c.gap.copy()
        self.farthest, self.largest = np.zeros(m), np.zeros(m)
        self.lo, self.hi = x[:, live].copy(), x[:, live].copy()

    def soft(self, name: str) -> np.ndarray:
        """Each contact's soft coefficient ``name`` (a ``Softness`` field), made when used (K floats)."""
        return np.where(self.on_plane, getattr(self.plane_soft, name), getattr(self.ball_soft, name))

    def separation(self, t: float) -> np.ndarray:
        """s = s₀ + n·(Δx_a − Δx_b): each contact's separation from the balls' moved positions (and a
        moving plane's surface, moved by its speed along n for ``t``)."""
        d = self.x - self.x0
        s = self.c.gap + exact.dot_cols(
            np.take(d, self.ends_a, axis=1) - np.take(d, self.ends_b, axis=1), self.n
        )
        if self.surface_n is not None:
            s -= self.surface_n * t
        return s
