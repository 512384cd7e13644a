"""Step-rate benchmarks: free flight, a falling grid of balls piling into a box, a pile at rest, and
the slopes and see-saw demos.

Every measurement runs in its own process (``python -m ballpit.cli.bench --one ...``) so engines and sizes
do not share caches or memory, and so the peak resident memory per ball can be read honestly.
PyBullet, when installed (``pip install 'ballpit[bench]'``), runs the same pile for comparison.

    ballpit bench                       # free flight and pile tables at the default sizes
    ballpit bench --workload pile --sizes 1000,10000 --pybullet --plot scaling.png
    ballpit bench --workload settled --sizes 1000,10000,100000   # cost growth in a pile at rest
    ballpit bench --workload slopes --steps 2400   # the slopes demo headless, 10 s of it
    ballpit bench --workload seesaw --steps 1440   # the see-saw demo headless, its 6 s (a turning plank)
    ballpit bench --peers --sizes 1000,3000 --csv peers.csv --plot peers.png   # against MuJoCo and PyBullet

``--peers`` lands the grid in ballpit, MuJoCo and PyBullet at the same materials and the same 240 Hz,
the engines taking turns over rounds (``peers/``).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import platform
import resource
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .allocator import keep_freed_memory
from .arguments import OneLineParser, count, one_line, positive
from .children import run_child
from .peers.landing import DT, RADIUS, pile_layout

# DT: both engines solve contacts this often; a "step" below is this much simulated time.
# ballpit takes the pile and settled workloads as its bundled piles do: 1/60 s frames of 4 soft
# substeps (Box2D v3's soft step), so it too solves their contacts 240 times a second
SUBSTEPS = 4
# The bundled demos timed as they are (workloads named after their scenes).
DEMOS = ("slopes", "seesaw")


@dataclass
class Result:
    engine: str
    workload: str
    n: int
    steps: int
    seconds: float
    rss_bytes_per_ball: float

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds

    @property
    def ns_per_ball_step(self) -> float:
        return 1e9 * self.seconds / (self.steps * self.n)


SETTLED_LAYERS = 4


def settled_layout(n: int) -> tuple[np.ndarray, float]:
    """``n`` balls at rest in touching columns four deep on the floor, and the box's half width.

    The depth stays the same as N grows, so the cost per ball is comparable across sizes.
    """
    layers = SETTLED_LAYERS
    side = int(np.ceil(np.sqrt(n / layers)))
    ix, iy, iz = np.meshgrid(np.arange(side), np.arange(layers + 1), np.arange(side), indexing="ij")
    cells = np.stack((ix.ravel(), iy.ravel(), iz.ravel()), axis=1)
    cells = cells[np.lexsort((cells[:, 2], cells[:, 0], cells[:, 1]))][:n]
    centres = (cells - [0.5 * (side - 1), 0.0, 0.5 * (side - 1)]) * (2 * RADIUS) + [0.0, RADIUS, 0.0]
    return centres, side * RADIUS


def free_layout(n: int) -> np.ndarray:
    """``n`` ball centres on a cubic grid 1 m apart (free flight: no box, no contacts)."""
    side = int(np.ceil(n ** (1 / 3)))
    return np.stack(np.meshgrid(*(np.arange(side),) * 3, indexing="ij"), -1).reshape(-1, 3)[:n] * 1.0


def _box_layout(workload: str, n: int) -> tuple[np.ndarray, float]:
    """The ball centres and box half width of the pile or settled workload, the same for both engines."""
    return pile_layout(n) if workload == "pile" else settled_layout(n)


def _ballpit_world(workload: str, n: int):
    import ballpit

    if workload in DEMOS:  # the bundled demo as it is (its own ball count; ``n`` is not used)
        from ..scene import read_scene, resolve_scene_path

        return read_scene(resolve_scene_path(workload)).world
    world = ballpit.World(integrator="rk4")
    if workload == "free":
        rng = np.random.default_rng(0)
        world.add_spheres(free_layout(n), radius=RADIUS, velocity=rng.normal(0, 0.1, (n, 3)))
        world.gravity = (0, 0, 0)
        return world
    centres, half = _box_layout(workload, n)
    world.add_plane(normal=(0, 1, 0), restitution=0.5, friction=0.5, rolling_friction=0.02)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -half), normal=normal, restitution=0.5)
    world.add_spheres(centres, radius=RADIUS, restitution=0.5, rolling_friction=0.02)
    return world


def _pybullet_world(workload: str, n: int):
    """The workload in a PyBullet client, each ball a rigid body (PyBullet's fast path for free bodies)."""
    import pybullet as p

    from .peers.pybullet_engine import build_world

    client = p.connect(p.DIRECT)
    centres, half = (free_layout(n), None) if workload == "free" else _box_layout(workload, n)
    gravity = 0.0 if workload == "free" else 9.81
    build_world(client, centres, half, restitution=0.5, friction=0.5, gravity=gravity)
    return lambda: p.stepSimulation(physicsClientId=client)


def measure_one(engine: str, workload: str, n: int, steps: int) -> Result:
    """Build the workload, step it ``steps`` times and time only the stepping."""
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    # Untimed steps first: imports and first allocations, and for a pile at rest the solver's
    # warm start, which takes a few dozen steps to carry the stacks' contact forces.
    warm_up = 60 if workload == "settled" else 1
    if engine == "ballpit":
        world = _ballpit_world(workload, n)
        # a crowd in frames of SUBSTEPS soft substeps: one call advances that many steps of DT
        per_call = SUBSTEPS if workload in ("pile", "settled") else 1
        world.substeps = per_call
        frame = DT * per_call
        for _ in range(-(-warm_up // per_call)):
            world.step(frame)
        calls = -(-steps // per_call)
        steps = calls * per_call

        def step() -> object:
            return world.step(frame)
    else:
        calls = steps
        step = _pybullet_world(workload, n)
        for _ in range(warm_up):
            step()
    start = time.perf_counter()
    for _ in range(calls):
        step()
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    if engine == "ballpit":
        n = len(world.spheres)  # a demo has its own
    return Result(engine, workload, n, steps, seconds, (peak - base) * 1024.0 / n)


def run_isolated(engine: str, workload: str, n: int, steps: int, timeout: float) -> Result | None:
    """``measure_one`` in a fresh interpreter (``children.py``); None (after one line on stderr) when
    it fails."""
    result = run_child("ballpit.cli.bench", ["--one", engine, workload, str(n), str(steps)], timeout)
    if isinstance(result, dict):
        try:
            return Result(**result)
        except TypeError:
            result = f"an unexpected result: {one_line(str(result), limit=200)}"
    print(f"ballpit bench: {engine} {workload} N={n}: failed: {result}", file=sys.stderr)
    return None


def _table(results: list[Result], reference: dict[tuple[str, int], Result]) -> str:
    lines = [
        f"{'engine':8} {'workload':8} {'N':>7} {'steps':>6} {'steps/s':>10} {'ns/ball-step':>13} "
        f"{'RSS B/ball':>10} {'vs PyBullet':>11}"
    ]
    for r in results:
        ref = reference.get((r.workload, r.n))
        ratio = f"{r.steps_per_second / ref.steps_per_second:10.2f}x" if ref and r.engine == "ballpit" else ""
        lines.append(
            f"{r.engine:8} {r.workload:8} {r.n:7d} {r.steps:6d} {r.steps_per_second:10.1f} "
            f"{r.ns_per_ball_step:13.1f} {r.rss_bytes_per_ball:10.0f} {ratio:>11}"
        )
    return "\n".join(lines)


def _plot(results: list[Result], path: str) -> None:
    figure(results).savefig(path, dpi=120)
    print(f"wrote {path}")


def figure(results: list[Result]) -> object:
    """The log-log plot of step time against N (a matplotlib Figure), labelled with plain numbers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plots import label_log_axis_plainly

    fig, ax = plt.subplots(figsize=(6, 4))
    for engine in sorted({r.engine for r in results}):
        for workload in sorted({r.workload for r in results}):
            rs = sorted(
                (r for r in results if r.engine == engine and r.workload == workload), key=lambda r: r.n
            )
            if rs:
                ax.loglog(
                    [r.n for r in rs],
                    [1e3 / r.steps_per_second for r in rs],
                    "o-",
                    label=f"{engine} {workload}",
                )
    for axis in (ax.xaxis, ax.yaxis):
        label_log_axis_plainly(axis)
    ax.set_xlabel("balls")
    ax.set_ylabel("ms per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


PEER_SIZES = (1_000, 3_000, 10_000)
PEER_STEPS = 480  # the first 2 s: the grid lands and settles
PEER_ROUNDS = 3


def _peers(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    """``--peers``: the comparison lives in ``peers/``; here only the options are checked."""
    for option in ("workload", "pybullet", "pybullet_up_to", "one"):
        if getattr(args, option) not in (None, False, "all", "pile"):
            parser.error(f"--{option.replace('_', '-')} does not go with --peers (it runs the landing grid)")
    from .peers.report import run_peers

    plot = Path(args.plot) if args.plot else None
    sizes = args.sizes or list(PEER_SIZES)
    return run_peers(
        sizes, args.steps or PEER_STEPS, args.rounds or PEER_ROUNDS, args.timeout, args.csv, plot
    )


MAX_TIMEOUT = 1e6  # s (11.6 days): the wait for a child is kept in int milliseconds (at most 24.8 days)


def _timeout(text: str) -> float:
    seconds = positive(text)
    if seconds > MAX_TIMEOUT:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_TIMEOUT:g} seconds, got {text!r}")
    return seconds


def _sizes(text: str) -> list[int]:
    try:
        sizes = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"sizes must be integers separated by commas, got {text!r}"
        ) from None
    if not sizes or min(sizes) < 1:
        raise argparse.ArgumentTypeError(f"sizes must be positive, got {text!r}")
    return sizes


def main(argv: list[str] | None = None) -> int:
    description = " ".join(__doc__.split("\n\n")[0].split())  # the first paragraph, whole
    parser = OneLineParser(prog="ballpit bench", description=description)
    parser.add_argument(
        "--workload",
        choices=("free", "pile", "settled", *DEMOS, "all"),
        default="all",
        help="free flight; a grid falling into a box (the pile forming); a pile already at rest; or the "
        "slopes or see-saw demo headless (their own 5 balls; --sizes does not apply, PyBullet has no "
        "such scene)",
    )
    parser.add_argument("--sizes", type=_sizes, help="comma-separated ball counts (default per workload)")
    parser.add_argument(
        "--steps",
        type=count,
        default=None,
        help="steps of 1/240 s to time (default: 1 s of simulation; ballpit's pile and settled round up "
        "to whole 1/60 s frames)",
    )
    parser.add_argument("--pybullet", action="store_true", help="also run PyBullet on the same workload")
    parser.add_argument(
        "--pybullet-up-to",
        type=count,
        metavar="N",
        help="run PyBullet only up to N balls (its pile at rest grows as about N^1.6: hours at 100,000)",
    )
    parser.add_argument(
        "--peers",
        action="store_true",
        help="the landing grid in ballpit, MuJoCo and PyBullet (those installed), each at its fastest "
        f"stable settings at 240 Hz, taking turns over --rounds; --steps defaults to {PEER_STEPS} (2 s), "
        f"--sizes to {','.join(map(str, PEER_SIZES))} (10,000 takes the peers about 3 minutes a run)",
    )
    parser.add_argument("--rounds", type=count, help=f"with --peers: rounds (default {PEER_ROUNDS})")
    parser.add_argument("--csv", type=Path, metavar="CSV", help="with --peers: write every run to CSV")
    parser.add_argument("--plot", metavar="PNG", help="write a log-log plot of step time against N")
    parser.add_argument("--timeout", type=_timeout, default=1800.0, help="seconds allowed per measurement")
    parser.add_argument(
        "--one", nargs=4, metavar=("ENGINE", "WORKLOAD", "N", "STEPS"), help=argparse.SUPPRESS
    )
    args = parser.parse_args(argv)
    if args.peers:
        return _peers(parser, args)
    for option in ("rounds", "csv"):
        if getattr(args, option) is not None:
            parser.error(f"--{option} goes with --peers")
    if args.plot and not args.one:
        from .plots import MISSING_MATPLOTLIB, have_matplotlib

        if not have_matplotlib():  # say so now, not after the measurements
            parser.error(f"--plot {MISSING_MATPLOTLIB}")

    if args.one:
        keep_freed_memory()  # as the app runs the engine (allocator.py)
        engine, workload, n, steps = args.one
        print(json.dumps(asdict(measure_one(engine, workload, int(n), int(steps)))))
        return 0
    if args.pybullet and importlib.util.find_spec("pybullet") is None:
        print("ballpit bench: --pybullet needs PyBullet: pip install 'ballpit[bench]'", file=sys.stderr)
        return 2
    if args.plot:  # a bad path is one line now, before the measurements
        from .plots import PlotFile
        from .writers import OutputError

        try:
            PlotFile(Path(args.plot)).discard()
        except OutputError as e:
            print(f"ballpit bench: {one_line(str(e))}", file=sys.stderr)
            return 2

    plan = []
    if args.workload in ("free", "all"):
        plan += [("free", n) for n in (args.sizes or [10, 100, 1_000, 10_000, 100_000])]
    if args.workload in ("pile", "all"):
        plan += [("pile", n) for n in (args.sizes or [1_000, 10_000])]
    if args.workload in ("settled", "all"):
        plan += [("settled", n) for n in (args.sizes or [1_000, 10_000, 100_000])]
    plan += [(demo, 0) for demo in DEMOS if args.workload in (demo, "all")]
    machine = platform.processor() or platform.machine()
    versions = f"Python {platform.python_version()}, NumPy {np.__version__}"
    print(
        f"ballpit bench: {machine}, {versions}, RK4, each row in its own process; both engines solve "
        "contacts 240 times a second and a step is 1/240 s of simulated time (PyBullet steps 1/240 s; "
        f"ballpit takes pile and settled in 1/60 s frames of {SUBSTEPS} soft substeps)"
    )
    results: list[Result] = []
    reference: dict[tuple[str, int], Result] = {}
    failed = 0
    print(_table([], {}), flush=True)  # the header; each row prints as it finishes
    for workload, n in plan:
        steps = args.steps or 240  # one simulated second
        with_pybullet = args.pybullet and (args.pybullet_up_to is None or n <= args.pybullet_up_to)
        with_pybullet = with_pybullet and workload not in DEMOS
        # PyBullet first, so ballpit's row can show the ratio to it as soon as it is printed.
        engines = (["pybullet"] if with_pybullet else []) + ["ballpit"]
        for engine in engines:
            r = run_isolated(engine, workload, n, steps, args.timeout)
            if r is None:
                failed += 1
                continue
            results.append(r)
            if engine == "pybullet":
                reference[(workload, n)] = r
            print(_table([r], reference).splitlines()[1], flush=True)
    for engine in ("ballpit", "pybullet"):
        settled = sorted(
            (r for r in results if r.engine == engine and r.workload == "settled"), key=lambda r: r.n
        )
        if len(settled) >= 2:
            slope = np.polyfit(
                np.log([r.n for r in settled]), np.log([1 / r.steps_per_second for r in settled]), 1
            )[0]
            print(f"{engine}: log-log slope of step time against N in the settled pile: {slope:.2f}")
    if args.plot and results:
        _plot(results, args.plot)
    if failed:
        print(f"ballpit bench: {failed} of {failed + len(results)} measurements failed", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
