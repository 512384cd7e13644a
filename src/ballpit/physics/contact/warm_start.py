"""The warm start: the last interval's contact forces, kept by each pair's own identity
(``contacts.pair_keys``), so the next solve starts from them and a contact never picks up another
pair's force when balls are added; the forces of sleeping pairs are put aside until they wake."""

from __future__ import annotations

import numpy as np

from ..core import exact
from ..core.contacts import find_keys
from ..core.settings import SWEEP_CHUNK
from ..core.state import shallow_copy
from .contact_model import Impulses


class WarmStart:
    """Last interval's resting forces (N, N·s/s per unit time), sorted by pair key."""

    def __init__(self) -> None:
        self.keys = np.zeros(0, np.int64)
        self.forces = Impulses.zeros(0)
        # per kept pair, how far a soft step's spring holds it apart beyond its overlap (softstep.py)
        self.apart = np.zeros(0)
        # the same three for the pairs of sleeping balls, put aside when they fell asleep (``put_to_sleep``)
        self.asleep = (np.zeros(0, np.int64), Impulses.zeros(0), np.zeros(0))

    def checkpoint(self) -> WarmStart:
        """What ``restore`` needs to put the warm start back: its arrays are replaced, never changed in
        place, so this shares them."""
        return shallow_copy(self)

    def restore(self, saved: WarmStart) -> None:
        """Put back the warm start ``saved`` (a ``checkpoint``; it stays usable)."""
        self.__dict__.update(vars(saved))

    def lookup(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Which of the pairs ``keys`` are kept, and where, as ``impulses`` and ``apart_of`` look them
        up (a caller asking both for the same pairs looks them up once); None when nothing is kept."""
        return self._found(keys) if len(self.keys) else None

    def _found(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which of the pairs ``keys`` are kept, and where (the kept rows of those found)."""
        found, pos = find_keys(self.keys, keys)
        return found, pos[found]

    def normal_impulses(self, keys: np.ndarray, h: float) -> np.ndarray:
        """The normal part of ``impulses``."""
        normal = np.zeros(len(keys))
        if len(self.keys):
            found, src = self._found(keys)
            normal[found] = self.forces.normal[src] * h
        return normal

    def impulses(
        self,
        keys: np.ndarray,
        normal: np.ndarray,
        h: float,
        tangential: np.ndarray | None = None,
        at: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> Impulses:
        """The kept forces of the pairs ``keys`` still touching, as impulses over ``h``; the friction
        and rolling impulses into ``tangential`` when given (zeros, (2, 3, K): ``jacobi.sweeps``' block)
        as views of its rows, with no (K, 3) arrays of their own. ``at``: ``lookup(keys)``, if made."""
        if tangential is None:
            imp = Impulses.zeros(len(keys))
        else:
            imp = Impulses(np.zeros(len(keys)), tangential[0].T, tangential[1].T)
        if len(self.keys) == 0:
            return imp
        found, src = self._found(keys) if at is None else at
        imp.normal[found] = self.forces.normal[src] * h
        if len(src) <= SWEEP_CHUNK:
            imp.friction[found] = _on_tangent_plane(self.forces.friction[src] * h, normal[found])
            imp.rolling[found] = self.forces.rolling[src] * h
            return imp
        rows = np.flatnonzero(found)  # SWEEP_CHUNK pairs at a time: the (chunk, 3) temporaries of a chunk
        for lo in range(0, len(src), SWEEP_CHUNK):
            to, at = rows[lo : lo + SWEEP_CHUNK], src[lo : lo + SWEEP_CHUNK]
            imp.friction[to] = _on_tangent_plane(self.forces.friction[at] * h, normal[to])
            imp.rolling[to] = self.forces.rolling[at] * h
        return imp

    def keep(self, keys: np.ndarray, imp: Impulses, h: float) -> np.ndarray:
        """Remember the impulses found over ``h`` as forces, for the next solve; returns the order the
        pairs ``keys`` are kept in (for ``keep_apart``)."""
        order = np.argsort(keys)
        self.keys = keys[order]
        # friction and rolling sorted into one (2, 3, K) block, the size of a frame's impulse blocks,
        # so that the heap's room for one serves the other (the same values as sorting each)
        tangential = np.empty((2, 3, len(order)))
        for into, part in zip(tangential, (imp.friction, imp.rolling), strict=True):
            np.take(part.T, order, axis=1, out=into)
        self.forces = Impulses(_divided(imp.normal[order], h), *_divided(tangential, h).transpose(0, 2, 1))
        self.apart = np.zeros(len(keys))
        return order

    def put_to_sleep(self, asleep: np.ndarray) -> None:
        """Put aside the kept forces of the pairs whose balls are all ``asleep`` (a plane counts as
        asleep): sleeping pairs are not solved, so the next ``keep`` would forget them, and a pile woken
        with no warm start sags under its own weight and springs back up, gaining energy."""
        held = _asleep_pairs(self.keys, asleep)
        if not np.count_nonzero(held):
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
        back = woken.nonzero()[0][fresh]
        merged = _merged((self.keys, self.forces, self.apart), _rows(self.asleep, back))
        self.keys, self.forces, self.apart = merged
        self.asleep = _rows(self.asleep, still)

    def apart_of(self, keys: np.ndarray, at: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """How far the soft springs of the pairs ``keys`` hold them apart (0 for pairs not kept);
        ``at``: ``lookup(keys)``, if made."""
        held = np.zeros(len(keys))
        if len(self.keys) == 0:
            return held
        found, src = self._found(keys) if at is None else at
        held[found] = self.apart[src]
        return held

    def keep_apart(self, apart: np.ndarray, order: np.ndarray) -> None:
        """Remember ``apart`` for the pairs just kept by ``keep``, given as they were given to it;
        ``order`` is the order it returned (the pairs are not sorted again)."""
        self.apart = apart[order]


def _on_tangent_plane(friction: np.ndarray, n: np.ndarray) -> np.ndarray:
    """The friction impulses (rows) onto today's tangent planes, of normals ``n``: f − (f·n)·n."""
    return friction - exact.dot_rows(friction, n)[:, None] * n


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
