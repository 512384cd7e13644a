"""``--events-kind all`` reports every contact of every step, sleeping balls' resting contacts too."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

import ballpit
from ballpit.cli.simulate import run
from ballpit.cli.writers import EventWriter

DT = 1 / 240


def _resting_pair() -> ballpit.World:
    """Two balls side by side on a floor, a third on them: two sphere-plane contacts, three
    sphere-sphere (the bottom two press on each other as the top one pushes them apart)."""
    world = ballpit.World(sleep=True)
    world.add_plane()
    top = [0.0, 0.5 + math.sqrt(0.75), 0.0]
    world.add_spheres([[-0.5, 0.5, 0.0], [0.5, 0.5, 0.0], top], radius=0.5, mass=[1.0, 2.0, 1.5])
    return world


def test_resting_contacts_are_written_every_step_after_the_balls_fall_asleep(tmp_path):
    world = _resting_pair()
    out = tmp_path / "events.csv"
    events = EventWriter(out)
    steps = 480  # 2 s: asleep after about half a second
    run(world, steps * DT, DT, events=events, events_kind="all")
    events.commit()
    assert world.asleep.all()  # the point of the test: they slept for most of the run
    with out.open() as f:
        rows = list(csv.DictReader(f))
    per_step: dict[float, set] = {}
    for row in rows:
        per_step.setdefault(float(row["time"]), set()).add((row["kind"], int(row["a"]), int(row["b"])))
    assert len(per_step) == steps  # no step without its contacts
    times = np.array(sorted(per_step))
    np.testing.assert_allclose(times, np.arange(steps) * DT, atol=1e-9)
    floor = {("sphere-plane", 0, 0), ("sphere-plane", 1, 0)}
    balls = {("sphere-sphere", 0, 1), ("sphere-sphere", 0, 2), ("sphere-sphere", 1, 2)}
    assert all(per_step[t] == floor | balls for t in times[20:])  # settled within 20 steps, then the same
    # The floor holds each bottom ball up with (m + half the top ball's m)·g·dt per step, asleep or awake.
    last = {(r["kind"], int(r["a"])): float(r["impulse"]) for r in rows if float(r["time"]) == times[-1]}
    assert last[("sphere-plane", 0)] == pytest.approx((1.0 + 0.75) * 9.81 * DT, rel=1e-4)
    assert last[("sphere-plane", 1)] == pytest.approx((2.0 + 0.75) * 9.81 * DT, rel=1e-4)


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_the_summary_counts_only_the_contacts_the_steps_solved(tmp_path):
    """Sleeping balls' rows are added to the events file only; the run's contact counts stay the step's."""
    world = _resting_pair()
    events = EventWriter(tmp_path / "e.csv")
    summary = run(world, 2.0, DT, events=events, events_kind="all")
    events.discard()
    plain = run(_resting_pair(), 2.0, DT)
    assert summary.contacts == plain.contacts
    assert events.count > summary.contacts
