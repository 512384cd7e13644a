"""Kinematic planes: each plane moves as told, with a velocity v and an angular velocity ω (world
frame, about its centre), and no ball pushes it.

A point p on a plane moves at its surface velocity v + ω × (p − c) (c the centre). Contacts use that
velocity at the contact point, so restitution and friction act on the relative motion: a ball rides an
elevator, a paddle moving at u launches a resting ball at (1 + e)·u, and a bounce on a plane moving at
constant velocity is the bounce on a still one, seen from the plane (Galilean invariance).
"""

from __future__ import annotations

import math

import numpy as np

from ..core import exact, quaternion
from ..core.state import Columns, State
from .model import Model


def place(pose: Columns, i: int, center: np.ndarray, q: np.ndarray) -> None:
    """The pose of plane ``i``, just added: its centre and its orientation ``q`` (with the axes it gives)."""
    pose.reserve(1)
    pose.full("center")[i] = center
    set_orientation(pose, i, q)


def set_orientation(pose: Columns, i: int, q: np.ndarray) -> None:
    """Store orientation ``q`` of plane ``i`` with the axes it gives: x (width), y (normal) and z."""
    _store_orientation(pose, i, tuple(np.asarray(q, float).tolist()))


def advance(model: Model, state: State, h: float) -> None:
    """Move every plane along its velocity and turn it about its centre by ω·h (exactly, not a
    first-order update, so a plane turned for a long time stays a rectangle).

    A few planes, not balls: each is worked in Python floats, whose +, −, × and ÷ are the same
    correctly rounded operations as NumPy's elementwise ones and are taken in the same order as
    ``quaternion.multiply``, ``quaternion.normalize`` and ``quaternion.rotate`` take them (the same bits,
    without a dozen NumPy calls on one row each).
    """
    pl, pose = model.planes, state.planes
    velocity, spin = pl.velocity, model.plane_spin()
    moving = (model.moving_plane_mask()).nonzero()[0]
    if moving.size == 0:
        return
    center, orientation = pose.center, pose.orientation
    for i in moving.tolist():
        (cx, cy, cz), (vx, vy, vz) = center[i].tolist(), velocity[i].tolist()
        center[i] = (cx + vx * h, cy + vy * h, cz + vz * h)
        wx, wy, wz = spin[i].tolist()
        rate = exact.norm_floats(wx, wy, wz)  # as np.linalg.norm sums a row
        if rate > 0.0:
            px, py, pz, pw = _turn(wx, wy, wz, rate, h)
            qx, qy, qz, qw = orientation[i].tolist()
            # the Hamilton product turn ⊗ q (quaternion.multiply), then q / |q| (quaternion.normalize)
            x = pw * qx + px * qw + py * qz - pz * qy
            y = pw * qy - px * qz + py * qw + pz * qx
            z = pw * qz + px * qy - py * qx + pz * qw
            w = pw * qw - px * qx - py * qy - pz * qz
            size = math.sqrt((x * x + z * z) + (y * y + w * w))  # the order einsum sums four terms in
            _store_orientation(pose, i, (x / size, y / size, z / size, w / size))


# The turn of a plane turning at ω over h, by (ω, h): a plane turning steadily turns by the same
# quaternion every whole step, so its sine and cosine (exact.sin_cos) are worked out once. Keyed by the
# bits, so −0 and +0 stay apart.
_TURNS: dict[bytes, tuple[float, float, float, float]] = {}
_TURNS_KEPT = 256


def _turn(wx: float, wy: float, wz: float, rate: float, h: float) -> tuple[float, float, float, float]:
    """The rotation by rate·h about ω / rate (``quaternion.from_axis_angle``), as four floats."""
    key = np.array((wx, wy, wz, rate, h)).tobytes()
    turn = _TURNS.get(key)
    if turn is None:
        if len(_TURNS) >= _TURNS_KEPT:
            _TURNS.clear()
        sin, cos = (float(f) for f in exact.sin_cos(np.array(0.5 * (rate * h))))
        turn = _TURNS[key] = (wx / rate * sin, wy / rate * sin, wz / rate * sin, cos)
    return turn


def _store_orientation(pose: Columns, i: int, q: tuple[float, float, float, float]) -> None:
    """Store unit quaternion ``q`` of plane ``i`` and the axes it turns x, y and z to, each formed as
    ``quaternion.rotate`` forms it (v + w·t + u × t with t = 2·u × v, u the vector part, and
    ``exact.cross_rows``'s order), the normal divided by its length (``exact.norm_rows``)."""
    ux, uy, uz, w = q

    def rotate(vx: float, vy: float, vz: float) -> tuple[float, float, float]:
        tx, ty, tz = 2.0 * (uy * vz - uz * vy), 2.0 * (uz * vx - ux * vz), 2.0 * (ux * vy - uy * vx)
        return (
            vx + w * tx + (uy * tz - uz * ty),
            vy + w * ty + (uz * tx - ux * tz),
            vz + w * tz + (ux * ty - uy * tx),
        )

    nx, ny, nz = rotate(0.0, 1.0, 0.0)
    size = exact.norm_floats(nx, ny, nz)
    pose.full("orientation")[i] = q
    pose.full("axis_u")[i] = rotate(1.0, 0.0, 0.0)
    pose.full("normal")[i] = (nx / size, ny / size, nz / size)
    pose.full("axis_v")[i] = rotate(0.0, 0.0, 1.0)


def surface_velocity(model: Model, state: State, plane: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Velocity of the surface of ``plane[k]`` at ``points[k]``: v + ω × (p − c)."""
    pl = model.planes
    offset = points - state.planes.center[plane]
    return pl.velocity[plane] + exact.cross_rows(model.plane_spin()[plane], offset)


def frames_at(model: Model, state: State, plane: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Centre and in-plane axes (u, v) of ``plane[k]`` after ``t[k]`` seconds of its motion."""
    pl, pose = model.planes, state.planes
    center = pose.center[plane] + pl.velocity[plane] * t[:, None]
    spin = model.plane_spin()[plane]
    rate = exact.norm_rows(spin)
    axis = spin / np.where(rate > 0.0, rate, 1.0)[:, None]
    turn = quaternion.from_axis_angle(axis, rate * t)  # the identity where the plane does not turn
    return center, quaternion.rotate(turn, pose.axis_u[plane]), quaternion.rotate(turn, pose.axis_v[plane])


def sweep(model: Model, plane: int, h: float, distance: np.ndarray) -> np.ndarray:
    """How far a point of ``plane`` within ``distance`` of its centre can move in ``h``:
    |v|·h + |ω|·h·(d + |v|·h) (an arc is never longer than its angle times its radius)."""
    pl = model.planes
    shift = exact.norm_floats(*pl.velocity[plane].tolist()) * h
    return shift + exact.norm_floats(*model.plane_spin()[plane].tolist()) * h * (distance + shift)


def closing_speed_bound(
    model: Model, state: State, ball: np.ndarray, plane: np.ndarray, v: np.ndarray, acc: np.ndarray, h: float
) -> np.ndarray:
    """A bound on how fast each ball (velocity ``v``, acceleration ``acc`` along its path) can close on
    its moving plane over the next ``h``: |v − v_p| + |a|·h + |ω_p|·D, where D bounds the ball's
    distance from the plane's centre over the interval (the closest point is never farther)."""
    pl = model.planes
    dv = v - pl.velocity[plane]
    linear = exact.norm_rows(dv) + exact.norm_rows(acc) * h
    far = exact.norm_rows(state.body[ball, 0:3] - state.planes.center[plane]) + linear * h
    return linear + exact.norm_rows(model.plane_spin()[plane]) * far
