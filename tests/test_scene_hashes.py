"""Every bundled scene gives bit-identical results from one change to the next.

Each scene runs for 2 s of simulated time at its own timestep; the hash covers every contact the
steps returned (time, kind, bodies, point, normal, impulse), the final state of every ball and the
final time. A change that alters any of them on purpose (a physics fix) must update the hash here and
say which scene changed and why in its commit message.

Recorded before the step was split into stages (issue #12) and unchanged by it. Changed on purpose
since: pile and pile10k, when crowded steps began to add the pairs a bounce turns balls towards to
their speculative contacts, and to stop short of any deep overlap with a pair still left out (#14);
billiards, pile and pile10k, when removing overlaps began to pay for the height it lifts balls by out
of their kinetic energy (#14: energy crept up in a closed elastic box); slopes, when its four slopes
got different restitutions and its balls the heights that keep the demo's meetings (#15); pile and
pile10k, when solves over 64 contacts or more became Jacobi sweeps with mass splitting and any meeting
among 256 kept pairs or more made a step crowded (#13: speed). No other scene has that many contacts.
pile, when it switched sleeping on (#13: a settled pile costs nothing): a few lone balls fall asleep
within its first 2 s. Every other scene, and pile with sleeping off, is unchanged by sleeping.
pile and pile10k, when Jacobi solves began to update friction in every fourth sweep only, the normal
impulses alone in the others (#13: speed); the six other scenes never solve 64 contacts at once.
pile and pile10k, when every solve of a crowded step became Jacobi, however few its contacts (#13:
speed); no other scene takes a crowded step.
seesaw, when the resting solve began to ask its contacts with a turning plane as they will be at the
interval's end (turned normal, the surface's velocity where the ball will be) (#23: balls rolling on
the plank drifted off it beyond the contact slop and split every step); no other scene has a turning
plane.
billiards, incline, gas, seesaw and pile10k, when time of impact began to leap, after 8 steps of
conservative advancement, to the earliest time a pair's gap along its normal could close (#23: a ball
rolling fast just above a surface made it crawl, 48 steps and a split of the step at a time); only
pairs that had needed more than 8 steps change, and slopes, cradle and pile have none in their first
2 s.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from ballpit.scene import read_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SECONDS = 2.0
HASHES = {
    "slopes": "36a8528b8a18082bac38998ec34ed841d60f3bf0a8fd2f051c23942bf69ce775",
    "cradle": "4f893dd8f2d151d5883149cd93af3aaefba83ccc7d8289a6121a877faad1150d",
    "billiards": "ad70d4ef11a01eeee16c8670fbec73d9c76c399f3e88706501ba809e8b75e957",
    "incline": "2b0d33dc38bf229efc8cbcfd5c7862c6d75a650fd97eb0636de4ed0a47122f78",
    "gas": "b5217e049d0d645593ec28d770adf7245e1a54da316e72dd7b1efd2f331882fa",
    "pile": "2ed3ffe792a2939ca1568c0e2102c482cf23422cdcfb0fc49b05c31b04ff7091",
    "pile10k": "22b9c279bbafd85fbb00de430609c705cde243daaa0db620421e72e2b1fda44b",
    "seesaw": "793a038b7a20dc17f56b59fc73a2e1de9436d12ba7ede4b103aa40f484156e19",
}


def scene_hash(path: Path, seconds: float = SECONDS) -> str:
    """SHA-256 of every step's contacts, then the final ball states and time, after ``seconds``."""
    scene = read_scene(path)
    world, dt = scene.world, scene.timestep
    digest = hashlib.sha256()
    for _ in range(round(seconds / dt)):
        c = world.step(dt)
        for column in (c.time, c.kind, c.a, c.b, c.point, c.normal, c.impulse):
            digest.update(np.ascontiguousarray(column).tobytes())
    digest.update(np.ascontiguousarray(world.state.body).tobytes())
    digest.update(np.float64(world.time).tobytes())
    return digest.hexdigest()


def test_every_bundled_scene_has_a_recorded_hash():
    assert {p.stem for p in SCENES.glob("*.toml")} == set(HASHES)


@pytest.mark.parametrize("name", sorted(HASHES))
def test_bundled_scene_runs_bit_identically(name):
    assert scene_hash(SCENES / f"{name}.toml") == HASHES[name]


if __name__ == "__main__":  # print the hashes of the scenes as they run now
    for p in sorted(SCENES.glob("*.toml")):
        print(f'    "{p.stem}": "{scene_hash(p)}",')
