"""Named force terms. Each adds its linear and angular acceleration for a trial state.

The integrators call every term at every stage, so velocity-dependent forces such as drag are
evaluated where a multi-stage method needs them, not frozen at the start of the step. Terms that do not
depend on the state at all also have ``constant``, so an integrator can add them up once per step
(``constant_acceleration``) instead of once per stage.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from ..core.state import Q, V, W, X


class ForceTerm(Protocol):
    """Something that accelerates balls: adds into ``lin`` (N, 3) and ``ang`` (N, 3)."""

    def add(self, state: np.ndarray, lin: np.ndarray, ang: np.ndarray) -> None: ...


class Gravity:
    """Uniform gravitational acceleration g."""

    def __init__(self, g: np.ndarray) -> None:
        self.g = g

    def add(self, state: np.ndarray, lin: np.ndarray, ang: np.ndarray) -> None:
        lin += self.g

    def constant(self, lin: np.ndarray, ang: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``add`` for any state, on arrays of any broadcastable shape (returns the sums)."""
        return lin + self.g, ang


class LinearDrag:
    """Linear drag: a = −c·v (c in 1/s)."""

    def __init__(self, c: float) -> None:
        self.c = c

    def add(self, state: np.ndarray, lin: np.ndarray, ang: np.ndarray) -> None:
        lin -= self.c * state[:, V]


class AngularDrag:
    """Angular drag: α = −c_ω·ω (c_ω in 1/s)."""

    def __init__(self, c: float) -> None:
        self.c = c

    def add(self, state: np.ndarray, lin: np.ndarray, ang: np.ndarray) -> None:
        ang -= self.c * state[:, W]


class ConstantPerBall:
    """Per-ball accelerations held constant over an interval: the contact solver's forces."""

    def __init__(self, lin: np.ndarray, ang: np.ndarray) -> None:
        self.lin = lin
        self.ang = ang

    def add(self, state: np.ndarray, lin: np.ndarray, ang: np.ndarray) -> None:
        lin += self.lin
        ang += self.ang

    def constant(self, lin: np.ndarray, ang: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``add`` for any state, on arrays of any broadcastable shape (returns the sums)."""
        return lin + self.lin, ang + self.ang


def forces_of(forces: list[ForceTerm], idx: np.ndarray, n_balls: int) -> list[ForceTerm]:
    """The force terms for the balls ``idx`` alone: per-ball constant terms (a sleeping ball's hold)
    cut down to their rows."""
    terms: list[ForceTerm] = []
    for term in forces:
        if isinstance(term, ConstantPerBall) and len(term.lin) == n_balls:
            term = ConstantPerBall(term.lin[idx], term.ang[idx])
        terms.append(term)
    return terms


def free_acceleration(body: np.ndarray, forces: list[ForceTerm]) -> tuple[np.ndarray, np.ndarray]:
    """Linear and angular acceleration of each ball from the force terms alone, at state ``body``."""
    constant = constant_acceleration(forces)
    if constant is not None:  # the same sums, made once (or once per ball) and repeated
        return tuple(a.repeat(len(body), axis=0) if len(a) == 1 else a for a in constant)
    lin = np.zeros((len(body), 3))
    ang = np.zeros((len(body), 3))
    for term in forces:
        term.add(body, lin, ang)
    return lin, ang


def constant_acceleration(forces: Sequence[ForceTerm]) -> tuple[np.ndarray, np.ndarray] | None:
    """The linear and angular acceleration the terms add up to when none depends on the state (else
    None): (1, 3) rows, or (N, 3) once a per-ball term joins.

    The sums are the ones ``add`` makes at every stage, in the same order from the same zero, so the
    values are bit for bit those a stage would see; only the broadcasting differs.
    """
    lin, ang = np.zeros((1, 3)), np.zeros((1, 3))
    for term in forces:
        constant = getattr(term, "constant", None)
        if constant is None:  # depends on the state (drag) or is not one of ours
            return None
        lin, ang = constant(lin, ang)
    return lin, ang


def column_accelerations(
    terms: Sequence[ForceTerm],
    constant: tuple[np.ndarray, np.ndarray] | None,
    x: np.ndarray,
    vw: np.ndarray,
    q: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Linear and angular accelerations (3, M) of M balls laid out as columns (positions ``x`` (3, M),
    velocities and spins ``vw`` (6, M), orientations ``q`` (M, 4)) under the force terms, at this state;
    ``constant`` is ``constant_acceleration(terms)``, made once."""
    if constant is not None:
        lin, ang = constant
        return lin.T, ang.T
    state = np.empty((x.shape[1], 13))
    state[:, X], state[:, V], state[:, Q], state[:, W] = x.T, vw[:3].T, q, vw[3:].T
    lin, ang = np.zeros((len(state), 3)), np.zeros((len(state), 3))
    for term in terms:
        term.add(state, lin, ang)
    return lin.T, ang.T
