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
pile and pile10k, when crowded steps became Box2D v3's soft step (softstep.py: contacts measured once
per step, a soft-biased Jacobi solve and relax per substep, one restitution pass; #22) and a pile
rests in it too; the six other scenes never take a crowded step and are unchanged.
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
    "billiards": "023af0524170b5a2d9f050d4c01e29a3d27d2c43ce0060d50181b28606faf21d",
    "incline": "6ca212819d67c114b8ca2f7d5d49b05eb5e102c362d94034fc4b3052193024b0",
    "gas": "79e162b84f53a910af613dc94d8d339dee9ff8d29570023a3c7c26e15d627db8",
    "pile": "96552c8f33a735c3a0d38246135687a5b2511849a35181ae520c640b948fb1ab",
    "pile10k": "de89598207bfcb8b7e523072e194c277249b5d744471b6c4c9db5ba7183e8f7a",
    "seesaw": "62599274fca23f940b3383039e4887c86d7f9ad2a3f515d5c631e5fad3379d11",
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
