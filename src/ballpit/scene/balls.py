"""The balls of a scene file, gathered from its ``[[sphere]]`` and ``[[grid]]`` entries into one batch.

The batch remembers which entry (and which ball of a grid) each ball came from, so the start-overlap
check can name both balls of a bad pair, and gives each ball its colour: its entry's, else the palette
by ball index.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..physics import World
from . import schema
from .colours import palette_colors
from .fields import Entry
from .overlap import first_overlap, first_plane_cut

_PER_BALL_SHAPE = {"velocity": (3,), "angular_velocity": (3,), "orientation": (4,)}


@dataclass
class _Block:
    """Balls from one entry: where they start in the batch and how to name ball k in messages."""

    start: int
    entry: Entry
    key: str | None
    name: Callable[[int], str | None]


@dataclass
class Balls:
    """Balls gathered from [[sphere]] and [[grid]] entries, added to the world in one batch.

    Each entry's properties are kept as given (one value for the whole entry, or one per ball) and
    expanded to one row per ball only once, in ``column``, so gathering is linear in the entries.
    """

    positions: list[np.ndarray] = field(default_factory=list)
    values: dict[str, list[np.ndarray]] = field(default_factory=lambda: {k: [] for k in schema.BALL_COLUMNS})
    colors: list[np.ndarray | None] = field(default_factory=list)  # None: the palette
    blocks: list[_Block] = field(default_factory=list)
    counts: list[int] = field(default_factory=list)
    count: int = 0

    def add(
        self,
        e: Entry,
        key: str | None,
        positions: np.ndarray,
        props: dict[str, object],
        colors: np.ndarray | None,
        name: Callable[[int], str | None],
    ) -> None:
        """Append entry ``e``'s balls; ``key`` is where errors about their positions point."""
        n = len(positions)
        self.blocks.append(_Block(self.count, e, key, name))
        self.positions.append(positions)
        for k in schema.BALL_COLUMNS:
            self.values[k].append(np.asarray(props[k], dtype=float))
        self.colors.append(colors)
        self.counts.append(n)
        self.count += n

    def column(self, k: str) -> np.ndarray:
        """Property ``k`` of every ball, one row per ball, in batch order."""
        shape = _PER_BALL_SHAPE.get(k, ())
        values = self.values[k]
        if all(v.shape == shape for v in values):  # one value per entry: repeat it for its balls
            return np.repeat(np.array(values).reshape(-1, *shape), self.counts, axis=0)
        return np.concatenate(
            [np.broadcast_to(v, (n, *shape)) for v, n in zip(values, self.counts, strict=True)]
        )

    def owner(self, k: int) -> tuple[Entry, str | None, str | None]:
        """The entry, key and ball name of ball ``k`` of the batch."""
        for block in reversed(self.blocks):
            if k >= block.start:
                return block.entry, block.key, block.name(k - block.start)
        raise IndexError(k)

    def sphere_colors(self) -> np.ndarray:
        """(N, 3) colours of the batch: each entry's own, else the palette by ball index."""
        out = [
            palette_colors(len(positions), block.start) if colors is None else colors
            for block, positions, colors in zip(self.blocks, self.positions, self.colors, strict=True)
        ]
        return np.concatenate(out) if out else np.zeros((0, 3))

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
