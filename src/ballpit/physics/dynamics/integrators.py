"""Explicit integrators over the full rigid state (x, v, q, ω) of every ball at once.

The state derivative is (v, a, ½·(ω,0)⊗q, α), where a and α come from the force terms evaluated at
each stage. Spheres are isotropic, so there is no gyroscopic term: α is the torque times a scalar I⁻¹.
Orientations are renormalised after every step; nothing is clamped.

When no force term depends on the state (gravity and the contact solver's constant forces, the common
case), RK4 takes a fast path, ``rk4_fast.rk4_constant``, with the very same arithmetic: see there.

``INTEGRATORS`` at the end is the registry: each method's name, label, colour, viewer key, order and
path are declared there once, and the command line, scene files, compare, plots, the viewer's keys and
ghosts, the broad phase and the time of impact all read them from it. A new integrator is one
function here plus one entry there.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..core import exact, quaternion
from ..core.state import Q, V, W, X
from ..core.workspace import Workspace
from .forces import ForceTerm, constant_acceleration
from .rk4_fast import rk4_constant


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
        return exact.norm_rows(dv) + exact.norm_rows(self.path_acceleration(da)) * h


# The registry, in the order of the viewer's number keys. Colours read on the plots' white and the
# viewer's dark sky alike.
_REGISTERED = (
    Integrator(
        name="euler",
        label="Euler",
        colour="#e8503a",
        key="1",
        order=1,
        advance=euler,
        bend=0.0,
        threshold_steps=8.0,
    ),
    Integrator(
        name="rk2",
        label="RK2",
        colour="#f0a030",
        key="2",
        order=2,
        advance=rk2,
        bend=1.0,
        threshold_steps=2.0,
    ),
    Integrator(
        name="rk4",
        label="RK4",
        colour="#3c9ee6",
        key="3",
        order=4,
        advance=rk4,
        bend=1.0,
        threshold_steps=2.0,
        constant_advance=rk4_constant,
    ),
    Integrator(
        name="symplectic",
        label="Symplectic",
        colour="#4cb85c",
        key="4",
        order=1,
        advance=symplectic_euler,
        bend=2.0,
        threshold_steps=2.0,
    ),
)
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
