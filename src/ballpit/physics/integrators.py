"""Explicit integrators over the full rigid state (x, v, q, ω) of every ball at once.

The state derivative is (v, a, ½·(ω,0)⊗q, α), where a and α come from the force terms evaluated at
each stage. Spheres are isotropic, so there is no gyroscopic term: α is the torque times a scalar I⁻¹.
Orientations are renormalised after every step; nothing is clamped.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from . import quaternion
from .forces import ForceTerm
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
    """An integration method and the shape of the path it takes over one step.

    ``quadratic_path`` is True when, under constant acceleration, the step reproduces
    x0 + v0·h + ½·a·h² exactly (RK2, RK4); explicit Euler moves along x0 + v0·h instead. The broad
    phase, the crowd test and the time of impact all follow that same path, through the methods below,
    so no stage needs to ask which integrator it is.

    ``threshold_steps`` is the default restitution threshold in units of |g|·dt. Explicit Euler gains
    g·dt of speed every flight, so a ball with restitution e settles into endless bounces at an arrival
    speed of g·dt/(1 − e) unless the threshold is above it: 8·|g|·dt brings every bounce with e ≤ 0.85
    to rest. The others use 2·|g|·dt: a ball bouncing slower than that would land again within a step
    or two.
    """

    name: str
    advance: Callable[[np.ndarray, Sequence[ForceTerm], float, Workspace], None]
    quadratic_path: bool
    threshold_steps: float

    def path_end(self, x: np.ndarray, v: np.ndarray, accel: np.ndarray, h: float) -> np.ndarray:
        """Where each ball would be after ``h`` along this integrator's path."""
        end = x + v * h
        if self.quadratic_path:
            end += 0.5 * h * h * accel
        return end

    def path_acceleration(self, accel: np.ndarray) -> np.ndarray:
        """The acceleration this integrator's path bends with: ``accel``, or zero for a straight path."""
        return accel if self.quadratic_path else np.zeros_like(accel)

    def sag(self, accel: np.ndarray, h: float) -> np.ndarray | float:
        """How far each path strays from the chord between its ends: ⅛·|a|·h² for a parabola."""
        return 0.125 * h * h * np.linalg.norm(accel, axis=1) if self.quadratic_path else 0.0

    def closing_speed_bound(self, dv: np.ndarray, da: np.ndarray, h: float) -> np.ndarray:
        """A bound on how fast each pair can close over the next ``h``, from the relative velocity and
        acceleration along this path: |Δv| + |Δa|·h (the acceleration term is zero on a straight path)."""
        return np.linalg.norm(dv, axis=1) + np.linalg.norm(self.path_acceleration(da), axis=1) * h


INTEGRATORS: dict[str, Integrator] = {
    "euler": Integrator("euler", euler, quadratic_path=False, threshold_steps=8.0),
    "rk2": Integrator("rk2", rk2, quadratic_path=True, threshold_steps=2.0),
    "rk4": Integrator("rk4", rk4, quadratic_path=True, threshold_steps=2.0),
}
# The names a World, a scene file and the command line accept, in order of accuracy.
INTEGRATOR_NAMES: tuple[str, ...] = tuple(INTEGRATORS)


def integrate(
    method: Integrator, state: np.ndarray, forces: Sequence[ForceTerm], h: float, ws: Workspace
) -> None:
    """Advance ``state`` (N, 13) in place by ``h`` seconds and renormalise the orientations."""
    if state.shape[0] == 0 or h <= 0.0:
        return
    method.advance(state, forces, h, ws)
    q = state[:, Q]
    quaternion.normalize(q, out=q)
