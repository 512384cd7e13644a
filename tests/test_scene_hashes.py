"""Every bundled scene gives bit-identical results from one change to the next.

Each scene runs for 2 s of simulated time at its own timestep; the hash covers every contact the
steps returned (time, kind, bodies, point, normal, impulse), the final state of every ball and the
final time. A change that alters any of them on purpose (a physics fix) must update the hash here and
say which scene changed and why in its commit message.

Recorded before the step was split into stages (issue #12) and unchanged by it. Changed on purpose
since: pile and pile10k, when crowded steps began to add the pairs a bounce turns balls towards to
their speculative contacts, and to stop short of any deep overlap with a pair still left out (#14).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from ballpit.scene import load_scene

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SECONDS = 2.0
HASHES = {
    "slopes": "97b34b83b30bebaa49f94c8f70e2f53523d2360a22550d23a2cf6d2b24a4902c",
    "cradle": "4f893dd8f2d151d5883149cd93af3aaefba83ccc7d8289a6121a877faad1150d",
    "billiards": "655eb9cea2697abce3c564485a48f84cfdc52c4b0195623dcc161bb9dff21db8",
    "incline": "6ca212819d67c114b8ca2f7d5d49b05eb5e102c362d94034fc4b3052193024b0",
    "gas": "79e162b84f53a910af613dc94d8d339dee9ff8d29570023a3c7c26e15d627db8",
    "pile": "2d3eb048ad197bfb0594f5ea1dbe5a22d05d5197374111cda1c9cd9e4930aa41",
    "pile10k": "7c3f46f1c950ea26abfdda94d31fc0373a0b4c88c54dfe160515d8364e62f9e0",
    "seesaw": "f0fa46d4f2857af995adbbb633f68e6cd9591c2348b7828c0e4117946793523e",
}


def scene_hash(path: Path, seconds: float = SECONDS) -> str:
    """SHA-256 of every step's contacts, then the final ball states and time, after ``seconds``."""
    world = load_scene(path)
    dt = world.scene.timestep
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
