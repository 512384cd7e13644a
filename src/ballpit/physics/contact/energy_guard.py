"""The energy guards: what a contact stage does to the balls may lose mechanical energy, never gain it.

The rule, one for every guard: where nothing does work on the balls but gravity, a contact stage's
result has no more energy, E = Σ ½·m·v² + ½·I·ω² − m·g·x over the balls it moved, than they had before
it. The stages are exact in their limits (a converged impact solve, a soft spring at rest), but not
always on the way there; where one would add energy, the gain is taken out of the motion of the balls
it moved, by the one factor that keeps what that stage must keep:

- ``impulses`` (impacts.py: each wave and each stop of the split step, and the soft frame's
  restitution waves): the impulses just applied are scaled down until the kinetic energy is what it
  was. Equal and opposite impulses stay so: momentum is kept. Not checked against a moving plane, which
  may give energy (a paddle).
- ``lift`` (penetration.py, and the soft frame's moving overlaps apart): positions moved apart lift
  balls against gravity; the potential energy that adds is paid out of the moved balls' kinetic energy,
  their velocities scaled (every direction of motion kept). A lowering is left alone.
- ``frame`` (a soft frame as a whole, step/soft.py, where no plane moves): the velocities relative to
  the centre of mass and the spins are scaled (momentum and every direction kept); when the springs
  lifted the balls more than their motion can pay, the rising balls are taken back part way.

Each guard is switched by ``Model.guards`` (``settings.EnergyGuards``, all on by default), so a test can show
what each prevents; a world's results are those of the guards on.
"""

from __future__ import annotations

import math

import numpy as np

from ..core import exact
from ..core.state import State, V, W, X
from ..dynamics.model import Model
from .rows import ContactRows


def keep_impulses(
    model: Model, rows: ContactRows, before: tuple[np.ndarray, ...], v: np.ndarray, w: np.ndarray
) -> float:
    """Make sure the impulses just applied to the balls of ``rows`` added no kinetic energy, and return
    the factor they were scaled by (1 when they added none).

    With Δ the velocity change, K(s) = K₀ + s·B + ½·s²·A (B = Σ m·v₀·Δv + I·ω₀·Δω, A = Σ m·Δv² + I·Δω²).
    If K(1) > K₀, the impulses are scaled by s = −2B/A (0 if B ≥ 0), where K(s) = K₀: equal and opposite
    impulses stay so, and momentum is kept. A moving plane may give energy (a paddle): not checked then.
    """
    balls, v0, w0 = before
    if not model.guards.impulses or rows.moving or len(balls) == 0:
        return 1.0
    dv, dw = v[balls] - v0, w[balls] - w0
    mass = model.spheres.mass[balls]
    inertia = 1.0 / model.spheres.inv_inertia[balls]

    dot, total = exact.dot_rows, exact.correctly_rounded_total
    b = total(mass * dot(v0, dv)) + total(inertia * dot(w0, dw))
    a = total(mass * dot(dv, dv)) + total(inertia * dot(dw, dw))
    if b + 0.5 * a <= 0.0 or a == 0.0:
        return 1.0
    s = max(0.0, -2.0 * b / a)
    v[balls] = v0 + s * dv
    w[balls] = w0 + s * dw
    return s


def wave_scale(
    model: Model, moving: bool, impulse: np.ndarray, vn: np.ndarray, after: np.ndarray
) -> float | None:
    """The factor a wave's normal ``impulse`` must be scaled by so that it adds no kinetic energy, or
    None when it adds none: the change is ΔK = Σ P·v_n + ½·Σ P·Δv_n for normal impulses on spheres
    (they do not turn the balls), with ``vn`` and ``after`` each contact's normal speed before and after
    them, and K(s) = K₀ + s·B + ½·s²·A is back to K₀ at s = −2B/A (``keep_impulses``' rule)."""
    if not model.guards.impulses or moving:
        return None
    gain_b = exact.total(impulse * vn)
    gain_a = exact.total(impulse * (after - vn))
    if gain_b + 0.5 * gain_a > 0.0 and gain_a > 0.0:
        return max(0.0, -2.0 * gain_b / gain_a)
    return None


def pay_for_lift(model: Model, state: State, old: np.ndarray, new: np.ndarray, partly: bool = False) -> None:
    """Take the potential energy a separation adds, ΔU = −Σ m·g·Δx, out of the moved balls' kinetic
    energy (their velocities scaled by √(1 − ΔU/K)), so removing overlaps never adds energy.

    Moving positions alone lifts balls against gravity: in a closed elastic box that once made the
    total energy creep up by 1e-5 every few seconds (nphysics #69 and haxball #2157 report the same).
    A lowering separation is left alone: energy lost there stays lost.

    When the moved balls' kinetic energy cannot pay for the whole lift, ``partly`` moves them only the
    part of the way it pays for, K/ΔU (``new`` changes in place), and stops them: the split step then
    leaves a resting overlap the soft step held (within its slop) as it is, instead of lifting a ball
    at rest out of it for nothing (a settled pile gained up to 1.7e-5 J a step that way). Without it
    the balls are moved all the way (the soft step's push-outs, and planes that win).
    """
    if not model.guards.lift:
        return
    moved = ((new != old).any(axis=1)).nonzero()[0]
    if moved.size == 0:
        return
    mass = model.spheres.mass[moved]
    lift = -exact.total(mass * exact.dot_rows(new[moved] - old[moved], model.gravity))
    if lift <= 0.0:
        return
    v = state.body[moved, V]
    kinetic = 0.5 * exact.total(mass * exact.dot_rows(v, v))
    if partly and kinetic < lift:
        new[moved] = old[moved] + (kinetic / lift) * (new[moved] - old[moved])
    scale = np.sqrt(max(0.0, 1.0 - lift / kinetic)) if kinetic > 0.0 else 0.0
    state.body[moved, V] = v * scale


def hold_frame(model: Model, state: State, before: np.ndarray, balls: np.ndarray) -> None:
    """Take any energy the frame gained out of the balls ``balls`` it moved: with no moving plane doing
    work, a frame may lose energy (inelastic bounces, friction) but never gain it, yet pushing overlaps
    apart lifts balls and a Jacobi restitution pass can overshoot. Their velocities relative to their
    centre of mass (and their spins) are scaled by the one factor that gives back the energy they had
    at ``before``, E = ½·m·v² + ½·I·ω² − m·g·x: momentum is kept, and so is every direction of motion.

    When the springs lifted the balls by more than all their motion relative to the centre of mass
    can pay (a settled pile whose load shifted: the overlaps it sank into spring back), that motion
    is stopped and the balls that rose are taken back towards where they started, each by the one
    fraction λ of its rise that leaves the energy they had (the potential −m·g·x is linear in x, so
    λ is exact); the balls that sank keep their places. The overlaps left are those of the frame's
    start or less, and the next frames push them apart as far as energy allows."""
    if not model.guards.frame or model.moving_planes():  # a moving plane may do work on the balls
        return
    sleeping = state.sleep.asleep
    if len(sleeping) == len(state.body) and sleeping.any():
        balls = balls[~sleeping[balls]]
    if balls.size == 0:
        return
    sph = model.spheres
    mass, inertia = sph.mass[balls], 1.0 / sph.inv_inertia[balls]
    g = model.gravity
    old, new = before[balls], state.body[balls]

    def energy(rows: np.ndarray) -> tuple[float, float]:
        v, w, x = rows[:, V], rows[:, W], rows[:, X]
        kinetic = 0.5 * (mass * exact.dot_rows(v, v) + inertia * exact.dot_rows(w, w))
        potential = -mass * exact.dot_rows(x, g)
        return exact.total(kinetic), exact.total(potential)

    k0, u0 = energy(old)
    k1, u1 = energy(new)
    if k1 + u1 <= k0 + u0:
        return
    total = exact.total(mass)
    v, w = new[:, V], new[:, W]
    momentum = mass[:, None] * v
    v_cm = np.array([exact.total(momentum[:, i]) for i in range(3)]) / total
    k_cm = 0.5 * total * float(v_cm[0] ** 2 + v_cm[1] ** 2 + v_cm[2] ** 2)
    k_rel = k1 - k_cm
    room = k0 + u0 - u1 - k_cm
    scale = math.sqrt(room / k_rel) if room > 0.0 and k_rel > 0.0 else 0.0
    state.body[balls, V] = v_cm + scale * (v - v_cm)
    state.body[balls, W] = scale * w
    if room < 0.0:  # the rise is more than the motion can pay: take the rising balls part way back
        x0, x1 = old[:, X], new[:, X]
        rise = -mass * exact.dot_rows(x1 - x0, g)
        up = rise > 0.0
        lifted = exact.total(np.where(up, rise, 0.0))
        fraction = min(max(1.0 + room / lifted, 0.0), 1.0) if lifted > 0.0 else 1.0
        state.body[balls[up], 0:3] = x0[up] + fraction * (x1[up] - x0[up])
