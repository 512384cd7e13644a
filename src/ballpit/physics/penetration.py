"""Penetration removal: overlapping balls are moved apart, by positions only.

No velocity is added, so removing an overlap never launches a ball (design.md). Each overlapping
contact's linearised gap g = n·(x_a − x_b) − offset is driven to zero by a few Gauss–Seidel sweeps
over the contact colours, each ball moved in proportion to its inverse mass.
"""

from __future__ import annotations

import numpy as np

from .contacts import ContactPoints
from .rows import ContactRows
from .state import State, X, with_static

# Overlaps shallower than this (m) are left alone: rounding, not penetration.
OVERLAP_TOLERANCE = 1e-7
# Gauss–Seidel sweeps over the overlapping contacts.
SWEEPS = 4


def remove_penetration(state: State, c: ContactPoints, rows: ContactRows) -> None:
    """Move overlapping balls apart along the contact normals (positions only)."""
    if not np.any(c.gap < -OVERLAP_TOLERANCE):
        return
    x = state.body[:, X]
    pos = with_static(x)
    n = c.normal
    offset = np.einsum("ij,ij->i", n, pos[c.a] - pos[c.b]) - c.gap
    share = rows.inv_mass_a / (rows.inv_mass_a + rows.inv_mass_b)
    for _ in range(SWEEPS):
        for idx in rows.colours:
            a, b = c.a[idx], c.b[idx]
            gap = np.einsum("ij,ij->i", n[idx], pos[a] - pos[b]) - offset[idx]
            depth = np.maximum(-gap, 0.0)[:, None] * n[idx]
            pos[a] += depth * share[idx, None]
            pos[b] -= depth * (1.0 - share[idx, None])
        pos[-1] = 0.0
    x[:] = pos[:-1]
