"""The pure-NumPy physics engine: no window, no OpenGL."""

from .bodies import Plane, Sphere
from .core.contacts import Contacts
from .core.settings import DEFAULT_TIMESTEP
from .dynamics.integrators import INTEGRATOR_NAMES
from .world import World

__all__ = ["DEFAULT_TIMESTEP", "INTEGRATOR_NAMES", "Contacts", "Plane", "Sphere", "World"]
