"""Contacts at two points in a step, each a structure of equal-length arrays, one entry per pair:

- ``ContactPoints``: every kept pair measured by the narrow phase at the current positions (gap,
  normal, point), touching or not;
- ``ContactRecord`` (public as ``ballpit.Contacts``): what one step resolved, one entry per pair, with
  its total impulse; ``EventLog`` collects it over the step's intervals.

The solver's own per-contact rows (masses, lever arms, mixed materials) are ``rows.ContactRows``, and
the broad phase's pairs are ``pairs.KeptPairs``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

SPHERE_PLANE = 0
SPHERE_SPHERE = 1
KIND_NAMES = ("sphere-plane", "sphere-sphere")


@dataclass(frozen=True)
class ContactRecord:
    """Contacts resolved in one step (``World.step`` returns it; public as ``ballpit.Contacts``).

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
    def empty() -> ContactRecord:
        return ContactRecord(
            time=np.zeros(0),
            kind=np.zeros(0, np.int8),
            a=np.zeros(0, np.intp),
            b=np.zeros(0, np.intp),
            point=np.zeros((0, 3)),
            normal=np.zeros((0, 3)),
            impulse=np.zeros(0),
        )

    @staticmethod
    def concatenate(parts: list[ContactRecord]) -> ContactRecord:
        if not parts:
            return ContactRecord.empty()
        if len(parts) == 1:
            return parts[0]
        return ContactRecord(
            **{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(ContactRecord)}
        )


# The public name (``ballpit.Contacts``): what ``World.step`` returns.
Contacts = ContactRecord


@dataclass
class ContactPoints:
    """Every kept pair measured at the current positions; sphere–plane pairs first.

    ``b`` is the other ball's row, or the static row N for a plane; ``other`` is what the events
    report as b (the plane's or the other ball's index). ``gaps`` keeps of each pair only which bodies
    it joins and its gap (``b``, ``normal`` and ``point`` None).
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

    def subset(self, mask: np.ndarray, without: tuple[str, ...] = ()) -> ContactPoints:
        """The contacts where ``mask`` holds (or at the indices ``mask``), in their order; the fields
        named in ``without`` left None (for a caller that takes them its own way)."""
        idx = take_indices(mask)
        parts = [None if name in without else getattr(self, name) for name in _POINT_FIELDS]
        return ContactPoints(*[None if v is None else v.take(idx, axis=0) for v in parts])

    def gaps(self) -> ContactPoints:
        """The same pairs with only their kind, bodies (a, other) and gaps: what a soft frame keeps of
        the pairs it does not solve (56 bytes a pair fewer)."""
        return replace(self, b=None, normal=None, point=None)

    @staticmethod
    def concatenate(parts: list[ContactPoints]) -> ContactPoints:
        return ContactPoints(*[np.concatenate([getattr(p, name) for p in parts]) for name in _POINT_FIELDS])

    def keys(self) -> np.ndarray:
        """A unique integer per pair, built from the pair's own identity (the ball's index and the
        other ball's or the plane's), so a key never changes meaning when bodies are added."""
        return pair_keys(self.a, self.other, self.kind == SPHERE_PLANE)


# ContactPoints' fields in their order (``dataclasses.fields`` costs more than a subset of a few contacts)
_POINT_FIELDS = tuple(f.name for f in fields(ContactPoints))


def take_indices(mask: np.ndarray) -> np.ndarray:
    """The indices a boolean ``mask`` selects (indices are returned as they are): taking rows by
    index from several arrays costs a third of what indexing each with the same boolean mask does,
    which finds the indices again for every array."""
    return mask.nonzero()[0] if mask.dtype == bool else mask  # (1-D: np.flatnonzero without its ravel)


# A pair's key: ball a in the high 32 bits; in the low 32, the other ball, or a plane with bit 31 set.
_PLANE_BIT = np.int64(1 << 31)


def pair_keys(a: np.ndarray, other: np.ndarray, on_plane: np.ndarray) -> np.ndarray:
    """Stable identities of pairs (ball ``a``, ball or plane ``other``) for the warm-start cache."""
    second = other.astype(np.int64) + np.where(on_plane, _PLANE_BIT, np.int64(0))
    return (a.astype(np.int64) << np.int64(32)) | second


def find_keys(sorted_keys: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which of the pair ``keys`` are among the distinct ``sorted_keys`` (non-empty, ascending), and
    where each would be there (a binary search each: ``np.isin`` sorts both arrays together, at about
    twice the cost); ``positions[found]`` are the rows of those found."""
    positions = np.minimum(np.searchsorted(sorted_keys, keys), len(sorted_keys) - 1)
    return sorted_keys[positions] == keys, positions


class EventLog:
    """Collects the impulses of one step and merges them into one ``ContactRecord`` entry per pair.

    Resting impulses are solved for the whole remaining step but applied only over the interval
    actually taken, so they are scaled by that fraction when the interval closes.
    """

    def __init__(self) -> None:
        self._parts: list[tuple] = []
        self._pending: tuple | None = None

    def add(self, time: float, contacts: ContactPoints, keys: np.ndarray, impulse: np.ndarray) -> None:
        hit = impulse > 0.0
        if np.count_nonzero(hit):
            self._parts.append((np.full(int(hit.sum()), time), contacts.subset(hit), keys[hit], impulse[hit]))

    def add_resting(
        self, time: float, contacts: ContactPoints, keys: np.ndarray, impulse: np.ndarray
    ) -> None:
        self._pending = (time, contacts, keys, impulse)

    def close_interval(self, fraction: float) -> None:
        if self._pending is not None:
            time, contacts, keys, impulse = self._pending
            self.add(time, contacts, keys, impulse * fraction)
            self._pending = None

    def balls_reached(self, balls: np.ndarray) -> np.ndarray:
        """Which of ``balls`` (a mask over the balls) an impulse recorded so far reached through a
        ball–ball contact (a mask)."""
        out = np.zeros(len(balls) + 1, bool)
        for _, c, _, _ in self._parts:
            pair = c.kind == SPHERE_SPHERE
            out[c.a[pair]] = True
            out[c.other[pair]] = True
        return out[:-1] & balls

    def record(self) -> ContactRecord:
        if not self._parts:
            return ContactRecord.empty()
        if len(self._parts) == 1:  # one add: one entry per pair already, in order, at one time
            time, c, _, impulse = self._parts[0]
            a, b = c.a.astype(np.intp, copy=False), c.other.astype(np.intp, copy=False)  # pairs keep int32
            return ContactRecord(time, c.kind.astype(np.int8), a, b, c.point, c.normal, impulse)
        time = np.concatenate([p[0] for p in self._parts])
        keys = np.concatenate([p[2] for p in self._parts])
        impulse = np.concatenate([p[3] for p in self._parts])
        c = ContactPoints.concatenate([p[1] for p in self._parts])
        # One entry per pair: the first time it was resolved (its point and normal then), the total impulse.
        unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        total = np.zeros(len(unique))
        np.add.at(total, inverse, impulse)
        order = np.lexsort((first, time[first]))
        first = first[order]
        return ContactRecord(
            time=time[first],
            kind=c.kind[first].astype(np.int8),
            a=c.a[first].astype(np.intp),
            b=c.other[first].astype(np.intp),
            point=c.point[first],
            normal=c.normal[first],
            impulse=total[order],
        )
