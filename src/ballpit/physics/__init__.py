"""The pure-NumPy physics engine: no window, no OpenGL."""

from .bodies import Plane, Sphere
from .contacts import Contacts
from .integrators import INTEGRATOR_NAMES
from .settings import DEFAULT_TIMESTEP
from .world import World

__all__ = ["DEFAULT_TIMESTEP", "INTEGRATOR_NAMES", "Contacts", "Plane", "Sphere", "World"]
