"""Mechanical energy of the balls: the one place it is computed (the summary, the HUD and the tests
all read it from here, through ``World.kinetic_energy`` and ``World.potential_energy``)."""

from __future__ import annotations

import numpy as np

from .core import exact
from .core.state import State, V, W, X
from .dynamics.model import Model


def kinetic(model: Model, state: State) -> float:
    """Translational plus rotational kinetic energy, Σ ½·m·v² + ½·I·ω² (J)."""
    sph, body = model.spheres, state.body
    v, w = body[:, V], body[:, W]
    return 0.5 * exact.total(sph.mass * np.einsum("ij,ij->i", v, v)) + 0.5 * exact.total(
        (1.0 / sph.inv_inertia) * np.einsum("ij,ij->i", w, w)
    )


def potential(model: Model, state: State) -> float:
    """Gravitational potential energy −Σ m·g·x (J), zero at the origin."""
    return -exact.total(model.spheres.mass * exact.dot_rows(state.body[:, X], model.gravity))
