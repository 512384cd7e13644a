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
- ``push`` (the split step's resting solve, resting.py): what its constant contact forces added over
  an interval is paid out of the pushed balls' kinetic energy, or, when they lifted the balls more
  than that can pay, the interval is taken back part way (as the frame guard's last resort).
- ``frame`` (a soft frame as a whole, step/soft.py, where no plane moves): the rising balls are taken
  back a little, then the velocities relative to the centre of mass and the spins are scaled
  (momentum and every direction kept); when the springs lifted the balls more than their motion can
  pay, the rising balls are taken back further and every ball's velocity made its move over the
  frame, so that the velocities always tell how the balls moved.

Each guard is switched by ``Model.guards`` (``settings.EnergyGuards``, all on by default), so a test can show
what each prevents; a world's results are those of the guards on.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..core import exact
from ..core.settings import GUARD_TAKE_BACK, INTERVAL_ROUNDING, TINY
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


def keep_interval(model: Model, state: State, balls: np.ndarray, before: np.ndarray) -> None:
    """Make sure an interval under the resting solve's constant forces added no energy to the balls
    ``balls`` they pushed (``before``: their rows at its start): a converged solve leaves no pushing
    contact separating, and its forces do no work, but one that is not (balls of a hundred to one) may
    push a ball on. The gain, ΔE = ΔK − Σ m·g·Δx, is paid out of their kinetic energy (velocities and
    spins scaled by √(1 − ΔE/K)), as a lift is (``pay_for_lift``); positions stay. When the forces
    lifted the balls more than their motion can pay (ΔE ≥ K: a light ball squeezed out of a wedge
    rises, its speed spent), the interval is taken back part way, every move, velocity and spin by one
    fraction (``_take_part_back``), so that the energy is what it was. Checked for the integrators
    exact under constant forces (RK2, RK4: a path of bend 1): explicit Euler gains energy in free fall
    on its own, and no moving plane, which may give energy."""
    if not model.guards.push or model.integrator.bend != 1.0 or model.moving_planes() or balls.size == 0:
        return
    sph = model.spheres
    mass, inertia = sph.mass[balls], 1.0 / sph.inv_inertia[balls]
    rows = state.body[balls]
    dot, total = exact.dot_rows, exact.correctly_rounded_total

    def kinetic(r: np.ndarray) -> float:
        return 0.5 * (total(mass * dot(r[:, V], r[:, V])) + total(inertia * dot(r[:, W], r[:, W])))

    k0, k1 = kinetic(before), kinetic(rows)
    fall = mass * dot(rows[:, X] - before[:, X], model.gravity)  # −ΔU per ball
    gain = k1 - k0 - total(fall)
    if gain <= INTERVAL_ROUNDING * (k1 + total(np.abs(fall))):  # rounding in exact sums of inexact terms
        return
    if gain >= k1:  # the motion cannot pay: λ²·K₁ − λ·Σ m·g·Δx = K₀
        _take_part_back(state, balls, before[:, X], rows[:, X], k0, k1, -total(fall))
        return
    scale = math.sqrt(1.0 - gain / k1)
    state.body[balls, V] = rows[:, V] * scale
    state.body[balls, W] = rows[:, W] * scale


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


def hold_frame(model: Model, state: State, before: np.ndarray, balls: np.ndarray, dt: float = 0.0) -> None:
    """Take any energy the frame gained out of the balls ``balls`` it moved: with no moving plane doing
    work, a frame may lose energy (inelastic bounces, friction) but never gain it, yet pushing overlaps
    apart lifts balls and a Jacobi restitution pass can overshoot. A gain of
    E = Σ ½·m·v² + ½·I·ω² − m·g·x against ``before`` is given back in steps, each only as far as it is
    left, so that the velocities still tell how the balls moved:

    1. the balls that rose are taken back along their moves, each by at most GUARD_TAKE_BACK of its
       radius (``_take_back``): their velocities stay as the frame made them;
    2. their velocities relative to their centre of mass (and their spins) are scaled by one factor:
       momentum is kept, and so is every direction of motion;
    3. when that motion cannot pay, the frame is taken back part way (``_take_part_back``): every
       move, velocity and spin by one fraction. A settled pile whose soft springs would lift it,
       more than its motion can pay, is held where it is, still.
    """
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

    def energy(rows: np.ndarray) -> tuple[float, float]:
        v, w, x = rows[:, V], rows[:, W], rows[:, X]
        kinetic = 0.5 * (mass * exact.dot_rows(v, v) + inertia * exact.dot_rows(w, w))
        potential = -mass * exact.dot_rows(x, g)
        return exact.total(kinetic), exact.total(potential)

    # ``balls`` is sorted and distinct: when it is every ball, the energies are read from the blocks
    # themselves (the same elementwise terms), not from copies of them (104 bytes a ball each)
    every = len(balls) == len(state.body)

    def gain() -> float:  # what E rose by
        k, u = energy(state.body if every else state.body[balls])
        return k + u - k0 - u0

    old = before if every else before[balls]
    k0, u0 = energy(old)
    gained = gain()
    if gained > 0.0:
        body = (mass, inertia, sph.radius[balls], g)
        _give_back(state, balls, old, state.body[balls], body, (k0, u0, dt), gained, gain)


def _give_back(
    state: State,
    balls: np.ndarray,
    old: np.ndarray,
    new: np.ndarray,
    body: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    start: tuple[float, float, float],
    gained: float,
    gain: Callable[[], float],
) -> None:
    """``hold_frame``'s three steps, for the balls ``balls`` (their ``old`` and ``new`` rows; their
    masses, inertias, radii and gravity, ``body``; their energies K₀ and U₀ at the ``start``): what the
    frame ``gained`` is given back; ``gain`` measures what is left of it after the first step."""
    mass, inertia, radius, g = body
    k0, u0, dt = start
    x0 = old[:, X]
    rise = -mass * exact.dot_rows(new[:, X] - x0, g)
    _take_back(new, x0, rise, GUARD_TAKE_BACK * radius, gained)
    state.body[balls, 0:3] = new[:, X]
    left = gain()
    if left <= 0.0:
        return
    total = exact.total(mass)
    v, w = new[:, V], new[:, W]
    momentum = mass[:, None] * v
    v_cm = np.array([exact.total(momentum[:, i]) for i in range(3)]) / total
    k_cm = 0.5 * total * float(v_cm[0] ** 2 + v_cm[1] ** 2 + v_cm[2] ** 2)
    k1 = 0.5 * exact.total(mass * exact.dot_rows(v, v) + inertia * exact.dot_rows(w, w))
    k_rel = k1 - k_cm
    room = k_rel - left  # the relative motion's energy, less the gain it is to pay
    if room >= 0.0:
        scale = math.sqrt(room / k_rel)
        state.body[balls, V] = v_cm + scale * (v - v_cm)
        state.body[balls, W] = scale * w
        return
    if dt > 0.0 and _tell_moves(state, balls, x0, new[:, X], mass, g, k0, dt):
        return
    u1 = -exact.total(mass * exact.dot_rows(new[:, X], g))
    _take_part_back(state, balls, x0, new[:, X], k0, k1, u1 - u0)


def _tell_moves(
    state: State,
    balls: np.ndarray,
    x0: np.ndarray,
    x1: np.ndarray,
    mass: np.ndarray,
    g: np.ndarray,
    k0: float,
    dt: float,
) -> bool:
    """When the motion cannot pay for the gain: each ball's velocity is made its move over the frame,
    v = Δx/dt (spins stopped), the balls that sank keeping their moves and those that rose taken back
    by one fraction f of theirs, the most that keeps the energy: with K_s, K_r the kinetic energies
    of the sinking and rising balls' moves and D < 0, R > 0 the potential energy their moves add,
    K_s + f²·K_r + D + f·R ≤ k0. False (nothing changed) when even f = 0 is too much."""
    move = x1 - x0
    du = -mass * exact.dot_rows(move, g)
    up = du > 0.0
    k = 0.5 * mass * exact.dot_rows(move, move) / (dt * dt)
    k_s, k_r = exact.total(np.where(up, 0.0, k)), exact.total(np.where(up, k, 0.0))
    d, r = exact.total(np.where(up, 0.0, du)), exact.total(np.where(up, du, 0.0))
    c = k_s + d - k0
    if c > 0.0:
        return False
    if k_r + r + c <= 0.0:
        f = 1.0
    elif k_r > 0.0:
        f = (-r + math.sqrt(r * r - 4.0 * k_r * c)) / (2.0 * k_r)
    else:
        f = -c / r
    f = min(max(f, 0.0), 1.0)
    moved = np.where(up[:, None], f * move, move)
    state.body[balls, 0:3] = x0 + moved
    state.body[balls, V] = moved / dt
    state.body[balls, W] = 0.0
    return True


def _take_part_back(
    state: State, balls: np.ndarray, x0: np.ndarray, x1: np.ndarray, k0: float, k1: float, du: float
) -> None:
    """The last resort of ``hold_frame``, when the balls' motion relative to their centre of mass
    cannot pay for the gain: the frame is taken back part way, every ball's move from ``x0`` to ``x1``,
    its velocity and its spin by one fraction λ, so that the velocities still tell the moves:
    x = x0 + λ·(x1 − x0), v = λ·v₁, ω = λ·ω₁. The energy is then k0 + u0 + (λ²·k1 + λ·du − k0) (``du`` =
    u1 − u0 the potential energy the whole move added, linear in λ; ``k1`` the kinetic energy at the
    frame's end), so λ is the larger root of λ²·k1 + λ·du = k0. A settled pile whose soft springs
    would lift it, with no motion to pay for that, is held where it is, still."""
    lam = (-du + math.sqrt(du * du + 4.0 * k1 * k0)) / (2.0 * k1) if k1 > 0.0 else k0 / du
    lam = min(max(lam, 0.0), 1.0)
    state.body[balls, 0:3] = x0 + lam * (x1 - x0)
    state.body[balls, V] *= lam
    state.body[balls, W] *= lam


def _take_back(new: np.ndarray, x0: np.ndarray, rise: np.ndarray, cap: np.ndarray, gain: float) -> None:
    """Take the balls that rose (``rise`` > 0, the potential energy their moves from ``x0`` added) back
    along their moves, by one fraction t of each move, but each by at most ``cap`` (m): ball i by
    t_i = min(t, τ_i), τ_i = min(1, cap_i/|Δx_i|), with t the least that gives back ``gain`` (J), or all
    of it that the caps allow. The energy given back, Σ rise_i·t_i, is piecewise linear in t, with a
    knee at each τ: found over the τ sorted. Changes the positions of ``new`` in place."""
    up = np.flatnonzero(rise > 0.0)
    if up.size == 0:
        return
    move = new[up, 0:3] - x0[up]
    length = exact.norm_rows(move)
    tau = np.minimum(1.0, cap[up] / np.maximum(length, TINY))
    order = np.argsort(tau, kind="stable")
    tau_s, rise_s = tau[order], rise[up][order]
    done = np.cumsum(rise_s * tau_s)  # what the balls up to each knee give back, taken back in full
    left = np.append(np.cumsum(rise_s[::-1])[::-1][1:], 0.0)  # what the later ones rise
    at_knee = done + tau_s * left
    k = int(np.searchsorted(at_knee, gain))
    if k == len(tau_s):
        t = float(tau_s[-1])
    else:
        before_k = float(done[k - 1]) if k > 0 else 0.0
        t = (gain - before_k) / float(rise_s[k] + left[k])
    back = np.minimum(t, tau)
    new[up, 0:3] = new[up, 0:3] - back[:, None] * move
