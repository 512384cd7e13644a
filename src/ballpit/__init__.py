"""ballpit: a desktop physics sandbox of balls, slopes, spin and impacts."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .physics import Contacts, Plane, Sphere, World

__version__ = "0.1.0"
__all__ = ["Contacts", "Plane", "Sphere", "World", "__version__", "load_scene"]

if TYPE_CHECKING:
    from .scene import load_scene


def __getattr__(name: str):
    # The scene loader is imported on first use so `import ballpit` stays light.
    if name == "load_scene":
        from .scene import load_scene

        return load_scene
    raise AttributeError(f"module 'ballpit' has no attribute {name!r}")
