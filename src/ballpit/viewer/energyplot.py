"""The live energy plot (P): kinetic, potential and total energy over the last ``WINDOW_SECONDS``.

``EnergyTrace`` keeps one sample per frame (stepping back in the history cuts the samples after the
present); ``plot_shapes`` turns it into screen-space geometry for the renderer's overlay pass: a panel
(triangles) and the curves (lines), vertices (x, y, 0, r, g, b, a) in window pixels, y up. No GL here.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .ghosts import LABELS, TINTS
from .overlays import VERTEX_WIDTH

WINDOW_SECONDS = 10.0
# Kinetic and potential energy: pink and violet, apart from every integrator's colour (red, orange,
# blue, green: physics/integrators.py), which the totals take with ghosts on.
KINETIC_COLOR = (1.0, 0.45, 0.8, 1.0)
POTENTIAL_COLOR = (0.69, 0.55, 1.0, 1.0)
TOTAL_COLOR = (0.97, 0.97, 0.97, 1.0)
PANEL_COLOR = (0.04, 0.05, 0.07, 0.75)
FRAME_COLOR = (0.6, 0.63, 0.7, 0.8)
ZERO_COLOR = (0.6, 0.63, 0.7, 0.35)


class EnergyTrace:
    """Samples (time, kinetic, potential, total per integrator) over the last ``window`` seconds."""

    def __init__(self, window: float = WINDOW_SECONDS) -> None:
        self.window = window
        self.samples: deque[tuple[float, float, float, dict[str, float]]] = deque()

    def clear(self) -> None:
        self.samples.clear()

    def add(self, time: float, kinetic: float, potential: float, totals: dict[str, float]) -> None:
        """Add a sample at simulated ``time``; samples later than it (after stepping back) are dropped."""
        while self.samples and self.samples[-1][0] >= time:
            self.samples.pop()
        self.samples.append((time, kinetic, potential, dict(totals)))
        while self.samples and self.samples[0][0] < time - self.window:
            self.samples.popleft()

    def series(self) -> dict[str, np.ndarray]:
        """``time``, ``kinetic``, ``potential`` and ``total <integrator>`` arrays (NaN where missing)."""
        if not self.samples:
            return {}
        out = {
            "time": np.array([s[0] for s in self.samples]),
            "kinetic": np.array([s[1] for s in self.samples]),
            "potential": np.array([s[2] for s in self.samples]),
        }
        names: list[str] = []
        for s in self.samples:
            names.extend(n for n in s[3] if n not in names)
        for name in names:
            out[f"total {name}"] = np.array([s[3].get(name, np.nan) for s in self.samples])
        return out


def _vertices(points: np.ndarray, color: tuple) -> np.ndarray:
    out = np.zeros((len(points), VERTEX_WIDTH), dtype=np.float32)
    out[:, :2] = points
    out[:, 3:] = color
    return out


def _polyline(x: np.ndarray, y: np.ndarray, color: tuple) -> np.ndarray:
    """Consecutive points joined as GL_LINES pairs, skipping NaN gaps."""
    good = np.isfinite(y[:-1]) & np.isfinite(y[1:])
    starts = np.column_stack([x[:-1], y[:-1]])[good]
    ends = np.column_stack([x[1:], y[1:]])[good]
    pairs = np.stack([starts, ends], axis=1).reshape(-1, 2)
    return _vertices(pairs, color)


def curve_colors(series: dict[str, np.ndarray], ghosts: bool) -> dict[str, tuple]:
    """The colour of each curve: K pink, U violet, the total white (one per integrator, in its colour,
    with ghosts on)."""
    colors = {"kinetic": KINETIC_COLOR, "potential": POTENTIAL_COLOR}
    for key in series:
        if key.startswith("total "):
            name = key[len("total ") :]
            colors[key] = (*TINTS[name], 1.0) if ghosts else TOTAL_COLOR
    return colors


def legend(series: dict[str, np.ndarray], ghosts: bool) -> list[tuple[str, tuple]]:
    """(text, colour) for each curve, in drawing order."""
    items = []
    for key, color in curve_colors(series, ghosts).items():
        if key == "kinetic":
            items.append(("kinetic", color))
        elif key == "potential":
            items.append(("potential", color))
        else:
            name = key[len("total ") :]
            items.append((f"E {LABELS[name]}" if ghosts else "total", color))
    return items


def legend_layout(
    widths: list[float], rect: tuple[float, float, float, float], line_height: float, gap: float = 12.0,
    pad: float = 6.0,
) -> list[tuple[float, float]]:  # fmt: skip
    """Where each legend label of these ``widths`` goes (x, y of its bottom-left corner, window pixels,
    y up): along the bottom of the plot in ``rect``, one after another, a new row above when the next
    would pass the plot's right edge, so every label stays inside it."""
    x0, y0, w, _ = rect
    right = x0 + w - pad
    places, x, y = [], x0 + pad, y0 + 4.0
    for width in widths:
        if x > x0 + pad and x + width > right:
            x, y = x0 + pad, y + line_height
        places.append((x, y))
        x += width + gap
    return places


def plot_shapes(
    trace: EnergyTrace, rect: tuple[float, float, float, float], ghosts: bool = False
) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    """Panel triangles, curve lines and the (low, high) energy range shown, for a plot in ``rect``
    (x, y, width, height in window pixels, y up). The time axis spans the last ``trace.window``
    seconds up to the newest sample."""
    x0, y0, w, h = rect
    corners = np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0], [x0 + w, y0 + h], [x0, y0 + h]])
    panel = _vertices(corners, PANEL_COLOR)
    frame_pts = np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0], [x0 + w, y0 + h],
                          [x0 + w, y0 + h], [x0, y0 + h], [x0, y0 + h], [x0, y0]])  # fmt: skip
    lines = [_vertices(frame_pts, FRAME_COLOR)]
    series = trace.series()
    low, high = 0.0, 1.0
    if series and len(series["time"]) >= 2:
        values = np.concatenate([v for k, v in series.items() if k != "time"])
        values = values[np.isfinite(values)]
        low, high = float(min(values.min(), 0.0)), float(max(values.max(), 0.0))
        pad = max((high - low) * 0.08, 1e-9)
        low, high = low - pad, high + pad
        t = series["time"]
        pad_x, pad_y = 6.0, 6.0
        px = x0 + pad_x + (t - (t[-1] - trace.window)) / trace.window * (w - 2 * pad_x)

        def py(v: np.ndarray) -> np.ndarray:
            return y0 + pad_y + (v - low) / (high - low) * (h - 2 * pad_y)

        # one sample per 2 px: shorter segments can drop out of the rasteriser, leaving dotted lines
        keep = np.r_[True, np.diff(np.floor(px / 2.0)) != 0]
        keep[-1] = True
        px, series = px[keep], {k: v[keep] for k, v in series.items()}
        zero = float(py(np.array(0.0)))
        lines.append(_vertices(np.array([[x0, zero], [x0 + w, zero]]), ZERO_COLOR))
        for key, color in curve_colors(series, ghosts).items():
            lines.append(_polyline(px, py(series[key]), color))
    return panel, np.concatenate(lines), (low, high)
