"""The panel's copy of the run (watch.py): the traces of the selected ball."""

from __future__ import annotations

import math

from ballpit.viewer.simulation import Simulation
from ballpit.viewer.watch import Traces

from .conftest import line_of_balls


def test_a_trace_cut_at_a_time_keeps_what_came_before_and_is_stepped_on_from_there():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    traces = Traces()
    traces.follow(0)
    sim.after_step.append(lambda: traces.sample(sim))
    sim.start()
    sim.advance(0.5)
    heights = {t: h for t, _, h, _ in traces.samples}
    traces.cut(0.25)  # the run resumed from 0.25 s: what it had after is a future dropped
    assert max(t for t, *_ in traces.samples) <= 0.25
    assert [t for t, *_ in traces.samples] == [t for t in heights if t <= 0.25]
    sim.timeline.seek(round(0.25 / sim.timestep))
    sim.resume_from_here()
    sim.advance(0.1)
    times = [t for t, *_ in traces.samples]
    assert times == sorted(times) and times[-1] > 0.25
    assert all(heights[t] == h for t, _, h, _ in traces.samples if t in heights)  # the same run again
