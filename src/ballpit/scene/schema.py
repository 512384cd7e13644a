"""The scene file's schema: which tables it has, the keys of each, and their defaults.

Defaults for what the physics builds (world parameters, ball and plane properties) are read from the
signatures of ``World.__init__``, ``World.add_sphere`` and ``World.add_plane``, so a scene file and a
World built in code cannot disagree about them. The timestep and integrator names come from the physics
package too.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable

from ..physics import DEFAULT_TIMESTEP, INTEGRATOR_NAMES, World
from ..physics.core import validation
from ..physics.core.settings import OVERLAP_TOLERANCE as OVERLAP_TOLERANCE


def _defaults(function: Callable, names: tuple[str, ...]) -> dict[str, object]:
    """The default of each named parameter of ``function`` (a KeyError if the physics renamed one)."""
    parameters = inspect.signature(function).parameters
    return {name: parameters[name].default for name in names}


# What the [world] table passes to World(...), and its defaults there.
WORLD_DEFAULTS = _defaults(
    World.__init__,
    ("gravity", "integrator", "linear_drag", "angular_drag", "restitution_threshold", "sleep", "substeps"),
)
TIMESTEP_DEFAULT = DEFAULT_TIMESTEP  # s per physics step, when [world] gives no timestep
INTEGRATORS = INTEGRATOR_NAMES
# What [[plane]] passes to World.add_plane.
PLANE_DEFAULTS = _defaults(
    World.add_plane,
    (
        "position",
        "rotation",
        "normal",
        "size",
        "restitution",
        "friction",
        "rolling_friction",
        "velocity",
        "angular_velocity",
    ),
)
# What every ball ([[sphere]] or a [[grid]]'s balls) passes to World.add_sphere besides its position.
BALL_DEFAULTS = _defaults(
    World.add_sphere,
    (
        "radius",
        "mass",
        "velocity",
        "angular_velocity",
        "orientation",
        "restitution",
        "friction",
        "rolling_friction",
        "hollow",
    ),
)
BALL_COLUMNS = tuple(BALL_DEFAULTS)  # the ball keys that become World columns

# [[grid]]: a block of nx × ny × nz balls.
GRID_SPACING = 2.2  # default spacing between ball centres, in radii
GRID_JITTER = 0.0  # m, the largest random offset of each ball along each axis
GRID_VELOCITY_JITTER = 0.0  # m/s, the same for each ball's velocity
GRID_SEED = 0
MAX_BALLS = 1_000_000  # in the whole scene, spheres and grids together
# Planes are a scene's walls and slopes. The broad phase tests every ball's box against each plane in
# turn (broadphase.sphere_plane_pairs), some 20 µs a plane, so 100,000 planes cost seconds a step, far
# past any use; a file of more is a mistake or an attack (a 16 MiB file can hold 1.6 million).
MAX_PLANES = 100_000
SUBSTEPS_RANGE = (1, validation.MAX_SUBSTEPS)  # [world] substeps, as World.substeps takes them
RESTITUTION_RANGE = validation.RESTITUTION_RANGE  # a ball's or a plane's, as World takes them

# Balls or a ball and a plane may touch at the start (a cradle, a ball resting on the floor), but not
# interpenetrate by more than OVERLAP_TOLERANCE (1e-6 m, defined with the physics' other tolerances in
# physics/settings.py), unless [world] overlap_tolerance says otherwise: a scene saved from a running
# world (Ctrl+S) sets it, since balls at rest press a little into each other and into the floor (about
# 4e-5 m between the 10 cm balls of pile.toml after 3 s).

WORLD_KEYS = (
    "gravity",
    "integrator",
    "timestep",
    "linear_drag",
    "angular_drag",
    "restitution_threshold",
    "sleep",
    "substeps",
    "duration",
    "overlap_tolerance",
)
CAMERA_KEYS = ("position", "look_at")
PLANE_KEYS = (*PLANE_DEFAULTS, "color")
BALL_KEYS = (*BALL_COLUMNS, "color")
SPHERE_KEYS = ("position", *BALL_KEYS)
GRID_KEYS = ("corner", "center", "count", "spacing", "jitter", "velocity_jitter", "seed", *BALL_KEYS)
# Every top-level name: "table" is written [name] once, "array" is written [[name]] any number of times.
TABLES = {"world": "table", "camera": "table", "plane": "array", "sphere": "array", "grid": "array"}
KEYS = {
    "world": WORLD_KEYS,
    "camera": CAMERA_KEYS,
    "plane": PLANE_KEYS,
    "sphere": SPHERE_KEYS,
    "grid": GRID_KEYS,
}


def header(name: str) -> str:
    """How table ``name`` is written: ``[world]`` or ``[[sphere]]``."""
    return f"[{name}]" if TABLES[name] == "table" else f"[[{name}]]"
