"""The ``ballpit`` command line: view, check, simulate, render, bench, scenes.

Bad input of any kind (a bad scene, a missing file, a bad option) exits with status 2 and one line
on stderr naming the file and the problem, never a traceback. Heavy modules (the viewer, the
renderer, the benchmark) are imported only by the command that needs them.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from . import __version__

COMMANDS = ("view", "check", "simulate", "render", "bench", "scenes")
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error message (no usage block), still exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _positive(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not math.isfinite(x) or x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text!r}")
    return x


def _count(text: str) -> int:
    try:
        k = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if k < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text!r}")
    return k


def _size(text: str) -> tuple[int, int]:
    parts = text.lower().split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be WIDTHxHEIGHT in pixels, like 960x540, got {text!r}"
        ) from None
    if w < 16 or h < 16 or w > 8192 or h > 8192:
        raise argparse.ArgumentTypeError(f"must be between 16 and 8192 pixels each way, got {text!r}")
    return w, h


def build_parser() -> argparse.ArgumentParser:
    """The argument parser for every command (``bench`` passes its arguments straight through)."""
    parser = _Parser(
        prog="ballpit",
        description="Balls, slopes, spin and impacts: a physics sandbox with a viewer and a headless runner.",
        epilog="With no command, or just a scene file, ballpit opens the viewer.",
    )
    parser.add_argument("--version", action="version", version=f"ballpit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("view", help="open the viewer on SCENE (default: the bundled slopes demo)")
    p.add_argument("scene", nargs="?", help="a scene file, or a bundled scene's name")
    p.add_argument("--record", type=Path, metavar="FILE", help="when the window closes, write every step "
                   "it showed to FILE (.npz or .csv, simulate's trajectory columns)")  # fmt: skip
    p.set_defaults(handler=_view)

    p = sub.add_parser("check", help="validate a scene file")
    p.add_argument("scene", help="a scene file, or a bundled scene's name")
    p.set_defaults(handler=_check)

    p = sub.add_parser(
        "simulate",
        help="run a scene headless and write its trajectory and contacts",
        description="Run a scene without a window. The trajectory has one row per ball per recorded step "
        "(the initial state, every K-th step and the final state); events one row per contact.",
    )
    p.add_argument("scene", help="a scene file, or a bundled scene's name")
    p.add_argument("--duration", type=_positive, metavar="S", help="seconds to simulate (default: the "
                   "scene's [world] duration, else 10)")  # fmt: skip
    p.add_argument(
        "--dt", type=_positive, metavar="S", help="seconds per step (default: the scene's timestep)"
    )
    p.add_argument("--integrator", choices=("euler", "rk2", "rk4"), help="override the scene's integrator")
    p.add_argument("--out", type=Path, metavar="FILE", help="trajectory file, .csv or .npz")
    p.add_argument("--events", type=Path, metavar="FILE", help="contact events file, .csv or .npz")
    p.add_argument("--every", type=_count, default=1, metavar="K", help="record every K-th step (default 1)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    p.set_defaults(handler=_simulate)

    p = sub.add_parser("render", help="render a scene offscreen to a GIF or a folder of PNG frames")
    p.add_argument("scene", help="a scene file, or a bundled scene's name")
    p.add_argument(
        "--out", required=True, metavar="PATH", help="demo.gif, frame.png, or a folder for PNG frames"
    )
    p.add_argument("--duration", type=_positive, metavar="S", help="seconds to render (default: the scene's "
                   "[world] duration, else 10)")  # fmt: skip
    p.add_argument("--fps", type=_count, default=30, metavar="F", help="frames per second (default 30)")
    p.add_argument("--size", type=_size, default=(960, 540), metavar="WxH", help="pixels (default 960x540)")
    p.set_defaults(handler=_render)

    sub.add_parser(
        "bench", help="the step-rate benchmark (ballpit bench --help for its options)", add_help=False
    )

    p = sub.add_parser("scenes", help="list the bundled scenes")
    p.set_defaults(handler=_scenes)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    if args_list and args_list[0] == "bench":
        return _bench(args_list[1:])
    if not args_list or (args_list[0] not in COMMANDS and _looks_like_scene(args_list[0])):
        args_list = ["view", *args_list]
    parser = build_parser()
    args = parser.parse_args(args_list)
    from .scene import SceneError
    from .writers import OutputError

    try:
        return int(args.handler(args) or EXIT_OK)
    except (SceneError, OutputError) as e:
        print(f"ballpit: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("ballpit: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _looks_like_scene(arg: str) -> bool:
    return not arg.startswith("-") and (arg.endswith(".toml") or Path(arg).is_file())


def _load(scene_arg: str):
    from .scene import load_scene, resolve_scene_path

    return load_scene(resolve_scene_path(scene_arg))


def _check(args: argparse.Namespace) -> int:
    world = _load(args.scene)
    info = world.scene
    duration = f", suggested duration {info.duration:g} s" if info.duration else ""
    print(
        f"{info.path}: ok: {len(world.spheres)} balls, {len(world.planes)} planes, {world.integrator}, "
        f"timestep {info.timestep * 1000:.4g} ms{duration}"
    )
    return EXIT_OK


def _simulate(args: argparse.Namespace) -> int:
    from .simulate import format_summary, run
    from .writers import EventWriter, OutputError, TrajectoryWriter

    world = _load(args.scene)
    info = world.scene
    if args.integrator:
        world.integrator = args.integrator
    dt = args.dt or info.timestep
    duration = args.duration or info.duration or 10.0
    if args.out is not None and args.events is not None and args.out.resolve() == args.events.resolve():
        raise OutputError(f"{args.out}: --out and --events must be different files")
    writers: list = []
    try:
        trajectory = events = None
        if args.out is not None:
            trajectory = TrajectoryWriter(args.out, len(world.spheres))
            writers.append(trajectory)
        if args.events is not None:
            events = EventWriter(args.events)
            writers.append(events)
        try:
            summary = run(
                world,
                duration,
                dt,
                every=args.every,
                trajectory=trajectory,
                events=events,
                progress=not args.quiet,
            )
        except FloatingPointError as e:
            print(
                f"ballpit: {info.path}: the simulation failed at t = {world.time:.6g} s: {e}", file=sys.stderr
            )
            return EXIT_FAILED
        for w in writers:
            w.commit()
        writers.clear()
    finally:
        for w in writers:  # anything not committed: failure or interrupt
            w.discard()
    if not args.quiet:
        for line in format_summary(summary, info.name, world.integrator, dt, len(world.spheres)):
            print(line)
        if trajectory is not None:
            print(f"  wrote {args.out} ({summary.records} records x {len(world.spheres)} balls)")
        if events is not None:
            print(f"  wrote {args.events} ({events.count} contacts)")
    return EXIT_OK


def _view(args: argparse.Namespace) -> int:
    from .scene import resolve_scene_path
    from .writers import check_output_path

    if args.record is not None:
        check_output_path(args.record, "--record")  # a bad path is a one-line error before a window opens
    path = None
    if args.scene is not None:
        path = resolve_scene_path(args.scene)
        _load(str(path))  # a bad scene gets its one-line error before a window opens
    try:
        from .viewer.app import run
    except ImportError as e:
        print(
            f"ballpit: the viewer is not available ({e}); 'ballpit simulate' runs scenes headless",
            file=sys.stderr,
        )
        return EXIT_FAILED
    return int(run(path, record=args.record) or EXIT_OK)


def _render(args: argparse.Namespace) -> int:
    from .scene import resolve_scene_path
    from .writers import OutputError

    path = resolve_scene_path(args.scene)
    world = _load(str(path))
    duration = args.duration or world.scene.duration or 10.0
    out = Path(args.out)
    folder = args.out.endswith(("/", os.sep)) or out.is_dir() or not out.suffix
    if not folder and out.suffix.lower() not in (".gif", ".png"):
        raise OutputError(
            f"{args.out}: --out must be a .gif, a .png or a folder for frames, not {out.suffix!r}"
        )
    try:
        from .viewer.render import render
    except ImportError as e:
        print(f"ballpit: offscreen rendering is not available ({e})", file=sys.stderr)
        return EXIT_FAILED
    written = render(path, out, duration=duration, fps=args.fps, size=args.size, progress=True)
    print(f"wrote {written or out}")
    return EXIT_OK


def _bench(argv: list[str]) -> int:
    try:
        from .bench import main as bench_main
    except ImportError as e:
        print(f"ballpit: the benchmark is not available ({e})", file=sys.stderr)
        return EXIT_FAILED
    return int(bench_main(argv) or EXIT_OK)


def _scenes(args: argparse.Namespace) -> int:
    from .scene import bundled_scenes

    for path in bundled_scenes():
        first = next(
            (ln.lstrip("# ").strip() for ln in path.read_text().splitlines() if ln.startswith("#")), ""
        )
        print(f"{path.stem:<12} {first}")
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
