"""The balls of a scene file, gathered from its ``[[sphere]]`` and ``[[grid]]`` entries into one batch.

The batch remembers which entry (and which ball of a grid) each ball came from, so the start-overlap
check can name both balls of a bad pair, and gives each ball its colour: its entry's, else the palette
by ball index.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..physics import World
from . import schema
from .colours import palette_colors
from .fields import Entry
from .overlap import first_overlap, first_plane_cut

_PER_BALL_SHAPE = {"velocity": (3,), "angular_velocity": (3,), "orientation": (4,)}


def _sphere_row_layout() -> dict[str, slice]:
    """Where each value of a [[sphere]] sits in its row of numbers: the position, every ball column,
    then the colour (NaN: the palette's)."""
    widths = {"position": 3, **{k: int(np.prod(_PER_BALL_SHAPE.get(k, ()))) for k in schema.BALL_COLUMNS}}
    widths["color"] = 3
    layout, at = {}, 0
    for key, width in widths.items():
        layout[key] = slice(at, at + width)
        at += width
    return layout


_SPHERE_ROW = _sphere_row_layout()
_SPHERE_WIDTH = max(s.stop for s in _SPHERE_ROW.values())
_DEFAULT_ROW = np.full(_SPHERE_WIDTH, np.nan)  # every ball column's default; position and colour unset
for _key, _value in schema.BALL_DEFAULTS.items():
    _DEFAULT_ROW[_SPHERE_ROW[_key]] = np.asarray(_value, dtype=float)


@dataclass
class _Grid:
    """A grid's balls: where they start in the batch, their entry, and how to name ball k in messages."""

    start: int
    entry: Entry
    key: str  # where errors about its balls' positions point
    name: Callable[[int], str | None]
    positions: np.ndarray
    values: dict[str, np.ndarray]  # one value for the whole grid, or one per ball
    colors: np.ndarray | None  # None: the palette


class Balls:
    """Balls gathered from [[sphere]] and [[grid]] entries, added to the world in one batch.

    Spheres come first, one ball each in file order, so ball k < ``spheres`` is sphere #k+1, and
    ``sphere_entry(k)`` gives its entry back when an error names it. Each sphere is one row of numbers
    in a block made for as many as the file has (doubled if more come): a file of half a million
    spheres keeps 22 numbers a ball, not a Python object for each value. A grid keeps its properties
    as given (one value for the whole grid, or one per ball), expanded to one row per ball only in
    ``column``.
    """

    def __init__(self, sphere_entry: Callable[[int], Entry], spheres: int = 16) -> None:
        self.sphere_entry = sphere_entry
        self._rows = np.empty((max(spheres, 1), _SPHERE_WIDTH))  # room for as many as the file has
        self.spheres = 0
        self.grids: list[_Grid] = []
        self.count = 0

    def add_sphere(self, position: np.ndarray, props: dict[str, object], color: np.ndarray | None) -> None:
        """Append one [[sphere]]'s ball (before any grid's): its position, the ball properties it gives
        (the rest take their defaults) and its colour (None: the palette's)."""
        if self.grids:
            raise ValueError("spheres are gathered before grids")
        if self.spheres == len(self._rows):
            grown = np.empty((2 * len(self._rows), _SPHERE_WIDTH))
            grown[: self.spheres] = self._rows
            self._rows = grown
        row = self._rows[self.spheres]
        row[:] = _DEFAULT_ROW
        row[_SPHERE_ROW["position"]] = position
        for k, value in props.items():
            row[_SPHERE_ROW[k]] = value
        if color is not None:
            row[_SPHERE_ROW["color"]] = color
        self.spheres += 1
        self.count += 1

    def add_grid(
        self,
        e: Entry,
        key: str,
        positions: np.ndarray,
        props: dict[str, object],
        colors: np.ndarray | None,
        name: Callable[[int], str | None],
    ) -> None:
        """Append a [[grid]]'s balls."""
        values = {k: np.asarray(props[k], dtype=float) for k in schema.BALL_COLUMNS}
        self.grids.append(_Grid(self.count, e, key, name, positions, values, colors))
        self.count += len(positions)

    def _sphere_column(self, k: str) -> np.ndarray:
        part = self._rows[: self.spheres, _SPHERE_ROW[k]]
        return part if k in ("position", "color", *_PER_BALL_SHAPE) else part[:, 0]

    def positions(self) -> np.ndarray:
        """Every ball's position, (N, 3) in batch order."""
        parts = [self._sphere_column("position"), *(g.positions for g in self.grids)]
        return np.concatenate(parts) if self.grids else np.array(parts[0])

    def column(self, k: str) -> np.ndarray:
        """Property ``k`` of every ball, one row per ball, in batch order; the grid's own value when
        there is one grid and nothing else (``World.add_spheres`` broadcasts it, a million-ball grid
        needs no million copies)."""
        shape = _PER_BALL_SHAPE.get(k, ())
        if self.spheres == 0 and len(self.grids) == 1:
            return self.grids[0].values[k]
        parts = [self._sphere_column(k)]
        parts += [np.broadcast_to(g.values[k], (len(g.positions), *shape)) for g in self.grids]
        return np.concatenate(parts)

    def owner(self, k: int) -> tuple[Entry, str | None, str | None]:
        """The entry, key and ball name of ball ``k`` of the batch."""
        if k < self.spheres:
            return self.sphere_entry(k), "position", None
        for grid in reversed(self.grids):
            if k >= grid.start:
                return grid.entry, grid.key, grid.name(k - grid.start)
        raise IndexError(k)

    def sphere_colors(self) -> np.ndarray:
        """(N, 3) colours of the batch: each entry's own, else the palette by ball index."""
        colors = np.array(self._sphere_column("color"))
        unset = np.isnan(colors[:, 0])
        colors[unset] = palette_colors(self.spheres)[unset]
        out = [colors]
        for grid in self.grids:
            n = len(grid.positions)
            out.append(palette_colors(n, grid.start) if grid.colors is None else grid.colors)
        return np.concatenate(out)

    def check_overlaps(
        self,
        positions: np.ndarray,
        radii: np.ndarray,
        world: World,
        tolerance: float = schema.OVERLAP_TOLERANCE,
    ) -> None:
        """Refuse balls that interpenetrate each other or a plane by more than ``tolerance`` at the start."""
        pair = first_overlap(positions, radii, tolerance)
        if pair is not None:
            i, j = pair
            dist = float(np.linalg.norm(positions[i] - positions[j]))
            e, key, name_j = self.owner(j)
            e_i, _, name_i = self.owner(i)
            other = e_i.label if name_i is None else f"{e_i.label} {name_i}"
            raise e.error(
                key,
                f"{'overlaps' if name_j is None else name_j + ' overlaps'} {other} at the start: "
                f"centres {dist:.6g} m apart, radii {radii[j]:g} + {radii[i]:g} m",
            )
        cut = first_plane_cut(positions, radii, world.planes, tolerance)
        if cut is not None:
            p, k, dist = cut
            e, key, name = self.owner(k)
            raise e.error(
                key,
                f"{'the ball' if name is None else name} cuts into plane #{p + 1} at the start: "
                f"its centre is {dist:.6g} m from the plane, less than its radius {radii[k]:g} m",
            )
