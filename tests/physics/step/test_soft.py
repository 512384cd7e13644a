"""The soft stage (step/soft.py): a frame that cannot keep its promises is undone to the step's
checkpoint and tried with twice the substeps, at most RETRIES times; the last try is kept when its
only fault is a contact that overlapped deeper; else the step is split at impacts, as if it had been
planned so.

The verdict on each try is replaced here (the rule that acts on it is what is checked); the verdict's
own checks are tests/physics/contact/test_softstep.py's and test_robustness.py's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballpit.physics.contact import columns, jacobi
from ballpit.physics.core.settings import RETRIES
from ballpit.physics.step import soft
from ballpit.physics.step.checkpoint import Checkpoint
from ballpit.physics.step.collide import Motion, collide
from ballpit.physics.step.plan import Plan

from .stages import pile_on_a_floor, prepared

DT = 1 / 60


def judged_always(monkeypatch, verdict: soft.Verdict) -> list[int]:
    """Every try judged ``verdict``; returns the list each try is counted in."""
    tries = []

    def judge(step, motion, left, c, frame, before):
        tries.append(frame)
        return verdict

    monkeypatch.setattr(soft, "verdict", judge)
    return tries


def falling_pile():
    world = pile_on_a_floor(substeps=2)
    world.spheres.velocities[:] = (0.0, -0.5, 0.0)
    return world


def test_a_frame_no_try_can_trust_is_undone_to_the_checkpoint_after_every_retry(monkeypatch):
    world = falling_pile()
    tries = judged_always(monkeypatch, soft.Verdict.MOVED_TOO_FAR)
    step = prepared(world, DT)
    motion = Motion.of(world.model, world.state)
    collision = collide(step, motion)
    checkpoint = Checkpoint.of(world.parts)
    body, kept, warm = world.state.body.copy(), world.parts.pairs.kept, world.parts.warm.keys
    assert not soft.frames(step, motion, collision, Plan.soft(2), checkpoint)
    assert len(tries) == RETRIES + 1
    assert np.array_equal(world.state.body, body)
    assert world.parts.warm.keys is warm and world.parts.pairs.kept.pair_i is kept.pair_i
    assert step.intervals == 0 and len(step.events.record()) == 0


def test_the_last_try_is_kept_when_its_only_fault_is_a_contact_that_overlapped_deeper(monkeypatch):
    world = falling_pile()
    tries = judged_always(monkeypatch, soft.Verdict.DEEPER)
    world.step(DT)
    assert len(tries) == RETRIES + 1
    assert world.crowded_steps == 1 and world.profile.intervals == 1


@pytest.mark.parametrize("verdict", [soft.Verdict.MOVED_TOO_FAR, soft.Verdict.LEFT_OUT])
def test_a_step_whose_soft_frame_failed_is_split_at_impacts_exactly_as_if_planned_so(monkeypatch, verdict):
    # the undone tries leave nothing behind: the same bits as a world that never tries a soft frame
    tried, split = falling_pile(), falling_pile()
    split.crowd_limit = math.inf  # always split at impacts
    judged_always(monkeypatch, verdict)
    tried_contacts = tried.step(DT)
    monkeypatch.undo()
    split_contacts = split.step(DT)
    assert tried.profile.crowded and not split.profile.crowded  # planned soft, taken split
    assert tried.crowded_steps == split.crowded_steps == 0
    assert np.array_equal(tried.state.body, split.state.body)
    assert np.array_equal(tried_contacts.impulse, split_contacts.impulse)
    assert np.array_equal(tried.parts.warm.keys, split.parts.warm.keys)


def test_soft_frames_solved_a_few_contacts_at_a_time_end_in_the_same_bits_as_solved_whole(monkeypatch):
    """The sweeps, the normal speeds and the mass split form their per-contact values SWEEP_CHUNK
    contacts at a time (a settled pile's memory); every value is one contact's own and the per-ball
    sums are still one bincount over all contacts, so chunks of 7 contacts leave a heap thrown onto
    a floor (a few hundred contacts) exactly where whole sweeps leave it."""

    def fallen(chunk: int | None) -> tuple[np.ndarray, np.ndarray]:
        if chunk is not None:
            for module in (jacobi, columns):  # the sweeps and the columns they read
                monkeypatch.setattr(module, "SWEEP_CHUNK", chunk)
        world = pile_on_a_floor(side=6, r=0.1, substeps=4)
        world.spheres.velocities[:] = (0.3, -0.5, 0.1)
        for _ in range(12):
            world.step(1 / 60)
        assert world.crowded_steps > 0
        return world.spheres.positions.copy(), world.spheres.angular_velocities.copy()

    whole, chunked = fallen(None), fallen(7)
    assert np.array_equal(whole[0], chunked[0])
    assert np.array_equal(whole[1], chunked[1])
