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
