"""ballpit: a desktop physics sandbox of balls, slopes, spin and impacts."""

from __future__ import annotations

__version__ = "0.1.0"
__all__ = ["Contacts", "Plane", "Sphere", "World", "__version__", "load_scene"]

# Nothing is imported here, not even typing: `ballpit` (the command line's entry point, which routes
# Ctrl+C and SIGTERM first thing) must start before anything that takes time to load.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from .physics import Contacts, Plane, Sphere, World
    from .scene import load_scene

# Imported on first use, so `import ballpit` loads neither NumPy nor the physics.
_LAZY = {"Contacts": "physics", "Plane": "physics", "Sphere": "physics", "World": "physics",
         "load_scene": "scene"}  # fmt: skip


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ballpit' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
