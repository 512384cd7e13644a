"""Where the memory of a settled pile's frame goes: the traced peak of one ``World.step`` of the
``settled`` workload (``ballpit bench --workload settled``), the line it is reached on, and what is
alive then, per allocation site, in bytes a ball (#22 target 4; docs/benchmarks.md, 2026-12-04).

    .venv/bin/python benchmarks/settled_memory.py                 # 100,000 balls, after 3 frames
    .venv/bin/python benchmarks/settled_memory.py --balls 10000 --frames 15

Two identical runs (the step is deterministic): the first traces every line of the step with
tracemalloc and finds where the peak is, the second takes a snapshot just before that line. The
tracing slows the step about tenfold, and a traced peak leaves out what the allocator keeps around
(``ballpit bench`` reports peak RSS, a few hundred bytes a ball more).
"""

import argparse
import linecache
import sys
import tracemalloc

from ballpit.cli import bench
from ballpit.cli.allocator import keep_freed_memory

FRAME = bench.SUBSTEPS * bench.DT


def settled(n: int, frames: int):
    world = bench._ballpit_world("settled", n)
    world.substeps = bench.SUBSTEPS
    for _ in range(frames):
        world.step(FRAME)
    return world


def traced_step(world, take: int = -1) -> tuple[int, int, tuple | None, tracemalloc.Snapshot | None]:
    """One step, line by line: the traced peak, the event it came at and its line; with ``take``, the
    snapshot just before event ``take``."""
    found = {"i": 0, "prev": None, "peak": 0, "at": -1, "line": None, "shot": None}

    def local(frame, event, arg):
        if event in ("line", "return"):
            peak = tracemalloc.get_traced_memory()[1]
            if found["prev"] is not None and peak > found["peak"]:
                found.update(peak=peak, at=found["i"] - 1, line=found["prev"])
            if found["i"] == take:
                found["shot"] = tracemalloc.take_snapshot()
            found["prev"] = (frame.f_code.co_filename, frame.f_lineno)
            found["i"] += 1
            tracemalloc.reset_peak()
        return local

    def tracer(frame, event, arg):
        return local if "/ballpit/" in frame.f_code.co_filename else None

    tracemalloc.reset_peak()
    sys.settrace(tracer)
    world.step(FRAME)
    sys.settrace(None)
    return found["peak"], found["at"], found["line"], found["shot"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--balls", type=int, default=100_000)
    parser.add_argument("--frames", type=int, default=3, help="frames stepped before the one measured")
    parser.add_argument("--top", type=int, default=40, help="allocation sites shown")
    args = parser.parse_args()
    n = args.balls
    keep_freed_memory()  # as the app and the bench run the engine
    tracemalloc.start(30)
    world = settled(n, args.frames)
    before = tracemalloc.get_traced_memory()[0]
    peak, at, (path, line), _ = traced_step(world)
    code = linecache.getline(path, line).strip()
    print(f"{n} balls: live between steps {before / n:.0f} B a ball, traced peak of a frame {peak / n:.0f}")
    print(f"at {path.split('/ballpit/')[-1]}:{line}  {code}")
    del world
    _, _, _, shot = traced_step(settled(n, args.frames), take=at)
    shot = shot.filter_traces([tracemalloc.Filter(False, tracemalloc.__file__)])
    stats = shot.statistics("traceback")
    print(f"alive just before that line: {sum(s.size for s in stats) / n:.0f} B a ball; by site:")
    for s in stats[: args.top]:
        frames = [f for f in reversed(list(s.traceback)) if "/ballpit/" in f.filename]
        where = " <- ".join(f"{f.filename.split('/')[-1]}:{f.lineno}" for f in frames[:3])
        code = linecache.getline(frames[0].filename, frames[0].lineno).strip()[:60] if frames else ""
        print(f"  {s.size / n:7.1f}  {where:58s} {code}")


if __name__ == "__main__":
    main()
