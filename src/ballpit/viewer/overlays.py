"""Debug overlays as vertices (x, y, z, r, g, b, a): contact points and normals, velocity arrows, trails.

The contact marks and arrows are pairs of vertices, float32 (2·segments, 7), ready for one ``GL_LINES``
draw. Trails are ribbons, one triangle strip for all balls (``trail_ribbons``): OpenGL's core profile
draws lines one pixel wide, too faint to follow. Everything is vectorised over contacts and balls.
"""

from __future__ import annotations

import numpy as np

VERTEX_WIDTH = 7
CONTACT_COLOR = (1.0, 0.95, 0.2, 1.0)
NORMAL_COLOR = (0.2, 1.0, 0.45, 1.0)
VELOCITY_COLOR = (0.35, 0.85, 1.0, 1.0)
CONTACT_CROSS = 0.06  # half length of the cross marking a contact point, m
NORMAL_LENGTH = 0.35  # m
VELOCITY_SCALE = 0.12  # metres of arrow per m/s
ARROW_HEAD = 0.25  # head length as a fraction of the arrow
TRAIL_WIDTH = 0.6  # ball radii: a trail's width at its newest end; it narrows to a third at its oldest
TRAIL_ALPHA = 0.9  # opacity at the newest end; it fades to nothing at the oldest


def empty() -> np.ndarray:
    return np.zeros((0, VERTEX_WIDTH), dtype=np.float32)


def _segments(starts: np.ndarray, ends: np.ndarray, colors: np.ndarray) -> np.ndarray:
    """Interleave (S, 3) starts and ends with (S, 4) or (2, S, 4) colours into (2S, 7) vertices."""
    s = len(starts)
    out = np.empty((s, 2, VERTEX_WIDTH), dtype=np.float32)
    out[:, 0, :3] = starts
    out[:, 1, :3] = ends
    colors = np.asarray(colors, dtype=np.float32)
    if colors.ndim == 3:  # separate colours for start and end vertices
        out[:, 0, 3:] = colors[0]
        out[:, 1, 3:] = colors[1]
    else:
        out[:, :, 3:] = colors[:, None, :] if colors.ndim == 2 else colors
    return out.reshape(-1, VERTEX_WIDTH)


def contact_lines(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """A small 3-axis cross at each contact point and a line along its normal."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    normals = np.asarray(normals, dtype=float).reshape(-1, 3)
    if len(points) == 0:
        return empty()
    axes = np.eye(3) * CONTACT_CROSS
    starts = (points[:, None, :] - axes[None]).reshape(-1, 3)
    ends = (points[:, None, :] + axes[None]).reshape(-1, 3)
    cross = _segments(starts, ends, np.broadcast_to(CONTACT_COLOR, (len(starts), 4)))
    normal = _segments(
        points, points + normals * NORMAL_LENGTH, np.broadcast_to(NORMAL_COLOR, (len(points), 4))
    )
    return np.concatenate([cross, normal])


def velocity_arrows(positions: np.ndarray, velocities: np.ndarray, min_speed: float = 1e-3) -> np.ndarray:
    """An arrow from each moving ball's centre along its velocity, with a two-line head."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    velocities = np.asarray(velocities, dtype=float).reshape(-1, 3)
    speed = np.linalg.norm(velocities, axis=1)
    moving = speed > min_speed
    if not moving.any():
        return empty()
    p, v = positions[moving], velocities[moving]
    tip = p + v * VELOCITY_SCALE
    shaft = tip - p
    direction = shaft / np.linalg.norm(shaft, axis=1, keepdims=True)
    # a side vector perpendicular to the arrow, preferring the horizontal plane
    side = np.cross(direction, np.array([0.0, 1.0, 0.0]))
    vertical = np.linalg.norm(side, axis=1) < 1e-3
    side[vertical] = np.cross(direction[vertical], np.array([1.0, 0.0, 0.0]))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    head = np.linalg.norm(shaft, axis=1, keepdims=True) * ARROW_HEAD
    back = tip - direction * head
    left = back + side * head * 0.5
    right = back - side * head * 0.5
    starts = np.concatenate([p, tip, tip])
    ends = np.concatenate([tip, left, right])
    return _segments(starts, ends, np.broadcast_to(VELOCITY_COLOR, (len(starts), 4)))


def trail_ribbons(
    samples: np.ndarray,
    colors: np.ndarray,
    radii: np.ndarray,
    eye: np.ndarray,
    current: np.ndarray | None = None,
) -> np.ndarray:
    """Each ball's recent path as a ribbon facing the eye, for one ``GL_TRIANGLE_STRIP`` draw: as wide as
    ``TRAIL_WIDTH`` of the ball at the ball, narrower and more transparent towards the oldest sample.

    ``samples`` is (L, N, 3) oldest first; ``colors`` (N, 3); ``radii`` (N,); ``current`` (N, 3) joins
    the newest sample to where the ball is drawn now. Each ball's strip repeats its first and last
    vertex, so the triangles joining one strip to the next have no area.
    """
    points = np.asarray(samples, dtype=np.float32)
    if current is not None:
        points = np.concatenate([points, np.asarray(current, dtype=np.float32)[None]])
    length, count = points.shape[:2]
    if length < 2 or count == 0:
        return empty()
    tangent = np.empty_like(points)  # along the path: central differences, one-sided at the ends
    tangent[1:-1] = points[2:] - points[:-2]
    tangent[0], tangent[-1] = points[1] - points[0], points[-1] - points[-2]
    side = np.cross(tangent, points - np.asarray(eye, dtype=np.float32))  # across the path, facing the eye
    norm = np.linalg.norm(side, axis=-1, keepdims=True)
    side = np.divide(side, norm, out=np.zeros_like(side), where=norm > 1e-12)  # a ball at rest: no width
    grow = np.linspace(0.0, 1.0, length, dtype=np.float32)[:, None]  # 0 at the oldest sample, 1 now
    half = 0.5 * TRAIL_WIDTH * np.asarray(radii, dtype=np.float32)[None, :] * (1.0 + 2.0 * grow) / 3.0
    strip = np.empty((count, length, 2, VERTEX_WIDTH), dtype=np.float32)
    offset = (side * half[..., None]).transpose(1, 0, 2)  # (N, L, 3)
    along = points.transpose(1, 0, 2)
    strip[:, :, 0, :3] = along - offset
    strip[:, :, 1, :3] = along + offset
    strip[..., 3:6] = np.asarray(colors, dtype=np.float32)[:, None, None, :]
    strip[..., 6] = (TRAIL_ALPHA * grow[:, 0])[None, :, None]
    strip = strip.reshape(count, 2 * length, VERTEX_WIDTH)
    return np.concatenate([strip[:, :1], strip, strip[:, -1:]], axis=1).reshape(-1, VERTEX_WIDTH)
