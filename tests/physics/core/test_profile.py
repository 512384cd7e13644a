"""The profile (profile.py): a step's time lands under the stage named, only names of ``Stage`` are
taken, and a run adds its steps up."""

from __future__ import annotations

import time

import pytest

import ballpit
from ballpit.physics.core.profile import STAGES, RunProfile, Stage, StepProfile


def test_a_timed_block_adds_its_time_to_its_stage_alone():
    profile = StepProfile()
    with profile.stage(Stage.IMPACTS):
        time.sleep(0.02)
    assert profile.seconds[Stage.IMPACTS] >= 0.02
    assert all(s == 0.0 for name, s in profile.seconds.items() if name != Stage.IMPACTS)


def test_a_name_not_among_the_stages_is_refused():
    profile = StepProfile()
    with pytest.raises(KeyError, match="my stage"), profile.stage("my stage"):
        pass
    assert set(STAGES) == {v for k, v in vars(Stage).items() if k.isupper()}


def test_a_run_adds_up_its_steps_and_a_world_reports_each_step_under_the_stages():
    world = ballpit.World()
    world.add_plane()
    world.add_sphere(position=(0, 0.5, 0), radius=0.5)
    run = RunProfile()
    for _ in range(3):
        world.step(1 / 240)
        run.add(world.profile)
    assert run.steps == 3 and run.intervals >= 3 and set(run.seconds) == set(STAGES)
    assert world.profile.seconds[Stage.PAIRS] > 0.0 and world.profile.total >= sum(
        world.profile.seconds.values()
    )
