"""Accumulated contact impulses and the small vector helpers both contact solvers share."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import exact


@dataclass
class Impulses:
    """Accumulated impulses per contact: normal (K,), friction (K, 3), rolling (K, 3)."""

    normal: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray

    @staticmethod
    def zeros(count: int) -> Impulses:
        return Impulses(np.zeros(count), np.zeros((count, 3)), np.zeros((count, 3)))


def cap(vectors: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """Scale each row down to length ≤ limit (the friction cone and the rolling-resistance limit)."""
    length = np.sqrt(exact.dot(vectors, vectors) + 1e-300)  # + tiny: no 0/0 at zero
    return vectors * np.minimum(limit / length, 1.0)[:, None]


def skew(n: np.ndarray) -> np.ndarray:
    """Matrices [n]× with [n]×·s = n × s, so a batch of cross products is one einsum."""
    k = np.zeros((len(n), 3, 3))
    k[:, 0, 1], k[:, 0, 2] = -n[:, 2], n[:, 1]
    k[:, 1, 0], k[:, 1, 2] = n[:, 2], -n[:, 0]
    k[:, 2, 0], k[:, 2, 1] = -n[:, 1], n[:, 0]
    return k
