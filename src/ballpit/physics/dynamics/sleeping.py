"""Sleeping: balls that have been still for a while stop costing anything until something reaches them.

Every engine built for piles does this (Box2D's islands, Bullet's deactivation, PhysX, Jolt): a
settled pile is the state most scenes spend most of their time in. The rules, as in Box2D v3:

- A ball is *still* while its speed and its surface speed from spin, |ω|·r, are both below
  SLEEP_SPEED. Its rest timer counts how long it has been still.
- Balls touching each other form an island; an island falls asleep whole, and only when every ball in
  it has been still for TIME_TO_SLEEP. Asleep, a ball's velocity and spin are exactly zero and a step
  leaves it where it is: its pairs with other sleeping balls and with planes are not measured or
  solved, and a holding force cancels its free acceleration, so it neither falls nor drifts. The
  warm start of its pairs is put aside while it sleeps and given back when it wakes
  (``resting.WarmStart.put_to_sleep`` and ``wake``), so a woken pile holds where it was.
- An island wakes whole when an awake ball touches one of its balls or could reach one within the
  step (the same bound the crowd test uses), when a step leaves one of its balls moving, or when one
  of its balls is moved or set moving by hand. Changing gravity or the radii, moving any plane, or
  switching sleeping off wakes every ball.

Sleeping is off by default (``World.sleep``), so a world steps exactly as it did without it.
"""

from __future__ import annotations

import numpy as np

from ..core.contacts import SPHERE_SPHERE, ContactPoints
from ..core.settings import SLEEP_SPEED, TIME_TO_SLEEP
from ..core.state import Q, Sleep, State, V, W, X
from .forces import ConstantPerBall
from .model import Model


def context(model: Model, state: State) -> tuple:
    """What a sleeping ball's rest depends on besides its neighbours: gravity, radii and planes."""
    pose = state.planes
    return (
        model.gravity.tobytes(),
        model.spheres.radius.tobytes(),
        pose.center.tobytes(),
        pose.orientation.tobytes(),
    )


def before_step(model: Model, state: State, sleep: Sleep, enabled: bool) -> None:
    """Wake what changed since the last step: balls moved or set moving by hand (their islands),
    and every ball when sleeping is off, a plane moves, or gravity, a radius or a plane changed."""
    sleep.fit(model.spheres.count)
    if not sleep.any:
        return
    now = context(model, state)
    if not enabled or model.moving_planes() or now != sleep.context:
        sleep.wake_all()
        return
    body = state.body
    idx = sleep.asleep.nonzero()[0]
    held = body[idx]
    moving = (held[:, V] != 0.0).any(axis=1) | (held[:, W] != 0.0).any(axis=1)
    moved = (np.hstack((held[:, X], held[:, Q])) != sleep.pose[idx]).any(axis=1)
    edited = moving | moved
    if edited.any():
        sleep.wake(idx[edited])


def hold(sleep: Sleep, free: tuple[np.ndarray, np.ndarray]) -> ConstantPerBall:
    """A force term that cancels the free accelerations ``free`` of the sleeping balls (no others)."""
    lin, ang = free
    mask = sleep.asleep[:, None]
    return ConstantPerBall(np.where(mask, -lin, 0.0), np.where(mask, -ang, 0.0))


def reached(c: ContactPoints, asleep: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """The sleeping balls that an awake ball touches or may reach in the step (``reach``: the
    contacts within reach), as a mask over the balls."""
    n = len(asleep)
    ball_pair = c.kind == SPHERE_SPHERE
    other = np.where(ball_pair, c.other, n)
    flags = np.append(asleep, False)
    a_sleeps, b_sleeps = flags[c.a], flags[other]
    hit = reach & ball_pair & (a_sleeps != b_sleeps)
    out = np.zeros(n + 1, bool)
    out[c.a[hit & a_sleeps]] = True
    out[other[hit & b_sleeps]] = True
    return out[:n]


def islands(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A label per ball: balls joined by the edges (a, b) share one (the smallest index among them).

    Min-label propagation with pointer jumping: each round every edge pulls both ends' labels down to
    the smaller, then every label is replaced by its own label's label.
    """
    label = np.arange(n)
    if len(a) == 0:
        return label
    while True:
        low = np.minimum(label[a], label[b])
        new = label.copy()
        np.minimum.at(new, a, low)
        np.minimum.at(new, b, low)
        new = new[new]
        if np.array_equal(new, label):
            return label
        label = new


def may_fall_asleep(sleep: Sleep, dt: float) -> bool:
    """Whether some awake ball will have been still for TIME_TO_SLEEP if it stays still this step."""
    return bool(((sleep.rest + dt >= TIME_TO_SLEEP) & ~sleep.asleep).any())


def links(c: ContactPoints, reach: np.ndarray, touching: float) -> tuple[np.ndarray, np.ndarray]:
    """The ball–ball pairs (a, b) of ``c`` that join islands: those touching (closer than ``touching``)
    or within reach of each other (``reach``, a mask over ``c``), whose balls would wake each other."""
    linked = (c.kind == SPHERE_SPHERE) & (reach | (c.gap < touching))
    return c.a[linked], c.other[linked]


def after_step(
    model: Model, state: State, sleep: Sleep, joined: tuple[np.ndarray, np.ndarray] | None, dt: float
) -> None:
    """Update the rest timers and put to sleep the islands whose balls have all been still for
    TIME_TO_SLEEP; wake any sleeping ball the step left moving.

    Islands are joined by the ball–ball pairs ``joined`` (``links`` of the contacts measured at the
    step's start). They may be None when no ball was asleep and none ``may_fall_asleep``: then none
    falls.
    """
    body = state.body
    n = len(body)
    radius = model.spheres.radius
    speed = np.einsum("ij,ij->i", body[:, V], body[:, V])
    spin = np.einsum("ij,ij->i", body[:, W], body[:, W]) * radius**2
    still = (speed < SLEEP_SPEED**2) & (spin < SLEEP_SPEED**2)
    if sleep.any:
        # A sleeping ball hit during the step by a path no contact foresaw wakes; one an awake ball
        # only leaned on stays where it fell asleep, as still as a plane.
        hit = sleep.asleep & ~still
        if hit.any():
            sleep.wake(hit)
        idx = sleep.asleep.nonzero()[0]
        body[idx, V] = 0.0
        body[idx, W] = 0.0
        body[idx, X] = sleep.pose[idx, :3]
        body[idx, Q] = sleep.pose[idx, 3:]
    awake = ~sleep.asleep
    sleep.rest = np.where(awake, np.where(still, sleep.rest + dt, 0.0), sleep.rest)
    ready = awake & (sleep.rest >= TIME_TO_SLEEP)
    if not ready.any():
        return
    a, b = joined
    both = awake[a] & awake[b]
    label = islands(n, a[both], b[both])
    restless = np.unique(label[awake & ~ready])
    falls = ready & ~np.isin(label, restless)
    if not falls.any():
        return
    idx = falls.nonzero()[0]
    _, group = np.unique(label[idx], return_inverse=True)
    body[idx, V] = 0.0
    body[idx, W] = 0.0
    sleep.fall_asleep(idx, group, body[idx, X], body[idx, Q])
    sleep.context = context(model, state)
