"""Scratch arrays a step reuses from one step to the next, so its hot path allocates nothing new."""

from __future__ import annotations

import numpy as np


class Workspace:
    """Scratch arrays reused between steps so the hot path allocates nothing new."""

    def __init__(self) -> None:
        self._buffers: dict[tuple[str, tuple[int, ...]], np.ndarray] = {}

    def get(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        key = (name, shape)
        buf = self._buffers.get(key)
        if buf is None:
            if len(self._buffers) > 64:  # shapes change as balls are added; drop stale ones
                self._buffers.clear()
            buf = self._buffers[key] = np.empty(shape)
        return buf
