"""Reaching into the running world: pick up and throw balls, shoot balls, select and move planes.

No GL and no pyglet here: the window passes in pointer rays, held key names and frame times, so this is
testable on its own, and the Simulation's step hooks keep a held ball where the pointer is.

- A held ball is pulled towards the pointer's point in the plane facing the camera through its centre
  by a soft spring, a mouse joint (MuJoCo's perturbation, Box2D's ``b2MouseJoint``): before every
  physics step its velocity is changed as Box2D v3's soft constraint would (``spring_velocity``). The
  step then moves it like any ball, so it keeps colliding, with continuous collision against planes and
  balls: it never passes through either. Letting go leaves it with the velocity it has, so a quick drag
  throws it. While time stands still (paused, before X) it is moved along the drag's path only as far
  as that path is clear of balls and planes, and letting go gives it the drag's velocity, measured
  over the last ``THROW_WINDOW`` seconds of frames.
- A selected plane turns at ``TILT_RATE`` about a horizontal axis while an arrow key is held (← / →
  about the view's horizontal forward axis, ↑ / ↓ about its right axis) and moves at ``LIFT_SPEED`` up or
  down while PgUp / PgDn is held; letting go gives it back the motion it had when selected.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

import numpy as np

from ballpit.scene.colours import palette_colors

from . import overlays
from .camera import WORLD_UP, Camera
from .picking import Ray, camera_basis, pick, pointer_ray, ray_plane_point
from .simulation import Phase, Simulation

THROW_WINDOW = 0.1  # s of pointer motion the throw velocity is measured over
# The mouse joint: a spring of this frequency and damping ratio (stiffness k = m·ω², damping c = 2·m·ζ·ω
# with ω = 2π·f, so the pull is the same for a light ball as for a heavy one), its acceleration capped
SPRING_HERTZ = 5.0
SPRING_DAMPING = 0.7
SPRING_MAX_ACCELERATION = 400.0  # m/s², about 40 g
TILT_RATE = 0.4  # rad/s while an arrow key is held (about 23°/s)
LIFT_SPEED = 1.0  # m/s while PgUp / PgDn is held
SHOT_SPEEDS = (5.0, 10.0, 20.0, 40.0)  # m/s; Shift+B steps through them
DEFAULT_SHOT_SPEED = 10.0
SHOT_RADIUS, SHOT_MASS = 0.25, 1.0  # a shot ball when the scene has no balls to copy
THROW_COLOR = (1.0, 0.72, 0.05, 1.0)
# Held keys that move a selected plane: tilt keys as (camera axis, sign), lift keys as a sign.
TILT_KEYS: dict[str, tuple[str, float]] = {
    "UP": ("right", -1.0),  # the far edge goes down
    "DOWN": ("right", 1.0),
    "LEFT": ("forward", -1.0),  # the left edge goes down
    "RIGHT": ("forward", 1.0),
}
LIFT_KEYS: dict[str, float] = {"PAGEUP": 1.0, "PAGEDOWN": -1.0}
# A replay writes recorded frames into the world: a ball added or moved there has no frames to follow.
NOT_IN_REPLAY = "{} is not available in a replay: it plays a recorded run"
PLANE_KEYS = frozenset(TILT_KEYS) | frozenset(LIFT_KEYS)


def typical_material(spheres: object) -> dict[str, float]:
    """The most common (restitution, friction, rolling friction) among ``spheres`` (the first of the
    most common on a tie), as ``add_sphere`` arguments; {} when there are no balls (the defaults).

    A shot ball made of it rolls to a stop where the scene's own balls do, rather than rolling on for
    ever without the rolling friction they have."""
    names = ("restitution", "friction", "rolling_friction")
    if not len(spheres):  # type: ignore[arg-type]
        return {}
    rows = np.array([[getattr(ball, name) for name in names] for ball in spheres])  # type: ignore[attr-defined]
    kinds, first, counts = np.unique(rows, axis=0, return_index=True, return_counts=True)
    best = np.lexsort((first, -counts))[0]  # the most common, then the earliest
    return dict(zip(names, (float(v) for v in kinds[best]), strict=True))


def spring_velocity(
    position: np.ndarray,
    velocity: np.ndarray,
    target: np.ndarray,
    target_velocity: np.ndarray,
    h: float,
    hertz: float = SPRING_HERTZ,
    damping: float = SPRING_DAMPING,
    max_acceleration: float = SPRING_MAX_ACCELERATION,
) -> np.ndarray:
    """The velocity a ball has after one step ``h`` of a soft mouse joint pulling it to ``target``
    (Box2D v3, ``b2MakeSoft``: ω = 2πf, bias rate ω/(2ζ + hω), mass scale hω(2ζ + hω)/(1 + hω(2ζ + hω))).
    The ball's mass cancels: stiffness and damping are scaled by it. The change is at most
    ``max_acceleration``·h."""
    omega = 2.0 * np.pi * hertz
    a1 = 2.0 * damping + h * omega
    a2 = h * omega * a1
    bias_rate, mass_scale = omega / a1, a2 / (1.0 + a2)
    c = np.asarray(position, float) - np.asarray(target, float)
    cdot = np.asarray(velocity, float) - np.asarray(target_velocity, float)
    change = -mass_scale * (cdot + bias_rate * c)
    size = float(np.sqrt((change * change).sum()))
    limit = max_acceleration * h
    if size > limit:
        change *= limit / size
    return np.asarray(velocity, float) + change


def clear_path(world: object, index: int, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """How far along the segment from ``start`` to ``end`` ball ``index`` can be moved without touching
    another ball or a plane: the last clear point of samples half a radius apart (a ball's centre
    cannot cross a plane, or meet a ball, between two clear samples that close)."""
    spheres = world.spheres  # type: ignore[attr-defined]
    r = float(spheres.radii[index])
    start, end = np.asarray(start, float), np.asarray(end, float)
    d = end - start
    n = max(1, int(np.ceil(np.sqrt((d * d).sum()) / (0.5 * r))))
    samples = start + d * (np.arange(1, n + 1) / n)[:, None]
    others = np.delete(np.arange(len(spheres)), index)
    blocked = np.zeros(n, dtype=bool)
    if others.size:
        gap = samples[:, None, :] - np.asarray(spheres.positions)[others][None, :, :]
        reach = np.asarray(spheres.radii)[others] + r
        blocked |= ((gap * gap).sum(axis=-1) < reach * reach).any(axis=1)
    for plane in world.planes:  # type: ignore[attr-defined]
        blocked |= np.asarray(plane.distance(samples)) < r
    first = int(np.argmax(blocked)) if blocked.any() else n
    return samples[first - 1] if first > 0 else start


class Interaction:
    """What the user's hands are doing to one Simulation: a held ball, a selected plane, the shot speed."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self.shot_speed = DEFAULT_SHOT_SPEED
        self.clock = 0.0  # seconds of frames so far; throw velocities are measured on it
        self.held_ball: int | None = None
        self.selected_ball: int | None = None  # the inspector's ball (the last one clicked)
        self.selected_plane: int | None = None
        self.pointer = (0.0, 0.0)
        self.target = np.zeros(3)  # where the held ball's centre goes
        self._offset = np.zeros(3)  # ball centre minus the point under the pointer
        self._samples: deque[tuple[float, np.ndarray]] = deque()
        self._base_motion = (np.zeros(3), np.zeros(3))  # the selected plane's own (velocity, spin)
        sim.before_step.append(self._pull)
        sim.after_reset.append(self.clear)

    # ------------------------------------------------------------------ pointer
    def press(self, ray: Ray, x: float, y: float, facing: np.ndarray) -> str:
        """Left button down at window point (x, y): pick up a ball (to move in the plane through it
        with normal ``facing``, the view direction), select a plane, or (on nothing) deselect. Returns
        what happened, for the HUD."""
        hit = pick(ray, self.sim.world)
        if hit is None:
            self.deselect()
            self.selected_ball = None
            return ""
        if hit.kind == "plane":
            self.select(hit.index)
            self.selected_ball = None
            # numbered as world.planes and the events' b (plane index) count them: from 0
            return f"plane {hit.index} selected: arrows tilt it, PgUp/PgDn raise and lower it"
        self.deselect()
        self.selected_ball = hit.index
        if self.in_replay:
            return NOT_IN_REPLAY.format("dragging a ball")
        ball = self.sim.world.spheres[hit.index]
        centre = np.array(ball.position, dtype=float)
        grabbed = ray_plane_point(ray, centre, np.asarray(facing, dtype=float))
        self.held_ball = hit.index
        self.pointer = (float(x), float(y))
        self._offset = centre - (grabbed if grabbed is not None else centre)
        self.target = centre
        self._samples.clear()
        self._samples.append((self.clock, centre.copy()))
        return ""

    def move(self, x: float, y: float) -> None:
        """The pointer moved (with the left button down)."""
        self.pointer = (float(x), float(y))

    def release(self) -> np.ndarray | None:
        """Left button up: let go of a held ball (returns its velocity then). While time runs it keeps
        the velocity the spring gave it; while time stands still it gets the drag's."""
        if self.held_ball is None:
            return None
        ball = self.sim.world.spheres[self.held_ball]
        if self.sim.phase is not Phase.RUNNING:
            index = self.held_ball
            self.sim.edit(
                lambda world: setattr(world.spheres[index], "velocity", self.throw_velocity()), False
            )
        velocity = np.array(ball.velocity, dtype=float)
        self.held_ball = None
        self._samples.clear()
        return velocity

    def throw_velocity(self) -> np.ndarray:
        """The held ball's velocity: its motion over the last ``THROW_WINDOW`` seconds of frames."""
        samples = list(self._samples)  # one copy: the window reads it while the physics side appends
        if len(samples) < 2:
            return np.zeros(3)
        (t0, p0), (t1, p1) = samples[0], samples[-1]
        return (p1 - p0) / (t1 - t0) if t1 > t0 else np.zeros(3)

    # ------------------------------------------------------------------ per frame
    def update(self, camera: Camera, size: tuple[int, int], held_keys: Iterable[str], seconds: float) -> None:
        """Once per frame, before physics: move the held ball's target to the pointer and drive the
        selected plane from the held keys."""
        self.clock += max(float(seconds), 0.0)
        if self.held_ball is not None:
            self._follow_pointer(camera, size)
        if self.selected_plane is not None:
            self._drive_plane(camera, set(held_keys))

    def _follow_pointer(self, camera: Camera, size: tuple[int, int]) -> None:
        ray = pointer_ray(camera, *self.pointer, *size)
        normal = camera.forward
        offset = self._offset - np.dot(self._offset, normal) * normal
        hit = ray_plane_point(ray, self.target, normal)
        if hit is None or np.dot(hit - ray.origin, ray.direction) <= 0.0:
            return  # the pointer is above the horizon of the drag plane: leave the ball where it is
        self.target = hit + offset
        self._samples.append((self.clock, self.target.copy()))
        while len(self._samples) > 2 and self._samples[1][0] <= self.clock - THROW_WINDOW:
            self._samples.popleft()
        if self.sim.phase is not Phase.RUNNING:  # no steps to carry it: move it as far as is clear
            index = self.held_ball

            def place(world: object) -> None:
                ball = world.spheres[index]  # type: ignore[attr-defined]
                ball.position = clear_path(world, index, ball.position, self.target)
                ball.velocity = (0.0, 0.0, 0.0)
                ball.angular_velocity = (0.0, 0.0, 0.0)

            self.sim.edit(place, ghosts=False)

    def _pull(self) -> None:
        """Step hook: the mouse joint changes a held ball's velocity before the step (which then moves
        it, colliding as usual). The history keeps the pulled state, so stepping back repeats it."""
        if self.held_ball is None or self.held_ball >= self.sim.ball_count:
            return
        index, h = self.held_ball, self.sim.timestep

        def pull(world: object) -> None:
            ball = world.spheres[index]  # type: ignore[attr-defined]
            ball.velocity = spring_velocity(
                ball.position, ball.velocity, self.target, self.throw_velocity(), h
            )

        self.sim.edit(pull, ghosts=False)

    # ------------------------------------------------------------------ planes
    def select(self, index: int) -> None:
        """Select plane ``index`` (deselecting any other)."""
        if self.selected_plane == index:
            return
        self.deselect()
        plane = self.sim.world.planes[index]
        self.selected_plane = index
        self._base_motion = (np.array(plane.velocity, dtype=float), np.array(plane.angular_velocity))

    def deselect(self) -> bool:
        """Deselect the selected plane, giving it back its own motion. False if none was selected."""
        if self.selected_plane is None:
            return False
        plane = self.sim.world.planes[self.selected_plane]
        plane.velocity, plane.angular_velocity = self._base_motion
        self.selected_plane = None
        return True

    def _drive_plane(self, camera: Camera, held: set[str]) -> None:
        right, _, _ = camera_basis(camera)
        axes = {"right": right, "forward": np.cross(WORLD_UP, right)}
        velocity, spin = (m.copy() for m in self._base_motion)
        for name in held & PLANE_KEYS:
            if name in TILT_KEYS:
                axis, sign = TILT_KEYS[name]
                spin += sign * TILT_RATE * axes[axis]
            else:
                velocity += LIFT_KEYS[name] * LIFT_SPEED * WORLD_UP
        plane = self.sim.world.planes[self.selected_plane]
        plane.velocity, plane.angular_velocity = velocity, spin

    def own_motion(self) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """The selected plane's own (velocity, angular velocity), without what held keys add to it."""
        return {} if self.selected_plane is None else {self.selected_plane: self._base_motion}

    def takes_key(self, name: str) -> bool:
        """Whether a key press belongs to the selected plane (arrows, PgUp, PgDn) rather than its action."""
        return self.selected_plane is not None and name in PLANE_KEYS

    # ------------------------------------------------------------------ shooting
    def next_shot_speed(self) -> float:
        """Shift+B: the next shot speed, round the list."""
        bigger = [s for s in SHOT_SPEEDS if s > self.shot_speed]
        self.shot_speed = bigger[0] if bigger else SHOT_SPEEDS[0]
        return self.shot_speed

    def shoot(self, camera: Camera) -> int | None:
        """B: a ball from just in front of the eye along the view at ``shot_speed``; returns its index
        (None in a replay, where the HUD says B is not available).
        It is as big and heavy as the scene's typical (median) ball, and made of its typical material."""
        if self.in_replay:
            self.sim.message = NOT_IN_REPLAY.format("B (shoot a ball)")
            return None
        spheres = self.sim.world.spheres
        radius = float(np.median(spheres.radii)) if len(spheres) else SHOT_RADIUS
        mass = float(np.median(spheres.masses)) if len(spheres) else SHOT_MASS
        forward = camera.forward
        start = np.asarray(camera.position, dtype=float) + forward * (2.0 * radius + camera.near)
        color = palette_colors(1, first=len(spheres))[0]
        return self.sim.add_ball(
            color, position=start, radius=radius, mass=mass, velocity=forward * self.shot_speed,
            **typical_material(spheres),
        )  # fmt: skip

    # ------------------------------------------------------------------ state
    @property
    def in_replay(self) -> bool:
        """Whether the window plays a recorded run (``view --replay``) instead of live physics."""
        return self.sim.timeline.replay is not None

    def clear(self) -> None:
        """Reset hook: the world was replaced, so let go of everything (nothing to give back)."""
        self.held_ball = None
        self.selected_ball = None
        self.selected_plane = None
        self._samples.clear()

    def lines(self) -> np.ndarray:
        """The throw arrow from the held ball along its throw velocity, as overlay line vertices."""
        if self.held_ball is None:
            return overlays.empty()
        arrow = overlays.velocity_arrows(self.target[None, :], self.throw_velocity()[None, :])
        arrow[:, 3:] = THROW_COLOR
        return arrow

    def hud_lines(self) -> list[str]:
        """What the HUD says about reaching in."""
        lines = []
        if self.held_ball is not None:
            speed = float(np.linalg.norm(self.throw_velocity()))
            lines.append(f"holding     ball {self.held_ball}, throw {speed:.2f} m/s")
        if self.selected_plane is not None:
            lines.append(f"selected    plane {self.selected_plane}: arrows PgUp PgDn")
        return lines
