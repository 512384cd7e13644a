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
billiards, gas, pile10k, seesaw and slopes, when the split step began to bounce in waves (#24): only
the contacts arriving take part in a bounce (a break passes the cue ball's impulse through the rack
ball by ball; resting contacts under a bouncing ball no longer join its solve), what a wave sets
closing bounces in turn, slower approaches are stopped after the waves, and normal speeds are summed
component by component. cradle (its balls 1 mm apart), incline and pile are unchanged. cannon and
cradle_touching were added with it.
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
    "billiards": "b6e58d46f54ce15ed187b4a1f8a3578500649d7225f67b434a94bb9bf3e66ece",
    "cannon": "222fd2e64e49534af044705ca7a0a923405d217bbc8d219bceb39d9459504df7",
    "cradle": "4f893dd8f2d151d5883149cd93af3aaefba83ccc7d8289a6121a877faad1150d",
    "cradle_touching": "5c2fe00e0740007f95b107236c28f3f5ae4e5196609bdbdfcb21393f11951a48",
    "gas": "d5569d9319e48d0fb1876b77b852c9cdcc6236ee1e05d687b9a5faf354225266",
    "incline": "6ca212819d67c114b8ca2f7d5d49b05eb5e102c362d94034fc4b3052193024b0",
    "pile": "2ed3ffe792a2939ca1568c0e2102c482cf23422cdcfb0fc49b05c31b04ff7091",
    "pile10k": "b46d00037ddcb809eb09d3256dd8c63663403025f1955592586abcfe53eafb17",
    "seesaw": "e59017594f080d2608694fc04c6509609bb93ae1c53bc1054b5d72db426be7af",
    "slopes": "288f8ec12fba4e61f899da699c5d1fbf2016d987099ce406f78d90afb5fa127a",
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
