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
    x0 + v0·h + ½·a·h² exactly (RK2, RK4); explicit Euler moves along x0 + v0·h instead. Time of
    impact is predicted along the same path the integrator will take.
    """

    name: str
    advance: Callable[[np.ndarray, Sequence[ForceTerm], float, Workspace], None]
    quadratic_path: bool


INTEGRATORS: dict[str, Integrator] = {
    "euler": Integrator("euler", euler, quadratic_path=False),
    "rk2": Integrator("rk2", rk2, quadratic_path=True),
    "rk4": Integrator("rk4", rk4, quadratic_path=True),
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
