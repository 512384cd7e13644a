"""The pure-NumPy physics engine: no window, no OpenGL."""

from .bodies import Plane, Sphere
from .contacts import Contacts
from .world import World

__all__ = ["Contacts", "Plane", "Sphere", "World"]
