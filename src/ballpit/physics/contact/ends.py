"""Both ends of K contacts as columns of a compact array of the M balls they touch: how every solve that
works on all contacts at once (jacobi.py, the impacts' waves) numbers the balls, splits their masses
and adds per-contact values back per ball."""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..core.settings import ADD_UP_BINS_UP_TO, SORT_ENDS_FROM


class Ends:
    """Both ends of K contacts as columns of a compact array of the M balls they touch: ``ends`` holds
    each contact's a then b, ``share`` each ball's number of contacts (its mass is split that many
    ways), and ``add_up`` adds per-end values back per ball with one ``np.bincount``."""

    def __init__(self, a: np.ndarray, b: np.ndarray) -> None:
        self.k = len(a)
        ab = np.concatenate((a, b))
        rows_in_world = int(ab.max(initial=-1)) + 1
        if len(ab) * SORT_ENDS_FROM < rows_in_world:  # few contacts in a big world: sorting them is cheaper
            self.balls, self.ends = np.unique(ab, return_inverse=True)
        else:  # the same compact numbering (balls in increasing order) from a table over the world
            present = np.zeros(rows_in_world, bool)
            present[ab] = True
            self.balls = present.nonzero()[0]
            self.ends = np.take(np.cumsum(present) - 1, ab)
        self.m = len(self.balls)
        self._flat: dict[int, np.ndarray] = {}  # add_up's bins for every entry, by number of rows

    @classmethod
    def numbered(cls, balls: np.ndarray, ends: np.ndarray) -> Ends:
        """The ends of contacts numbered already (``balls`` and ``ends`` as another ``Ends`` of the same
        contacts made them), without numbering them again."""
        e = cls.__new__(cls)
        e.k, e.balls, e.ends, e.m, e._flat = len(ends) // 2, balls, ends, len(balls), {}
        return e

    @cached_property
    def share(self) -> np.ndarray:
        """Each ball's number of contacts, as a float (made when first asked: a Gauss–Seidel solve
        never asks)."""
        return np.bincount(self.ends, minlength=self.m).astype(float)

    def add_up(self, values: np.ndarray) -> np.ndarray:
        """(rows, 2K) values per contact end, summed per ball: (rows, M), with one ``np.bincount`` over
        all rows (row r's entries land in bins r·M + ball). bincount adds each bin's entries in their
        order, so every sum is the same as one row at a time, at less than one call's cost a row.
        Beyond ADD_UP_BINS_UP_TO entries it is one call a row (the same sums), without keeping bins."""
        rows = len(values)
        if rows * len(self.ends) > ADD_UP_BINS_UP_TO:
            summed = np.empty((rows, self.m))
            for r in range(rows):
                summed[r] = self.add_row(values[r])
            return summed
        flat = self._flat.get(rows)
        if flat is None:
            flat = (self.ends[None, :] + self.m * np.arange(rows)[:, None]).ravel()
            self._flat[rows] = flat
        summed = np.bincount(flat, weights=values.ravel(), minlength=rows * self.m)
        return summed.reshape(rows, self.m)

    def add_row(self, values: np.ndarray) -> np.ndarray:
        """One row of (2K,) values per contact end, summed per ball: (M,)."""
        return np.bincount(self.ends, weights=values, minlength=self.m)
