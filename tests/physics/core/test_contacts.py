"""Contact arrays (contacts.py): a pair's key is its own identity, subsets keep their order, and the
event log hands a step's contacts to ``World.step``'s caller in the order they happened."""

from __future__ import annotations

import numpy as np

import ballpit
from ballpit.physics.core.contacts import SPHERE_PLANE, SPHERE_SPHERE, ContactPoints, EventLog, pair_keys


def points(k: int = 4) -> ContactPoints:
    return ContactPoints(
        kind=np.array([SPHERE_PLANE, SPHERE_SPHERE, SPHERE_SPHERE, SPHERE_PLANE][:k], np.int8),
        a=np.arange(k),
        b=np.array([9, 2, 3, 9][:k]),
        other=np.array([0, 2, 3, 1][:k]),
        gap=np.linspace(-0.1, 0.2, k),
        normal=np.tile([0.0, 1.0, 0.0], (k, 1)),
        point=np.arange(3.0 * k).reshape(k, 3),
    )


def test_a_pair_key_tells_a_plane_from_a_ball_of_the_same_index_and_never_changes_with_the_world():
    keys = pair_keys(np.array([3, 3, 2**20]), np.array([5, 5, 7]), np.array([False, True, False]))
    assert keys[0] != keys[1]  # ball 5 or plane 5
    assert keys[0] == (3 << 32) | 5 and keys[2] >> 32 == 2**20
    c = points()
    assert c.keys().tolist() == pair_keys(c.a, c.other, c.kind == SPHERE_PLANE).tolist()


def test_a_subset_by_mask_or_by_indices_keeps_the_contacts_in_their_order():
    c = points()
    by_mask = c.subset(np.array([True, False, True, True]))
    by_index = c.subset(np.array([0, 2, 3]))
    assert by_mask.a.tolist() == by_index.a.tolist() == [0, 2, 3]
    assert by_mask.point.tolist() == c.point[[0, 2, 3]].tolist()
    gaps = c.gaps()
    assert gaps.normal is None and gaps.gap.tolist() == c.gap.tolist()
    assert ContactPoints.concatenate([c.subset(np.array([0])), c.subset(np.array([1]))]).a.tolist() == [0, 1]


def test_the_event_log_records_each_resolved_contact_at_its_time_in_order():
    log = EventLog()
    c = points()
    log.add(0.25, c, c.keys(), np.array([0.0, 1.0, 2.0, 0.0]))  # only contacts with an impulse count
    log.add(0.5, c.subset(np.array([0])), c.keys()[:1], np.array([3.0]))
    record = log.record()
    assert record.time.tolist() == [0.25, 0.25, 0.5]
    assert record.a.tolist() == [1, 2, 0] and record.impulse.tolist() == [1.0, 2.0, 3.0]


def test_a_pair_resolved_twice_is_one_entry_at_its_first_time_with_its_total_impulse():
    log = EventLog()
    c = points(2)
    log.add(0.1, c, c.keys(), np.array([1.0, 0.0]))
    log.add_resting(0.2, c, c.keys(), np.array([4.0, 2.0]))  # solved for the whole rest of the step
    log.close_interval(0.25)  # applied over a quarter of it
    record = log.record()
    assert record.a.tolist() == [0, 1] and record.time.tolist() == [0.1, 0.2]
    assert record.impulse.tolist() == [2.0, 0.5]


def test_the_contact_record_names_balls_by_intp_indices_whatever_the_pairs_keep():
    """The record's ``a`` and ``b`` are the platform's index type in every step (the kept pairs hold
    int32 indices to save memory; a step with one batch of contacts hands that batch on as it is)."""
    world = ballpit.World(gravity=(0.0, 0.0, 0.0))
    world.add_spheres(
        [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], radius=0.5, velocity=[[2.0, 0.0, 0.0], [-2.0, 0.0, 0.0]]
    )
    records = [world.step(0.01) for _ in range(40)]
    touched = [r for r in records if len(r.a)]
    assert touched, "the balls never met"
    for r in touched:
        assert r.a.dtype == np.intp and r.b.dtype == np.intp
        assert sorted((int(r.a[0]), int(r.b[0]))) == [0, 1]
