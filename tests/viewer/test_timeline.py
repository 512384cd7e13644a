"""The Simulation's timeline without a window: ghosts follow integrator switches and the history, and
the energy trace forgets what lies after the present when you step back."""

from __future__ import annotations

import math

from ballpit.viewer.simulation import Simulation

from .conftest import line_of_balls


def running(sim: Simulation, seconds: float) -> None:
    for _ in range(round(seconds * 60)):
        sim.advance(1 / 60)


def test_ghosts_are_always_the_other_integrators():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    sim.toggle_ghosts()
    assert sim.timeline.ghosts.integrators == ("euler", "rk2", "symplectic")
    sim.start()
    running(sim, 0.2)
    sim.set_integrator("euler")
    assert sim.timeline.ghosts.integrators == ("rk2", "rk4", "symplectic")
    assert "ghosts on" in sim.message
    ghost = sim.timeline.ghosts.worlds["rk4"]
    assert ghost.time == sim.world.time and ghost.integrator == "rk4"
    sim.toggle_ghosts()
    assert sim.timeline.ghosts is None


def test_stepping_back_moves_the_ghosts_and_cuts_the_energy_trace():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    sim.toggle_ghosts()
    sim.start()
    running(sim, 1.0)
    sim.toggle_pause()
    latest = sim.timeline.energy.series()["time"][-1]
    sim.jump(-0.5)
    now = sim.world.time
    assert now < latest
    assert sim.timeline.energy.series()["time"][-1] == now
    for history in sim.timeline.ghosts.histories.values():
        assert history.current == sim.timeline.history.current
    for world in sim.timeline.ghosts.worlds.values():
        assert world.time == now


def test_reset_keeps_ghosts_on_and_starts_a_new_history():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    sim.start()
    running(sim, 0.3)
    sim.toggle_ghosts()
    sim.reset()
    assert sim.timeline.history is None and sim.timeline.ghosts is not None
    sim.start()
    running(sim, 0.1)
    assert sim.timeline.history.current == sim.timeline.ghosts.histories["euler"].current > 0
