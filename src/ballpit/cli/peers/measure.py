"""One engine, one landing grid, in this process: the step rate, and what the landing did to the balls.

The clock runs only while the engine steps. Between its calls (every 1/60 s of simulated time) the
balls' positions are read and their deepest overlap is taken; that reading is not timed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .engines import ENGINES
from .landing import DT, GRAVITY, RADIUS, Landing, inside_box, max_overlap, max_speed

DROP_SPEED = 2.0  # m/s: the bounce check's impact speed, about a ball's landing on the pile
DROP_HEIGHT = DROP_SPEED**2 / (2 * GRAVITY)  # m of fall, from touching the floor
DROP_SECONDS = 0.5  # the fall takes 0.2 s and the rebound's climb 0.05 s


@dataclass
class Landed:
    """One engine's landing of ``n`` balls for ``steps`` steps of DT."""

    engine: str
    version: str
    settings: str
    n: int
    steps: int
    seconds: float  # stepping only
    max_overlap: float  # deepest ball-ball or ball-wall overlap at any sample, a fraction of the radius
    final_speed: float  # m/s: the fastest ball at the end
    inside: int  # balls with their centres inside the box at the end
    bounce: float  # restitution a ball dropped on the floor at DROP_SPEED shows in this engine

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds


def land(engine: str, n: int, steps: int, overrides: dict[str, str] | None = None) -> Landed:
    """Run ``engine`` on the landing grid of ``n`` balls for at least ``steps`` steps of DT."""
    spec = ENGINES[engine]
    settings = spec.configure(overrides or {})
    landing = Landing.of(n)
    run = spec.start(landing, settings)
    advances = -(-steps // run.steps_per_advance)
    seconds = 0.0
    deepest = 0.0
    for _ in range(advances):
        start = time.perf_counter()
        run.advance()
        seconds += time.perf_counter() - start
        deepest = max(deepest, max_overlap(run.positions(), RADIUS, landing.half))
    positions = run.positions()
    return Landed(
        engine=engine,
        version=run.version,
        settings=settings.describe(),
        n=n,
        steps=advances * run.steps_per_advance,
        seconds=seconds,
        max_overlap=deepest,
        final_speed=max_speed(run.velocities()),
        inside=inside_box(positions, landing.half),
        bounce=bounce(engine, settings),
    )


def bounce(engine: str, settings: Any) -> float:
    """The restitution of one ball dropped onto the floor at DROP_SPEED: √(rebound height / drop height).

    Heights are read every 1/60 s; the rebound's apex is the highest point after the ball first
    moves up again (an apex sampled up to 1/120 s off is at most g/2·(1/120)² = 0.34 mm low, 1.4 % of e).
    """
    spec = ENGINES[engine]
    run = spec.start(Landing(np.array([[0.0, RADIUS + DROP_HEIGHT, 0.0]]), half=1.0), settings)
    heights, rising = [], []
    for _ in range(round(DROP_SECONDS / (DT * run.steps_per_advance))):
        run.advance()
        heights.append(run.positions()[0, 1] - RADIUS)
        rising.append(run.velocities()[0, 1] > 0)
    if not any(rising):
        return 0.0
    first_up = rising.index(True)
    return float(np.sqrt(max(0.0, max(heights[first_up:])) / DROP_HEIGHT))
