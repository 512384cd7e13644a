"""The resting solve: constant contact forces over an interval that leave every touching contact not
approaching and not slipping beyond the friction cone at the interval's end.

Solving for end-of-interval velocities and applying the impulses as constant forces keeps the
integrators exact: a resting ball's force cancels gravity, so it reports zero velocity.

The solve is warm-started from the forces of the last interval, looked up by each pair's own identity
(``contacts.pair_keys``), so a contact never picks up another pair's force when balls are added.
"""

from __future__ import annotations

import numpy as np

from . import exact, solver
from .contact_model import Impulses
from .contacts import ContactPoints, EventLog
from .forces import ConstantPerBall
from .model import Model
from .rows import ContactRows, rows_at_end
from .settings import JACOBI_FROM, WARM_START_SPAN
from .state import State, V, W, with_static


class WarmStart:
    """Last interval's resting forces (N, N·s/s per unit time), sorted by pair key."""

    def __init__(self) -> None:
        self.keys = np.zeros(0, np.int64)
        self.forces = Impulses.zeros(0)
        # per kept pair, how far a soft step's spring holds it apart beyond its overlap (softstep.py)
        self.apart = np.zeros(0)
        # the same three for the pairs of sleeping balls, put aside when they fell asleep (``put_to_sleep``)
        self.asleep = (np.zeros(0, np.int64), Impulses.zeros(0), np.zeros(0))

    def impulses(self, keys: np.ndarray, normal: np.ndarray, h: float) -> Impulses:
        """The kept forces of the pairs ``keys`` still touching, as impulses over ``h``."""
        imp = Impulses.zeros(len(keys))
        if len(self.keys) == 0:
            return imp
        pos = np.searchsorted(self.keys, keys)
        pos = np.minimum(pos, len(self.keys) - 1)
        found = self.keys[pos] == keys
        src = pos[found]
        imp.normal[found] = self.forces.normal[src] * h
        friction = self.forces.friction[src] * h
        n = normal[found]
        imp.friction[found] = friction - exact.dot(friction, n)[:, None] * n  # onto today's tangent plane
        imp.rolling[found] = self.forces.rolling[src] * h
        return imp

    def keep(self, keys: np.ndarray, imp: Impulses, h: float) -> None:
        """Remember the impulses found over ``h`` as forces, for the next solve."""
        order = np.argsort(keys)
        self.keys = keys[order]
        parts = (imp.normal, imp.friction, imp.rolling)
        self.forces = Impulses(*(_divided(part[order], h) for part in parts))
        self.apart = np.zeros(len(keys))

    def put_to_sleep(self, asleep: np.ndarray) -> None:
        """Put aside the kept forces of the pairs whose balls are all ``asleep`` (a plane counts as
        asleep): sleeping pairs are not solved, so the next ``keep`` would forget them, and a pile woken
        with no warm start sags under its own weight and springs back up, gaining energy (#24)."""
        held = _asleep_pairs(self.keys, asleep)
        if not held.any():
            return
        self.asleep = _merged(self.asleep, _rows((self.keys, self.forces, self.apart), held))

    def wake(self, asleep: np.ndarray) -> None:
        """Bring back the forces put aside of the pairs that are no longer all ``asleep``, for the next
        solve to start from."""
        keys = self.asleep[0]
        if len(keys) == 0:
            return
        still = _asleep_pairs(keys, asleep)
        if still.all():
            return
        woken = ~still
        fresh = ~np.isin(keys[woken], self.keys)  # a pair solved since keeps what it was solved to
        back = np.flatnonzero(woken)[fresh]
        merged = _merged((self.keys, self.forces, self.apart), _rows(self.asleep, back))
        self.keys, self.forces, self.apart = merged
        self.asleep = _rows(self.asleep, still)

    def apart_of(self, keys: np.ndarray) -> np.ndarray:
        """How far the soft springs of the pairs ``keys`` hold them apart (0 for pairs not kept)."""
        held = np.zeros(len(keys))
        if len(self.keys) == 0:
            return held
        pos = np.minimum(np.searchsorted(self.keys, keys), len(self.keys) - 1)
        found = self.keys[pos] == keys
        held[found] = self.apart[pos[found]]
        return held

    def keep_apart(self, keys: np.ndarray, apart: np.ndarray) -> None:
        """Remember ``apart`` for the pairs ``keys``, the ones just kept by ``keep``."""
        self.apart = apart[np.argsort(keys)]


def _divided(x: np.ndarray, h: float) -> np.ndarray:
    """x / h in place (x is a temporary): one array at a time, not two."""
    x /= h
    return x


def _asleep_pairs(keys: np.ndarray, asleep: np.ndarray) -> np.ndarray:
    """Which pairs ``keys`` (``contacts.pair_keys``) have every ball ``asleep``; a plane always."""
    a = (keys >> np.int64(32)).astype(np.intp)
    low = keys & np.int64(0xFFFFFFFF)
    plane = (low & np.int64(1 << 31)) != 0
    other = np.where(plane, 0, low).astype(np.intp)
    n = len(asleep)
    ok = (a < n) & (other < n)  # pairs of balls no longer in the world are dropped
    return ok & asleep[np.minimum(a, n - 1)] & (plane | asleep[np.minimum(other, n - 1)])


Kept = tuple[np.ndarray, Impulses, np.ndarray]  # pair keys, their forces and how far they are held apart


def _rows(kept: Kept, idx: np.ndarray) -> Kept:
    """The pairs ``idx`` (indices or a mask) of ``kept``."""
    keys, forces, apart = kept
    return keys[idx], Impulses(*(part[idx] for part in _parts(forces))), apart[idx]


def _merged(first: Kept, second: Kept) -> Kept:
    """Both sets of pairs, ``first``'s then ``second``'s, sorted by key (stably)."""
    keys = np.concatenate((first[0], second[0]))
    forces = Impulses(
        *(np.concatenate(pair) for pair in zip(_parts(first[1]), _parts(second[1]), strict=True))
    )
    apart = np.concatenate((first[2], second[2]))
    return _rows((keys, forces, apart), np.argsort(keys, kind="stable"))


def _parts(imp: Impulses) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return imp.normal, imp.friction, imp.rolling


def resting_forces(model: Model, state: State, c: ContactPoints, rows: ContactRows, lin: np.ndarray,
                   ang: np.ndarray, h: float, dt: float, min_normal_speed: np.ndarray, warm: WarmStart,
                   events: EventLog, now: float, jacobi_from: int = JACOBI_FROM
                   ) -> ConstantPerBall | None:  # fmt: skip
    """Constant contact forces over the next ``h`` seconds that leave each contact's normal speed at
    least ``min_normal_speed`` (0 for a touching contact, −gap/dt for a speculative one) at the
    interval's end.

    ``lin`` and ``ang`` are the free accelerations. The forces warm-start the next solve only when
    ``h`` is at least WARM_START_SPAN of the step ``dt``: the force that stops a slow arrival in the last
    sliver of a step is no force to hold for the next whole step. Warm-started with it, a column of
    balls is pre-stressed: the impulses cancel ball by ball, so the sweeps see nothing to correct until
    the stress reaches the top.
    """
    if len(c) == 0:
        return None
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    v[:-1] += lin * h
    w[:-1] += ang * h
    v_free, w_free = v.copy(), w.copy()
    keys = c.keys()
    imp = warm.impulses(keys, c.normal, h)
    if rows.moving and model.planes.angular_velocity.any():  # the contacts at the interval's end
        rows = rows_at_end(model, state, c, rows, lin, h, imp)
    solver.warm_start(rows, v, w, imp)
    solver.solve(rows, v, w, min_normal_speed, imp, model.solver_iterations, jacobi_from=jacobi_from)
    if h >= WARM_START_SPAN * dt:
        warm.keep(keys, imp, h)
    events.add_resting(now, c, keys, imp.normal)
    return ConstantPerBall((v[:-1] - v_free[:-1]) / h, (w[:-1] - w_free[:-1]) / h)
