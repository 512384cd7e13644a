"""How long ``ballpit check`` takes on a large or hostile scene file, and its peak memory.

    python benchmarks/scene_load.py planes 40000        # 40,000 [[plane]] tables
    python benchmarks/scene_load.py spheres 450977      # 15 MiB of [[sphere]] tables
    python benchmarks/scene_load.py spheres-nan 450977  # the same, the last one with a NaN position
    python benchmarks/scene_load.py grid 100            # one [[grid]] of 100 x 100 x 100 balls

The file is written to a temporary folder, then checked by ``python -m ballpit check`` in a process of
its own; the line printed is the kind, the size, the exit status, the wall time and the peak resident
memory (``ru_maxrss`` of the child). Run it under paired runs to compare two checkouts.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def write_scene(path: Path, kind: str, n: int) -> None:
    with open(path, "w") as f:
        if kind == "planes":
            for k in range(n):
                f.write(f"[[plane]]\nposition = [{k * 10.0}, 0, 0]\nsize = 4\n")
        elif kind in ("spheres", "spheres-nan"):
            for k in range(n):
                f.write(f"[[sphere]]\nposition=[{k % 80 * 2},{k // 80 % 80 * 2},{k // 6400 * 2}]\n")
            if kind == "spheres-nan":
                f.write("[[sphere]]\nposition=[nan,1,1]\n")
        elif kind == "grid":
            f.write(f"[[grid]]\ncount = [{n}, {n}, {n}]\ncorner = [0, 1, 0]\nradius = 0.1\n")
        else:
            raise SystemExit(f"unknown kind {kind!r}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=("planes", "spheres", "spheres-nan", "grid"))
    parser.add_argument("n", type=int)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{args.kind}.toml"
        write_scene(path, args.kind, args.n)
        began = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "ballpit", "check", str(path)], capture_output=True)
        wall = time.perf_counter() - began
    peak_mib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"{args.kind} {args.n}: status {done.returncode}, {wall:.2f} s, peak {peak_mib:.0f} MiB")


if __name__ == "__main__":
    main()
