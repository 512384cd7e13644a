"""Structure-of-arrays storage for balls and planes.

Arrays are allocated with spare capacity that doubles when full, so adding balls one at a time is
amortised O(1). The live part of each array is its first ``count`` rows.

The ball's dynamic state is one (capacity, 13) block, ``[x(3) v(3) q(4) ω(3)]``, so an integrator
combines whole states with a handful of array operations; ``x``, ``v``, ``q`` and ``w`` are column views
into it.
"""

from __future__ import annotations

import numpy as np

# Column slices of the dynamic state block.
X = slice(0, 3)
V = slice(3, 6)
Q = slice(6, 10)
W = slice(10, 13)
STATE_WIDTH = 13


class Columns:
    """Named arrays that share a leading capacity dimension and grow together."""

    def __init__(self, spec: dict[str, tuple[tuple[int, ...], type]], capacity: int = 16) -> None:
        self._spec = spec
        self.count = 0
        self.capacity = capacity
        self._arrays = {k: np.zeros((capacity, *shape), dtype) for k, (shape, dtype) in spec.items()}

    def reserve(self, extra: int) -> slice:
        """Make room for ``extra`` more rows; returns the slice of the new rows."""
        needed = self.count + extra
        if needed > self.capacity:
            capacity = max(needed, 2 * self.capacity)
            for k, old in self._arrays.items():
                new = np.zeros((capacity, *old.shape[1:]), old.dtype)
                new[: self.count] = old[: self.count]
                self._arrays[k] = new
            self.capacity = capacity
        rows = slice(self.count, needed)
        self.count = needed
        return rows

    def full(self, name: str) -> np.ndarray:
        """The whole allocated array, spare rows included (for writing new rows)."""
        return self._arrays[name]

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = self.__dict__.get("_arrays")
        if arrays is None or name not in arrays:
            raise AttributeError(name)
        return arrays[name][: self.count]


def sphere_columns() -> Columns:
    """Per-ball arrays: dynamic state, shape, mass properties and material."""
    f = float
    return Columns(
        {
            "state": ((STATE_WIDTH,), f),
            "radius": ((), f),
            "mass": ((), f),
            "inv_mass": ((), f),
            "inv_inertia": ((), f),  # spheres are isotropic: I⁻¹ is a scalar times the identity
            "restitution": ((), f),
            "friction": ((), f),
            "rolling_friction": ((), f),
            "hollow": ((), bool),
        }
    )


def plane_columns() -> Columns:
    """Per-plane arrays: frame, half extents (inf for unbounded) and material."""
    f = float
    return Columns(
        {
            "center": ((3,), f),
            "orientation": ((4,), f),
            "normal": ((3,), f),  # the plane's +y axis
            "axis_u": ((3,), f),  # width direction, the plane's +x axis
            "axis_v": ((3,), f),  # depth direction, the plane's +z axis
            "half_size": ((2,), f),
            "restitution": ((), f),
            "friction": ((), f),
            "rolling_friction": ((), f),
        },
        capacity=4,
    )
