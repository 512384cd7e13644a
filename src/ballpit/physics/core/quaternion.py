"""Unit quaternions, scalar last ``(x, y, z, w)`` as pyrr and scipy store them, vectorised over rows.

Every function takes arrays of shape (..., 4) (and (..., 3) vectors) so one call handles all balls.
"""

from __future__ import annotations

import numpy as np

from . import exact
from .settings import ANTIPARALLEL

IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p ⊗ q (apply q first, then p)."""
    px, py, pz, pw = np.moveaxis(np.asarray(p, float), -1, 0)
    qx, qy, qz, qw = np.moveaxis(np.asarray(q, float), -1, 0)
    return np.stack(
        (
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        ),
        axis=-1,
    )


def normalize(q: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Scale each quaternion to unit length (in place when ``out`` is ``q``)."""
    q = np.asarray(q, float)
    norm = np.sqrt(np.einsum("...i,...i->...", q, q))[..., None]
    return np.divide(q, norm, out=out)


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v by unit quaternions q: v' = v + 2w(u×v) + 2u×(u×v), u the vector part."""
    q = np.asarray(q, float)
    v = np.asarray(v, float)
    u = q[..., :3]
    w = q[..., 3:4]
    t = 2.0 * exact.cross_rows(u, v)
    return v + w * t + exact.cross_rows(u, t)


def from_axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation by ``angle`` radians about the unit vector ``axis``."""
    axis = np.asarray(axis, float)
    sin, cos = exact.sin_cos(0.5 * np.asarray(angle, float)[..., None])
    return np.concatenate((axis * sin, cos), axis=-1)


def from_euler_xyz(degrees: np.ndarray) -> np.ndarray:
    """Extrinsic rotations about world X, then Y, then Z, in degrees (scipy's "xyz").

    Extrinsic x-then-y-then-z means R = Rz · Ry · Rx, so q = qz ⊗ qy ⊗ qx.
    """
    ax, ay, az = np.radians(np.asarray(degrees, float))
    qx = from_axis_angle(np.array([1.0, 0.0, 0.0]), ax)
    qy = from_axis_angle(np.array([0.0, 1.0, 0.0]), ay)
    qz = from_axis_angle(np.array([0.0, 0.0, 1.0]), az)
    return normalize(multiply(qz, multiply(qy, qx)))


def from_up_to(normal: np.ndarray) -> np.ndarray:
    """The shortest rotation taking +y to the unit vector ``normal`` (180° about x when it is −y)."""
    n = np.asarray(normal, float)
    up = np.array([0.0, 1.0, 0.0])
    d = float(exact.dot_rows(up, n))
    if d < -1.0 + ANTIPARALLEL:
        return np.array([1.0, 0.0, 0.0, 0.0])
    # q = (up × n, 1 + up·n) normalised is the half-angle form of the rotation between them.
    return normalize(np.concatenate((np.cross(up, n), [1.0 + d])))


def derivative(q: np.ndarray, omega: np.ndarray, out: np.ndarray) -> np.ndarray:
    """dq/dt = ½·(ω, 0) ⊗ q for a world-frame angular velocity ω, written into ``out`` (N, 4).

    With the pure quaternion (ω, 0) on the left: vector part ½(q_w·ω + ω × q_v), scalar −½ ω·q_v.
    """
    # Component by component: on the strided columns of the state block this is about twice as fast
    # as a cross product, which would first copy them.
    qx, qy, qz, qw = q.T
    wx, wy, wz = omega.T
    out[:, 0] = qw * wx + wy * qz - wz * qy
    out[:, 1] = qw * wy + wz * qx - wx * qz
    out[:, 2] = qw * wz + wx * qy - wy * qx
    out[:, 3] = -(wx * qx + wy * qy + wz * qz)
    out *= 0.5
    return out


def turn(q: np.ndarray, w: np.ndarray, h: float) -> None:
    """q ← normalise(q + h·½·(ω, 0)⊗q), in place (``w`` is (3, M))."""
    dq = np.empty_like(q)
    derivative(q, w.T, dq)
    dq *= h
    q += dq
    normalize(q, out=q)
