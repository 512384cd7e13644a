"""What the panel's widgets ask of the World, as commands, and what came back.

Every edit is a command the physics thread runs between steps (stepper.py ``submit``), through
``Simulation.edit``: the history keeps the edited state, the ghosts get the same edit, ``--record``
records the run as edited. An edit the World refuses (a negative radius, NaN, a ball added inside
another) changes nothing: its one-line error is kept under the widget's key until an edit of that
widget succeeds, and the widget shows the last good value again (the World's own, handed over). No GL
and no ImGui here, so what each widget commands is tested without a window.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from operator import methodcaller
from pathlib import Path
from typing import Any

import numpy as np

from .picking import Ray
from .simulation import Simulation

Submit = Callable[..., None]  # PhysicsThread.submit(command, then)

BALL_NUMBERS = ("radius", "mass", "restitution", "friction", "rolling_friction")
BALL_VECTORS = ("velocity", "angular_velocity")
PLANE_NUMBERS = ("restitution", "friction", "rolling_friction")
PLANE_VECTORS = ("position", "rotation", "velocity", "angular_velocity")
# World settings the panel edits, and whether each applies at once or on reset (R).
AT_ONCE = ("gravity", "substeps", "sleep", "restitution_threshold", "integrator", "time_scale")
ON_RESET = ("timestep",)
NEW_BALL_GAP = 1e-3  # m between a ball added by pointing and the surface pointed at


def one_line(exc: BaseException) -> str:
    """An error as the one line shown beside its widget."""
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]


def refusals(command: Callable[[Simulation], Any]) -> Callable[[Simulation], Any]:
    """``command`` returning (not raising) the ValueError/TypeError the World refuses an edit with, so
    the physics thread does not report it as its own failure: the panel shows it beside the widget."""

    def guarded(sim: Simulation) -> Any:
        try:
            return command(sim)
        except (ValueError, TypeError, IndexError) as exc:
            return exc

    return guarded


# ---------------------------------------------------------------------- the edits (physics side)
# Each change handed to ``Simulation.edit`` is a ``methodcaller`` or a ``partial`` of a module-level
# function, not a closure: the ghosts' process gets it pickled (ghostproc.py).
def set_part(part: str, index: int, name: str, value: object, world: Any) -> None:
    """``world.<part>[index].<name> = value`` (part: "spheres" or "planes")."""
    setattr(getattr(world, part)[index], name, value)


def set_ball(sim: Simulation, index: int, name: str, value: object) -> None:
    """Ball ``index``'s ``name`` (one of BALL_NUMBERS or BALL_VECTORS) becomes ``value``."""
    if name in ("radius", "mass"):
        sim.edit(methodcaller("set_sphere_size", index, **{name: value}))
    elif name in BALL_NUMBERS or name in BALL_VECTORS:
        sim.edit(partial(set_part, "spheres", index, name, value))
    else:
        raise ValueError(f"a ball has no editable {name!r}")


def set_plane(sim: Simulation, index: int, name: str, value: object) -> None:
    """Plane ``index``'s ``name`` (PLANE_NUMBERS or PLANE_VECTORS; rotation in degrees, extrinsic x y z)
    becomes ``value``."""
    if name in ("position", "rotation"):
        sim.edit(methodcaller("move_plane", index, **{name: value}))
    elif name in PLANE_NUMBERS or name in ("velocity", "angular_velocity"):
        sim.edit(partial(set_part, "planes", index, name, value))
    else:
        raise ValueError(f"a plane has no editable {name!r}")


def set_world(sim: Simulation, name: str, value: object) -> None:
    """A world setting: gravity, substeps, sleep, the restitution threshold (None: automatic) and the
    integrator apply at once and stay through a reset (the scene's initial world gets them too); the
    time scale applies at once; the timestep applies from a reset, which it does at once."""
    if name == "time_scale":
        from .controls import TIME_SCALE_RANGE

        low, high = TIME_SCALE_RANGE
        scale = float(value)  # type: ignore[arg-type]
        if not low <= scale <= high:
            raise ValueError(f"time scale must be from {low:g} to {high:g}, got {value!r}")
        sim.time_scale = scale
        return
    if name == "timestep":
        from ballpit.physics.core import validation

        timestep = validation.number("timestep", value, positive=True, within=(1e-5, 0.1))
        sim.scene = dataclasses.replace(sim.scene, timestep=timestep)
        sim.reset()
        sim.message = f"timestep {sim.scene.timestep * 1000:g} ms: reset, X drops"
        return
    if name not in AT_ONCE:
        raise ValueError(f"the world has no editable {name!r}")
    setattr(sim.initial, name, value)  # validated here first: a refused value changes neither
    if name == "integrator":  # as the I key: the ghosts stay the other integrators, not this one
        sim.set_integrator(str(value))
        return
    sim.edit(methodcaller("__setattr__", name, value))


def add_ball_at(sim: Simulation, ray: Ray) -> int:
    """A ball like the scene's typical one (size, mass, material), on the plane the pointer's ``ray``
    meets first, on the viewer's side; refused when the ray meets no plane first or the ball would
    overlap a ball or a plane."""
    from ballpit.scene.colours import palette_colors

    from .interaction import typical_material
    from .picking import ray_planes

    planes = sim.world.planes
    u, v = (np.array([p.axes[k] for p in planes]).reshape(-1, 3) for k in (0, 1))
    index, distance = ray_planes(ray, planes.centers, planes.normals, u, v, planes.half_sizes)
    if index < 0:
        raise ValueError("point at a plane to add a ball on it")
    spheres = sim.world.spheres
    radius = float(np.median(spheres.radii)) if len(spheres) else 0.25
    mass = float(np.median(spheres.masses)) if len(spheres) else 1.0
    n = np.array(planes[index].normal, dtype=float)
    if float((n * ray.direction).sum()) > 0.0:  # the side facing the viewer
        n = -n
    color = palette_colors(1, first=len(spheres))[0]
    position = ray.at(distance) + n * (radius + NEW_BALL_GAP)
    cut = sim.world.first_overlap(position, radius)
    if cut is not None:
        where = ", ".join(f"{c:.2f}" for c in position)
        raise ValueError(f"position: a ball of radius {radius:g} at ({where}) would overlap {cut}")
    return sim.add_ball(color, position=position, radius=radius, mass=mass, **typical_material(spheres))


# ---------------------------------------------------------------------- the window's side
@dataclass
class Edits:
    """Sends the panel's edits to the physics side and keeps each refused one's error by widget key
    ("ball.radius", "plane.rotation", "world.gravity", "scene", ...)."""

    submit: Submit
    errors: dict[str, str] = field(default_factory=dict)
    sent: int = 0

    def _send(
        self, key: str, command: Callable[[Simulation], Any], then: Callable[[Any], None] | None = None
    ):
        self.sent += 1

        def answer(result: Any) -> None:
            if isinstance(result, Exception):
                self.errors[key] = one_line(result)
            else:
                self.errors.pop(key, None)
                if then is not None:
                    then(result)

        self.submit(refusals(command), answer)

    def ball(self, index: int, name: str, value: object) -> None:
        self._send(f"ball.{name}", lambda sim: set_ball(sim, index, name, value))

    def plane(self, index: int, name: str, value: object) -> None:
        self._send(f"plane.{name}", lambda sim: set_plane(sim, index, name, value))

    def world(self, name: str, value: object) -> None:
        self._send(f"world.{name}", lambda sim: set_world(sim, name, value))

    def remove_ball(self, index: int, then: Callable[[Any], None] | None = None) -> None:
        self._send("ball.remove", lambda sim: sim.remove_ball(index), then)

    def add_ball(self, ray: Ray, then: Callable[[Any], None] | None = None) -> None:
        self._send("add", lambda sim: add_ball_at(sim, ray), then)

    def open_scene(self, path: Path, then: Callable[[Any], None] | None = None) -> None:
        """Open a scene file; a file that is not a valid scene keeps the current one (its error is
        under "scene")."""

        def command(sim: Simulation) -> Any:
            if not sim.open(path):
                error, sim.error = sim.error, None  # shown in the panel, not as the scene's own error
                return ValueError(error)
            return path

        self._send("scene", command, then)

    def error(self, key: str) -> str | None:
        return self.errors.get(key)
