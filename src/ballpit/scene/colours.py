"""The one palette and restitution colour ramp, for scene files and the viewer alike.

Balls a scene does not colour take the palette by ball index. Planes show their bounciness: unbounded
planes are a neutral floor; finite ones go slate blue at restitution 0, green at 0.5, orange at 1 (the
viewer's legend uses the same stops). Colours are sRGB components 0..1.
"""

from __future__ import annotations

import numpy as np

# Default ball colours, cycled by ball index: saturated but not garish against a grey floor.
PALETTE = (
    "#e0482f",
    "#f4a259",
    "#3fa7d6",
    "#5bc06f",
    "#9b5de5",
    "#f15bb5",
    "#fee440",
    "#00bbf9",
    "#00c9a7",
    "#ff8c42",
)
GROUND_COLOR = (0.55, 0.57, 0.60)
RESTITUTION_STOPS = np.array([0.0, 0.5, 1.0])
RESTITUTION_COLORS = np.array([[0.29, 0.36, 0.50], [0.30, 0.56, 0.42], [0.93, 0.55, 0.20]])


def hex_to_rgb(code: str) -> np.ndarray:
    """``"#rrggbb"`` (the ``#`` optional) as three floats 0..1."""
    h = code.strip().removeprefix("#")
    return np.array([int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4)])


_PALETTE_RGB = np.array([hex_to_rgb(h) for h in PALETTE])
_PALETTE_RGB.setflags(write=False)


def palette_colors(count: int, first: int = 0) -> np.ndarray:
    """(count, 3) palette colours for balls ``first`` … ``first + count − 1``."""
    return _PALETTE_RGB[(first + np.arange(count)) % len(PALETTE)]


def restitution_colors(restitutions: object) -> np.ndarray:
    """(P, 3) plane colours showing bounciness: slate blue at 0, green at 0.5, orange at 1."""
    e = np.clip(np.asarray(restitutions, dtype=float).reshape(-1), 0.0, 1.0)
    return np.stack([np.interp(e, RESTITUTION_STOPS, RESTITUTION_COLORS[:, k]) for k in range(3)], axis=-1)


def plane_colors(restitutions: object, infinite: object) -> np.ndarray:
    """(P, 3) default plane colours: finite planes by restitution, infinite ones (the ground) grey."""
    colors = restitution_colors(restitutions)
    colors[np.asarray(infinite, dtype=bool).reshape(-1)] = GROUND_COLOR
    return colors
