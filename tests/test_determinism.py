"""The bundled scenes give the same bits whatever CPU kernels NumPy, OpenBLAS and the C library pick.

Each scene runs in fresh processes, once as this machine chooses and once under each switch below, and
every step's contacts and ball states must match bit for bit. The switches stand in for other x86-64
CPUs on this one:

- ``OPENBLAS_CORETYPE=Sandybridge``: OpenBLAS's AVX kernels, without the fused multiply-adds of the
  Haswell and SkylakeX ones (matrix products, ``np.dot`` and the norm of a single vector go there);
- an old CPU as a whole: OpenBLAS's SSE3 kernels (``Prescott``), every NumPy SIMD path that is chosen
  at run time switched off (``NPY_DISABLE_CPU_FEATURES``, leaving the build's baseline), and glibc's
  AVX2 and FMA variants of its maths functions (``sin``, ``cos``, ``exp``) switched off.

Before physics/exact.py, pile (its overlap removal paid for lifted balls with BLAS sums) first differed
in step 372 under Prescott and in step 397 under Sandybridge, seesaw (its turning plane's normal
divided by a BLAS norm) in step 128 under both, and a slope turned 52.4° (the sine of its half angle,
from glibc) in step 79 under the old CPU, when the ball lands on it (steps counted from 1); the
durations here reach past those steps.
"""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

SHARED = ("runs",)  # the default run and one per switch, made once (tests/conftest.py: on one worker)
pytestmark = pytest.mark.slow  # subprocesses under other CPU kernels: `make test`, not `make check`

SCENES = Path(__file__).resolve().parents[1] / "scenes"
# Simulated seconds per scene: past the first differing step found before the fix, and short.
SECONDS = {"pile": 1.75, "seesaw": 1.0, "slopes": 2.0, "incline": 2.0, "cradle": 2.0, "billiards": 1.0}
# A ball rolling down a slope turned 52.4° about z: sin(26.2°) is one of the few half angles whose
# sine glibc's FMA and plain variants round differently.
SLOPE = """[world]
timestep = 0.004166667
[[plane]]
rotation = [0, 0, 52.4]
size = 6
[[sphere]]
position = [0.5, 1.5, 0]
radius = 0.2
"""

# Each step's contacts and the whole ball state, digested; one line per step.
_CHILD = """
import hashlib, sys
from pathlib import Path
import numpy as np
from ballpit.scene import read_scene
for arg in sys.argv[1:]:
    path, seconds = arg.rsplit("=", 1)
    scene = read_scene(Path(path))
    world, dt = scene.world, scene.timestep
    for k in range(round(float(seconds) / dt)):
        c = world.step(dt)
        d = hashlib.sha256()
        for column in (c.time, c.kind, c.a, c.b, c.point, c.normal, c.impulse, world.state.body):
            d.update(np.ascontiguousarray(column).tobytes())
        print(Path(path).stem, k, d.hexdigest())
"""


def _dispatched_numpy_features() -> str:
    """Every CPU feature NumPy may pick at run time (the baseline it was built for cannot be switched
    off): AVX2/FMA3 and the AVX-512 family, under whatever names this NumPy uses."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # NumPy 1.x
        from numpy.core import _multiarray_umath as umath
    return " ".join(umath.__cpu_dispatch__)


SWITCHES = {
    "Sandybridge BLAS": {"OPENBLAS_CORETYPE": "Sandybridge"},
    "an old CPU": {
        "OPENBLAS_CORETYPE": "Prescott",
        "NPY_DISABLE_CPU_FEATURES": _dispatched_numpy_features(),
        "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4",
    },
}
_KNOBS = ("OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES", "GLIBC_TUNABLES", "OPENBLAS_NUM_THREADS")


def _run(switch: dict[str, str], scenes: dict[Path, float]) -> dict[str, list[str]]:
    """Every step's digest of each scene, in a fresh process with ``switch`` set (and nothing else)."""
    env = {k: v for k, v in os.environ.items() if k not in _KNOBS} | switch
    args = [f"{path}={seconds}" for path, seconds in scenes.items()]
    out = subprocess.run(
        [sys.executable, "-W", "error::ImportWarning", "-c", _CHILD, *args],
        env=env, capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    steps: dict[str, list[str]] = {path.stem: [] for path in scenes}
    for line in out.stdout.splitlines():
        name, _k, digest = line.split()
        steps[name].append(digest)
    return steps


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, dict[str, list[str]]]:
    """The default run and one per switch, two processes at a time."""
    slope = tmp_path_factory.mktemp("determinism") / "slope52.toml"
    slope.write_text(SLOPE)
    scenes = {SCENES / f"{name}.toml": seconds for name, seconds in SECONDS.items()} | {slope: 1.0}
    kinds = {"default": {}} | SWITCHES
    with ThreadPoolExecutor(max_workers=2) as pool:
        done = pool.map(lambda switch: _run(switch, scenes), kinds.values())
        return dict(zip(kinds, done, strict=True))


@pytest.mark.parametrize("switch", sorted(SWITCHES))
@pytest.mark.parametrize("scene", [*sorted(SECONDS), "slope52"])
def test_a_bundled_scene_gives_the_same_bits_under_other_cpu_kernels(runs, scene, switch):
    default, other = runs["default"][scene], runs[switch][scene]
    assert len(default) == len(other) > 0
    first = next((k for k, (a, b) in enumerate(zip(default, other, strict=True)) if a != b), None)
    assert first is None, f"{scene} under {switch} {SWITCHES[switch]} first differs in step {first + 1}"
