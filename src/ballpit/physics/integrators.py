"""Explicit integrators over the full rigid state (x, v, q, ω) of every ball at once.

The state derivative is (v, a, ½·(ω,0)⊗q, α), where a and α come from the force terms evaluated at
each stage. Spheres are isotropic, so there is no gyroscopic term: α is the torque times a scalar I⁻¹.
Orientations are renormalised after every step; nothing is clamped.

When no force term depends on the state (gravity and the contact solver's constant forces, the common
case), RK4 takes a fast path, ``rk4_constant``, with the very same arithmetic: see there.

``INTEGRATORS`` at the end is the registry: each method's name, label, colour, viewer key, order and
path are declared there once, and the command line, scene files, compare, plots, the viewer's keys and
ghosts, the broad phase and the time of impact all read them from it. A new integrator is one
function here plus one entry there.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from . import quaternion
from .forces import ForceTerm, constant_acceleration
from .settings import RK4_CHUNK
from .state import Q, V, W, X


def derivative(state: np.ndarray, forces: Sequence[ForceTerm], out: np.ndarray) -> np.ndarray:
    """Write d(state)/dt into ``out``."""
    out[:, X] = state[:, V]
    out[:, V] = 0.0
    out[:, W] = 0.0
    lin, ang = out[:, V], out[:, W]
    for term in forces:
        term.add(state, lin, ang)
    quaternion.derivative(state[:, Q], state[:, W], out[:, Q])
    return out


class Workspace:
    """Scratch arrays reused between steps so the hot path allocates nothing new."""

    def __init__(self) -> None:
        self._buffers: dict[tuple[str, tuple[int, ...]], np.ndarray] = {}

    def get(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        key = (name, shape)
        buf = self._buffers.get(key)
        if buf is None:
            if len(self._buffers) > 64:  # shapes change as balls are added; drop stale ones
                self._buffers.clear()
            buf = self._buffers[key] = np.empty(shape)
        return buf


def euler(state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace) -> None:
    """Explicit (forward) Euler: s ← s + h·f(s). First order."""
    k1 = derivative(state, forces, ws.get("k1", state.shape))
    state += h * k1


def rk2(state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace) -> None:
    """Midpoint Runge–Kutta: s ← s + h·f(s + ½h·f(s)). Second order."""
    k1 = derivative(state, forces, ws.get("k1", state.shape))
    mid = ws.get("s", state.shape)
    np.multiply(k1, 0.5 * h, out=mid)
    mid += state
    k2 = derivative(mid, forces, ws.get("k2", state.shape))
    state += h * k2


def symplectic_euler(state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace) -> None:
    """Symplectic (semi-implicit) Euler: kick, then drift with the new velocities.

    v ← v + h·a(s) and ω ← ω + h·α(s), then x ← x + h·v and q ← q + h·½(ω, 0)⊗q. First order like
    explicit Euler, and as cheap (one force evaluation), but it is symplectic: it keeps a nearby energy
    instead of pumping energy in. Under constant a a step lands at x + v·h + a·h² (explicit Euler at
    x + v·h), so a ball in free fall runs ½·g·t·h below the exact parabola and a bouncing ball loses
    about g·h of speed per flight where explicit Euler gains it.
    """
    k = derivative(state, forces, ws.get("k1", state.shape))
    state[:, V] += h * k[:, V]
    state[:, W] += h * k[:, W]
    state[:, X] += h * state[:, V]
    dq = quaternion.derivative(state[:, Q], state[:, W], ws.get("dq", (len(state), 4)))
    state[:, Q] += h * dq


def rk4(state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace) -> None:
    """Classical fourth-order Runge–Kutta with four force evaluations."""
    shape = state.shape
    trial = ws.get("s", shape)
    acc = ws.get("acc", shape)
    k = derivative(state, forces, ws.get("k", shape))
    np.copyto(acc, k)  # acc = k1
    for frac, weight in ((0.5, 2), (0.5, 2), (1.0, 1)):
        np.multiply(k, frac * h, out=trial)
        trial += state
        k = derivative(trial, forces, k)  # k2, k3, k4 in turn
        for _ in range(weight):
            acc += k
    acc *= h / 6.0
    state += acc


# The fast path's layout of a chunk, one ball per column: x, v, then q with its y and z repeated in
# front (qy qz qx qy qz qw) and ω with its x and y repeated behind (ωx ωy ωz ωx ωy), so the rotated
# copies ``_dq`` needs for ω × q are plain row slices.
_X, _V, _Q6, _Q, _W5, _W = slice(0, 3), slice(3, 6), slice(6, 12), slice(8, 12), slice(12, 17), slice(12, 15)
_ROWS = 17


def rk4_constant(state: np.ndarray, lin: np.ndarray, ang: np.ndarray, h: float, ws: Workspace) -> None:
    """``rk4`` followed by the renormalisation of ``integrate``, bit for bit, when the accelerations
    ``lin`` and ``ang`` ((1, 3) or (N, 3), from ``forces.constant_acceleration``) do not depend on the
    state.

    Every stage then has k_v = lin and k_ω = ang, so k2 and k3 share their x part (v + ½h·lin) and only
    the orientations need four derivatives, none at all for balls that neither spin nor are spun up
    (``_keeps_orientation``). Each value is still formed by the same operations in the same order as in
    ``rk4`` (trial = k·(frac·h) + s, acc = k1 + k2 + k2 + k3 + k3 + k4, s += acc·(h/6)) and
    ``quaternion.normalize`` (whose sum of squares is taken by the same call on the same rows), so the
    results are identical. The work is done on contiguous columns of RK4_CHUNK balls at a time instead
    of on strided (N, 13) views, and nothing is computed twice.
    """
    n = len(state)
    half, sixth = 0.5 * h, h / 6.0
    if len(lin) != len(ang):  # one per ball, the other shared
        lin, ang = np.broadcast_to(lin, (n, 3)), np.broadcast_to(ang, (n, 3))
    per_ball = len(lin) > 1
    # the v and ω parts of acc·(h/6): the six k's added one by one, as ``rk4`` does
    dv, dw = lin + lin, ang + ang
    for _ in range(4):
        dv += lin
        dw += ang
    dv *= sixth
    dw *= sixth
    spun_up = (ang != 0.0).any(axis=1)
    ang5 = ang[:, [0, 1, 2, 0, 1]]  # in ω's five-row layout
    lin_half, lin_h, ang_half, ang_h = lin * half, lin * h, ang5 * half, ang5 * h
    cols = ws.get("rk4 columns", (_ROWS, RK4_CHUNK))
    scratch = ws.get("rk4 scratch", (5, 3, RK4_CHUNK))  # acc_x, k2_x (then k4_x), three for _dq
    omegas = ws.get("rk4 omega", (2, 5, RK4_CHUNK))  # trial ω for stages 2–3 and for stage 4
    quats = ws.get("rk4 q", (2, 6, RK4_CHUNK))  # k and trial state for the orientation
    q_acc = ws.get("rk4 q acc", (4, RK4_CHUNK))
    for start in range(0, n, RK4_CHUNK):
        rows = state[start : start + RK4_CHUNK]
        m = len(rows)
        part = slice(start, start + m) if per_ball else slice(None)
        t = cols[:, :m]
        np.copyto(t[0:6], rows[:, 0:6].T)
        np.copyto(t[8:15], rows[:, 6:13].T)
        t[6:8] = t[9:11]
        t[15:17] = t[12:14]
        x, v, q6, q, w5, w = t[_X], t[_V], t[_Q6], t[_Q], t[_W5], t[_W]
        acc, k2, *tmp = scratch[:, :, :m]
        # x: acc = k1 + k2 + k2 + k3 + k3 + k4 with k1 = v, k2 = k3 = lin·½h + v, k4 = lin·h + v
        np.add(lin_half[part].T, v, out=k2)
        np.add(v, k2, out=acc)
        for _ in range(3):
            acc += k2
        np.add(lin_h[part].T, v, out=k2)
        acc += k2
        acc *= sixth
        x += acc
        if spun_up[part].any() or w.any() or not _keeps_orientation(q):
            # ω at the trial states: ang·½h + ω (stages 2 and 3) and ang·h + ω (stage 4)
            w_mid, w_end = omegas[:, :, :m]
            np.add(ang_half[part].T, w5, out=w_mid)
            np.add(ang_h[part].T, w5, out=w_end)
            # q: four derivatives, each at the trial state built from the one before
            k, trial = quats[:, :, :m]
            qacc = q_acc[:, :m]
            _dq(q6, w5, k, tmp)
            np.copyto(qacc, k[2:6])
            for frac_h, weight, omega in ((half, 2, w_mid), (half, 2, w_mid), (h, 1, w_end)):
                np.multiply(k, frac_h, out=trial)
                trial += q6
                _dq(trial, omega, k, tmp)
                for _ in range(weight):
                    qacc += k[2:6]
            qacc *= sixth
            q += qacc
        v += dv[part].T
        w += dw[part].T
        # back into the state, then q / |q| with |q|² summed by the very call ``normalize`` makes
        np.copyto(rows[:, 0:6], t[0:6].T)
        np.copyto(rows[:, 6:13], t[8:15].T)
        q_rows = rows[:, Q]
        q /= np.sqrt(np.einsum("...i,...i->...", q_rows, q_rows))
        np.copyto(q_rows, q.T)


_NEGATIVE_ZERO = np.array(-0.0).view(np.int64)


def _keeps_orientation(q: np.ndarray) -> bool:
    """Whether RK4 leaves the orientations ``q`` (4, m) exactly as they are, given that no ball spins
    or is spun up (ω = 0 and α = 0, either sign of zero).

    Then every product in dq/dt is a zero, so every k and the sum of them are zeros, each trial state
    is q + (±0) = q, and so is the end q + acc·(h/6): adding a zero changes no finite value, except
    that −0 + +0 is +0. So q is kept when it is finite and holds no −0 (the identity holds +0s).
    """
    return bool(np.isfinite(q).all()) and not (q.view(np.int64) == _NEGATIVE_ZERO).any()


def _dq(q6: np.ndarray, w5: np.ndarray, out: np.ndarray, tmp: list[np.ndarray]) -> None:
    """``quaternion.derivative`` in the fast path's layout: q6 = (qy qz qx qy qz qw) and w5 =
    (ωx ωy ωz ωx ωy) by columns, into ``out`` in q6's layout. Each component is formed as there:
    (qw·ω_i + ω_j·q_k) − ω_k·q_j for (i, j, k) = (x, y, z), (y, z, x), (z, x, y), and −((ωx·qx +
    ωy·qy) + ωz·qz), then halved."""
    vec, a, b = out[2:5], tmp[0], tmp[1]
    np.multiply(q6[5], w5[0:3], out=vec)  # qw·ω_i
    np.multiply(w5[1:4], q6[1:4], out=a)  # ω_j·q_k
    vec += a
    np.multiply(w5[2:5], q6[0:3], out=a)  # ω_k·q_j
    vec -= a
    np.multiply(w5[0:3], q6[2:5], out=b)  # ω_i·q_i
    s = out[5]
    np.add(b[0], b[1], out=s)
    s += b[2]
    np.negative(s, out=s)
    out[2:6] *= 0.5
    out[0:2] = out[3:5]


@dataclass(frozen=True)
class Integrator:
    """An integration method, how the program shows it, and the path it takes over one step.

    The path: under a constant acceleration a, one step of h takes a ball to x + v·h + ½·b·h², where
    b = ``bend``·a is the path's own acceleration: 0 for explicit Euler (it moves with the old velocity),
    1 for RK2 and RK4 (exact), 2 for symplectic Euler (it moves with the new velocity). The broad phase,
    the crowd test and the time of impact follow that path through the methods below, so no stage needs
    to ask which integrator it is, and a new one cannot tunnel for want of a case there.

    ``threshold_steps`` is the default restitution threshold in units of |g|·dt. Explicit Euler gains
    g·dt of speed every flight, so a ball with restitution e settles into endless bounces at an arrival
    speed of g·dt/(1 − e) unless the threshold is above it: 8·|g|·dt brings every bounce with e ≤ 0.85
    to rest. The others use 2·|g|·dt: a ball bouncing slower than that would land again within a step
    or two.
    """

    name: str  # in scene files, on the command line and in World(integrator=...)
    label: str  # in the HUD, the help, plots and tables
    colour: str  # "#rrggbb" (sRGB): its curves in plots and its ghost balls in the viewer
    key: str  # the viewer's number key that switches to it
    order: int  # global order of accuracy: the error at a fixed time shrinks as dtᵒʳᵈᵉʳ
    advance: Callable[[np.ndarray, Sequence[ForceTerm], float, Workspace], None]
    bend: float  # the path's acceleration b over the acceleration a (see above)
    threshold_steps: float
    # The same step when every force is constant (``forces.constant_acceleration``), bit for bit,
    # renormalisation included: (state, lin, ang, h, workspace).
    constant_advance: Callable[[np.ndarray, np.ndarray, np.ndarray, float, Workspace], None] | None = None

    @property
    def rgb(self) -> tuple[float, float, float]:
        """``colour`` as (r, g, b) in 0–1 (sRGB), as the viewer's shaders and overlays take it."""
        return tuple(int(self.colour[k : k + 2], 16) / 255.0 for k in (1, 3, 5))  # type: ignore[return-value]

    def path_acceleration(self, accel: np.ndarray) -> np.ndarray:
        """The acceleration this integrator's path bends with, b = bend·a: zero for a straight path."""
        if self.bend == 1.0:
            return accel
        return np.zeros_like(accel) if self.bend == 0.0 else self.bend * accel

    def path_offset(self, accel: np.ndarray, h: float) -> np.ndarray:
        """½·b·h²: how far the path's end lies from x + v·h."""
        return self.path_acceleration(accel) * (0.5 * h * h)

    def path_end(self, x: np.ndarray, v: np.ndarray, accel: np.ndarray, h: float) -> np.ndarray:
        """Where each ball would be after ``h`` along this integrator's path: x + v·h + ½·b·h²."""
        end = x + v * h
        if self.bend != 0.0:
            end += self.path_offset(accel, h)
        return end

    def position_at(self, x: np.ndarray, v: np.ndarray, accel: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Where each ball is at its own time ``t`` (a column, one per row) along the path:
        x + v·t + ½·b·t·t, in that order (the time of impact's gap function)."""
        return x + v * t + 0.5 * self.path_acceleration(accel) * t * t

    def sag(self, accel_norm: np.ndarray, h: float | np.ndarray) -> np.ndarray | float:
        """How far each path strays from the chord between its ends, given |a|: ⅛·|b|·h² for a
        parabola, 0 for a straight path."""
        if self.bend == 0.0:
            return 0.0
        return (0.125 * abs(self.bend)) * h * h * accel_norm

    def cover_sag(self, accel_norm: np.ndarray, h: float | np.ndarray) -> np.ndarray:
        """How far a ball can stray from the chord over ``h`` split into any steps: the larger of this
        path's sag and the exact parabola's, ⅛·|a|·h², which every integrator follows over many steps
        (explicit Euler's straight steps add up to a curve too). The kept pairs' boxes are grown by it."""
        return (0.125 * max(abs(self.bend), 1.0)) * h * h * accel_norm

    def closing_speed_bound(self, dv: np.ndarray, da: np.ndarray, h: float) -> np.ndarray:
        """A bound on how fast each pair can close over the next ``h``, from the relative velocity and
        acceleration along this path: |Δv| + |Δb|·h (the second term is zero on a straight path)."""
        return np.linalg.norm(dv, axis=1) + np.linalg.norm(self.path_acceleration(da), axis=1) * h


# The registry, in the order of the viewer's number keys. Colours read on the plots' white and the
# viewer's dark sky alike.
_REGISTERED = (
    Integrator(name="euler", label="Euler", colour="#e8503a", key="1", order=1, advance=euler,
               bend=0.0, threshold_steps=8.0),
    Integrator(name="rk2", label="RK2", colour="#f0a030", key="2", order=2, advance=rk2,
               bend=1.0, threshold_steps=2.0),
    Integrator(name="rk4", label="RK4", colour="#3c9ee6", key="3", order=4, advance=rk4,
               bend=1.0, threshold_steps=2.0, constant_advance=rk4_constant),
    Integrator(name="symplectic", label="Symplectic", colour="#4cb85c", key="4", order=1,
               advance=symplectic_euler, bend=2.0, threshold_steps=2.0),
)  # fmt: skip
INTEGRATORS: dict[str, Integrator] = {integrator.name: integrator for integrator in _REGISTERED}
# The names a World, a scene file and the command line accept.
INTEGRATOR_NAMES: tuple[str, ...] = tuple(INTEGRATORS)
# The default, and the reference compare measures the others against: the most accurate.
DEFAULT_INTEGRATOR = "rk4"


def integrate(
    method: Integrator, state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace
) -> None:
    """Advance ``state`` (N, 13) in place by ``h`` seconds and renormalise the orientations."""
    if state.shape[0] == 0 or h <= 0.0:
        return
    if method.constant_advance is not None and (accel := constant_acceleration(forces)) is not None:
        method.constant_advance(state, *accel, h, ws)  # renormalises too
        return
    method.advance(state, forces, h, ws)
    q = state[:, Q]
    quaternion.normalize(q, out=q)
