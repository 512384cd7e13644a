"""Debug overlays as line vertices: contact points and normals, velocity arrows, trails.

Each builder returns a float32 array of shape (2·segments, 7): pairs of vertices (x, y, z, r, g, b, a)
ready for one ``GL_LINES`` draw. Everything is vectorised over contacts and balls.
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


def trail_lines(samples: np.ndarray, colors: np.ndarray, current: np.ndarray | None = None) -> np.ndarray:
    """Lines through each ball's recent positions, fading out towards the oldest.

    ``samples`` is (L, N, 3) oldest first; ``colors`` (N, 3); ``current`` (N, 3) joins the newest sample
    to where the ball is drawn now.
    """
    samples = np.asarray(samples, dtype=np.float32)
    if current is not None:
        samples = np.concatenate([samples, np.asarray(current, dtype=np.float32)[None]])
    length, count = samples.shape[:2]
    if length < 2 or count == 0:
        return empty()
    starts = samples[:-1].reshape(-1, 3)
    ends = samples[1:].reshape(-1, 3)
    fade = np.linspace(0.0, 0.9, length, dtype=np.float32)
    rgb = np.asarray(colors, dtype=np.float32)[None, :, :]
    start_alpha = np.broadcast_to(fade[:-1, None, None], (length - 1, count, 1))
    end_alpha = np.broadcast_to(fade[1:, None, None], (length - 1, count, 1))
    rgb = np.broadcast_to(rgb, (length - 1, count, 3))
    start_colors = np.concatenate([rgb, start_alpha], axis=-1).reshape(-1, 4)
    end_colors = np.concatenate([rgb, end_alpha], axis=-1).reshape(-1, 4)
    return _segments(starts, ends, np.stack([start_colors, end_colors]))
