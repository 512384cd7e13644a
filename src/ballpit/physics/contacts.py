"""The record of contacts a step resolved: equal-length arrays, one entry per contact."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

SPHERE_PLANE = 0
SPHERE_SPHERE = 1
KIND_NAMES = ("sphere-plane", "sphere-sphere")


@dataclass(frozen=True)
class Contacts:
    """Contacts resolved in one step.

    ``time`` when each was resolved (world time, s); ``kind`` SPHERE_PLANE (0) or SPHERE_SPHERE (1);
    ``a`` the sphere; ``b`` the plane index (sphere-plane) or the other sphere; ``point`` (K, 3) the contact
    point; ``normal`` (K, 3) the unit normal pointing towards ``a``; ``impulse`` the normal impulse (N·s)
    given to ``a`` over the step.
    """

    time: np.ndarray
    kind: np.ndarray
    a: np.ndarray
    b: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    impulse: np.ndarray

    def __len__(self) -> int:
        return len(self.time)

    @property
    def kind_names(self) -> np.ndarray:
        """``kind`` as the strings "sphere-plane" / "sphere-sphere"."""
        return np.asarray(KIND_NAMES)[self.kind]

    @staticmethod
    def empty() -> Contacts:
        return Contacts(
            time=np.zeros(0),
            kind=np.zeros(0, np.int8),
            a=np.zeros(0, np.intp),
            b=np.zeros(0, np.intp),
            point=np.zeros((0, 3)),
            normal=np.zeros((0, 3)),
            impulse=np.zeros(0),
        )

    @staticmethod
    def concatenate(parts: list[Contacts]) -> Contacts:
        if not parts:
            return Contacts.empty()
        if len(parts) == 1:
            return parts[0]
        return Contacts(
            **{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Contacts)}
        )


@dataclass
class Candidates:
    """Pairs the broad phase found for the rest of the step, with the boxes they were found from."""

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


@dataclass
class ContactSet:
    """Every candidate pair evaluated at the current positions; sphere–plane pairs first.

    ``b`` is the other ball's row, or the static row N for a plane; ``other`` is what the events
    report as b (the plane's or the other ball's index).
    """

    kind: np.ndarray
    a: np.ndarray
    b: np.ndarray
    other: np.ndarray
    gap: np.ndarray
    normal: np.ndarray
    point: np.ndarray

    def __len__(self) -> int:
        return len(self.a)

    def subset(self, mask: np.ndarray) -> ContactSet:
        return ContactSet(**{f.name: getattr(self, f.name)[mask] for f in fields(ContactSet)})

    def keys(self, n_spheres: int) -> np.ndarray:
        """A unique integer per pair, stable from step to step (for warm starting)."""
        second = np.where(self.kind == SPHERE_SPHERE, self.other, n_spheres + self.other)
        return self.a.astype(np.int64) * (2 * n_spheres + 2**20) + second


class EventLog:
    """Collects the impulses of one step and merges them into one ``Contacts`` entry per pair.

    Resting impulses are solved for the whole remaining step but applied only over the interval
    actually taken, so they are scaled by that fraction when the interval closes.
    """

    def __init__(self) -> None:
        self._parts: list[tuple] = []
        self._pending: tuple | None = None

    def add(self, time: float, contacts: ContactSet, keys: np.ndarray, impulse: np.ndarray) -> None:
        hit = impulse > 0.0
        if hit.any():
            self._parts.append((np.full(int(hit.sum()), time), contacts.subset(hit), keys[hit], impulse[hit]))

    def add_resting(self, time: float, contacts: ContactSet, keys: np.ndarray, impulse: np.ndarray) -> None:
        self._pending = (time, contacts, keys, impulse)

    def close_interval(self, fraction: float) -> None:
        if self._pending is not None:
            time, contacts, keys, impulse = self._pending
            self.add(time, contacts, keys, impulse * fraction)
            self._pending = None

    def record(self) -> Contacts:
        if not self._parts:
            return Contacts.empty()
        time = np.concatenate([p[0] for p in self._parts])
        keys = np.concatenate([p[2] for p in self._parts])
        impulse = np.concatenate([p[3] for p in self._parts])
        c = ContactSet(
            **{
                f.name: np.concatenate([getattr(p[1], f.name) for p in self._parts])
                for f in fields(ContactSet)
            }
        )
        # One entry per pair: the first time it was resolved (its point and normal then), the total impulse.
        unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        total = np.zeros(len(unique))
        np.add.at(total, inverse, impulse)
        order = np.lexsort((first, time[first]))
        first = first[order]
        return Contacts(
            time=time[first],
            kind=c.kind[first].astype(np.int8),
            a=c.a[first],
            b=c.other[first],
            point=c.point[first],
            normal=c.normal[first],
            impulse=total[order],
        )
