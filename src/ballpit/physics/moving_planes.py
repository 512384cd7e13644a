"""Kinematic planes: each plane moves as told, with a velocity v and an angular velocity ω (world
frame, about its centre), and no ball pushes it.

A point p on a plane moves at its surface velocity v + ω × (p − c) (c the centre). Contacts use that
velocity at the contact point, so restitution and friction act on the relative motion: a ball rides an
elevator, a paddle moving at u launches a resting ball at (1 + e)·u, and a bounce on a plane moving at
constant velocity is the bounce on a still one, seen from the plane (Galilean invariance).
"""

from __future__ import annotations

import numpy as np

from . import exact, quaternion
from .model import Model
from .state import Columns, State


def set_orientation(pose: Columns, i: int, q: np.ndarray) -> None:
    """Store orientation ``q`` of plane ``i`` with the axes it gives: x (width), y (normal) and z."""
    axes = quaternion.rotate(q, np.eye(3))  # rows: the plane's x, y (normal) and z axes
    pose.full("orientation")[i] = q
    pose.full("axis_u")[i] = axes[0]
    pose.full("normal")[i] = axes[1] / exact.norm(axes[1])
    pose.full("axis_v")[i] = axes[2]


def advance(model: Model, state: State, h: float) -> None:
    """Move every plane along its velocity and turn it about its centre by ω·h (exactly, not a
    first-order update, so a plane turned for a long time stays a rectangle)."""
    pl, pose = model.planes, state.planes
    moving = np.flatnonzero(pl.velocity.any(axis=1) | pl.angular_velocity.any(axis=1))
    if moving.size == 0:
        return
    pose.center[moving] += pl.velocity[moving] * h
    spin = pl.angular_velocity[moving]
    rate = np.linalg.norm(spin, axis=1)
    turning = rate > 0.0
    if turning.any():
        rows = moving[turning]
        axis = spin[turning] / rate[turning, None]
        turn = quaternion.from_axis_angle(axis, rate[turning] * h)
        q = quaternion.normalize(quaternion.multiply(turn, pose.orientation[rows]))
        for i, qi in zip(rows, q, strict=True):  # a few planes, not balls
            set_orientation(pose, i, qi)


def surface_velocity(model: Model, state: State, plane: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Velocity of the surface of ``plane[k]`` at ``points[k]``: v + ω × (p − c)."""
    pl = model.planes
    offset = points - state.planes.center[plane]
    return pl.velocity[plane] + np.cross(pl.angular_velocity[plane], offset)


def frames_at(model: Model, state: State, plane: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Centre and in-plane axes (u, v) of ``plane[k]`` after ``t[k]`` seconds of its motion."""
    pl, pose = model.planes, state.planes
    center = pose.center[plane] + pl.velocity[plane] * t[:, None]
    spin = pl.angular_velocity[plane]
    rate = np.linalg.norm(spin, axis=1)
    axis = spin / np.where(rate > 0.0, rate, 1.0)[:, None]
    turn = quaternion.from_axis_angle(axis, rate * t)  # the identity where the plane does not turn
    return center, quaternion.rotate(turn, pose.axis_u[plane]), quaternion.rotate(turn, pose.axis_v[plane])


def sweep(model: Model, plane: int, h: float, distance: np.ndarray) -> np.ndarray:
    """How far a point of ``plane`` within ``distance`` of its centre can move in ``h``:
    |v|·h + |ω|·h·(d + |v|·h) (an arc is never longer than its angle times its radius)."""
    pl = model.planes
    shift = float(exact.norm(pl.velocity[plane])) * h
    return shift + float(exact.norm(pl.angular_velocity[plane])) * h * (distance + shift)


def closing_speed_bound(model: Model, state: State, ball: np.ndarray, plane: np.ndarray, v: np.ndarray,
                        acc: np.ndarray, h: float) -> np.ndarray:  # fmt: skip
    """A bound on how fast each ball (velocity ``v``, acceleration ``acc`` along its path) can close on
    its moving plane over the next ``h``: |v − v_p| + |a|·h + |ω_p|·D, where D bounds the ball's
    distance from the plane's centre over the interval (the closest point is never farther)."""
    pl = model.planes
    dv = v - pl.velocity[plane]
    linear = np.linalg.norm(dv, axis=1) + np.linalg.norm(acc, axis=1) * h
    far = np.linalg.norm(state.body[ball, 0:3] - state.planes.center[plane], axis=1) + linear * h
    return linear + np.linalg.norm(pl.angular_velocity[plane], axis=1) * far
