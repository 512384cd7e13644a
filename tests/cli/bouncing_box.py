"""A scene whose energies are known in closed form: one frictionless ball bouncing with e = 1 on the
floor of a closed box, dropped from rest.

Exact motion conserves E0 = m·g·y0 (potential measured from y = 0). The ball reaches the floor at
v0 = √(2·g·h) after falling h, and each flight (floor to floor, or apex to apex) lasts 2·v0/g.

Explicit Euler under constant gravity: v' = v − g·dt, y' = y + v·dt, so every whole step changes the
energy by ½m(v'² − v²) + m·g·(y' − y) = ½m(g²dt² − 2·v·g·dt) + m·g·v·dt = ½·m·g²·dt², exactly,
whatever v is: the energy grows linearly, ½·m·g²·dt per second. Over a flight of 2·v/g that is
m·g·v·dt ≈ ½m((v + g·dt)² − v²): the ball arrives g·dt faster after each flight, so after k flights
its arrival speed is about v_k = v0 + k·g·dt and its energy has grown by about ½m(v_k² − v0²).
RK2 (midpoint) and RK4 integrate constant acceleration exactly, so their energy holds to rounding.
"""

from __future__ import annotations

import math
from pathlib import Path

G = 9.81  # m/s²
MASS = 2.0  # kg
RADIUS = 0.1  # m
DROP = 1.25  # m from the ball's bottom to the floor
DT = 0.01  # s, the scene's timestep
Y0 = RADIUS + DROP  # m, the centre's start height
V0 = math.sqrt(2 * G * DROP)  # m/s, the speed at each landing of the exact motion
FLIGHT = 2 * V0 / G  # s, one flight of the exact motion
E0 = MASS * G * Y0  # J, the total energy (kinetic 0 at the start)

_WALL = "[[plane]]\nposition = {p}\nnormal = {n}\nrestitution = 1.0\nfriction = 0.0\n"


def write_scene(folder: Path, dt: float = DT) -> Path:
    """The box (floor, ceiling at 4 m, walls at ±1 m) with the ball dropped at its middle."""
    walls = [
        ([0, 0, 0], [0, 1, 0]),
        ([0, 4, 0], [0, -1, 0]),
        ([-1, 2, 0], [1, 0, 0]),
        ([1, 2, 0], [-1, 0, 0]),
        ([0, 2, -1], [0, 0, 1]),
        ([0, 2, 1], [0, 0, -1]),
    ]
    text = f'[world]\ngravity = [0, {-G}, 0]\nintegrator = "rk4"\ntimestep = {dt!r}\n\n'
    text += "\n".join(_WALL.format(p=p, n=n) for p, n in walls)
    text += (
        f"\n[[sphere]]\nposition = [0, {Y0!r}, 0]\nradius = {RADIUS!r}\nmass = {MASS!r}\n"
        "restitution = 1.0\nfriction = 0.0\n"
    )
    path = folder / "box.toml"
    path.write_text(text)
    return path


def euler_gain_per_flight_formula(flights: int, dt: float = DT) -> float:
    """½m(v_k² − v0²) with v_k = v0 + k·g·dt: Euler's energy gain after k flights (J)."""
    return 0.5 * MASS * ((V0 + flights * G * dt) ** 2 - V0**2)


def euler_gain_per_step_law(steps: int, dt: float = DT) -> float:
    """steps·½·m·g²·dt²: Euler's energy gain over whole steps of free flight (J)."""
    return steps * 0.5 * MASS * G**2 * dt**2
