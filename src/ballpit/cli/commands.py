"""The ``ballpit`` commands: view, check, simulate, compare, render, bench, scenes (``cli.main`` runs
them, its stop handlers already in place).

Bad input of any kind (a bad scene, a missing file, a bad option) exits with status 2 and one line
on stderr naming the file and the problem, never a traceback. Heavy modules (the viewer, the
renderer, the benchmark) are imported only by the command that needs them.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from .. import __version__
from . import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, raise_if_stopped
from .allocator import keep_freed_memory
from .arguments import OneLineParser, one_line
from .arguments import count as _count
from .arguments import positive as _positive
from .arguments import size as _size

if TYPE_CHECKING:
    from ..physics import World

COMMANDS = ("view", "check", "simulate", "compare", "render", "bench", "scenes")


class UsageError(ValueError):
    """A command line whose options are each fine but that cannot be run (a run of 10¹² steps)."""


def _add_run_arguments(p: argparse.ArgumentParser) -> None:
    """The scene, --duration and --dt that simulate and compare share."""
    p.add_argument("scene", help="a scene file, or a bundled scene's name")
    p.add_argument("--duration", type=_positive, metavar="S", help="seconds to simulate (default: the "
                   "scene's [world] duration, else 10)")  # fmt: skip
    p.add_argument(
        "--dt", type=_positive, metavar="S", help="seconds per step (default: the scene's timestep)"
    )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser for every command (``bench`` passes its arguments straight through)."""
    from ..physics.dynamics.integrators import INTEGRATOR_NAMES, INTEGRATORS

    labels = [integrator.label for integrator in INTEGRATORS.values()]
    integrator_labels = ", ".join(labels[:-1]) + " and " + labels[-1]  # "Euler, RK2, RK4 and ..."

    parser = OneLineParser(
        prog="ballpit",
        description="Balls, slopes, spin and impacts: a physics sandbox with a viewer and a headless runner.",
        epilog="With no command, or just a scene file, ballpit opens the viewer.",
    )
    parser.add_argument("--version", action="version", version=f"ballpit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("view", help="open the viewer on SCENE (default: the bundled slopes demo)")
    p.add_argument("scene", nargs="?", help="a scene file, or a bundled scene's name")
    p.add_argument(
        "--replay",
        type=Path,
        metavar="FILE",
        help="play a trajectory (.npz or .csv) written by 'simulate --out' or '--record'; "
        "the scene gives the planes, radii and colours",
    )
    p.add_argument("--record", type=Path, metavar="FILE", help="when the window closes, write every step "
                   "it showed to FILE (.npz or .csv, simulate's trajectory columns)")  # fmt: skip
    p.add_argument("--quality", choices=("auto", "low", "high"), default="auto",
                   help="drawing quality: low (no MSAA, cheap shadows, the view at half resolution) "
                   "or high; auto (default) is low on a software renderer such as llvmpipe; F3 "
                   "switches live")  # fmt: skip
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
    _add_run_arguments(p)
    p.add_argument("--integrator", choices=INTEGRATOR_NAMES, help="override the scene's integrator")
    p.add_argument("--out", type=Path, metavar="FILE", help="trajectory file, .csv or .npz")
    p.add_argument("--events", type=Path, metavar="FILE", help="contact events file, .csv or .npz")
    p.add_argument(
        "--events-kind",
        choices=("impacts", "all"),
        default="impacts",
        help="impacts (default): a row when a contact starts (a bounce, a collision, a landing), not "
        "for each step it rests or rolls on; all: every contact of every step, sleeping balls' resting "
        "contacts included",
    )
    p.add_argument("--every", type=_count, default=1, metavar="K", help="record every K-th step (default 1)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--plot", type=Path, metavar="FILE", help="plot kinetic, potential and total energy "
                   "over time: .png, .svg or .pdf")  # fmt: skip
    p.add_argument("--profile", action="store_true", help="print where the step's time went, stage by "
                   "stage, with intervals, pairs and contacts per step")  # fmt: skip
    p.set_defaults(handler=_simulate)

    p = sub.add_parser(
        "compare",
        help=f"run a scene under {integrator_labels} and compare energy drift and end positions",
        description=f"Run the scene under {integrator_labels} (each from its initial state) and RK4 at "
        "a quarter of the step as a reference; print each one's total-energy drift and how far its balls "
        "end from the reference's.",
    )
    _add_run_arguments(p)
    p.add_argument("--plot", type=Path, metavar="FILE", help="plot each integrator's total-energy drift "
                   "over time: .png, .svg or .pdf")  # fmt: skip
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=_compare)

    p = sub.add_parser("render", help="render a scene offscreen to an MP4, a GIF or a folder of PNG frames")
    p.add_argument("scene", help="a scene file, or a bundled scene's name")
    p.add_argument(
        "--out",
        required=True,
        metavar="PATH",
        help="demo.mp4 (needs the video extra), demo.gif, frame.png, or a folder for PNG frames",
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


def run(argv: Sequence[str] | None) -> int:
    """Parse ``argv`` (``sys.argv[1:]`` when None) and run its command; returns the exit status."""
    keep_freed_memory()
    args_list = list(sys.argv[1:] if argv is None else argv)
    if args_list and args_list[0] == "bench":
        return _bench(args_list[1:])
    if not args_list or (args_list[0] not in COMMANDS and _looks_like_scene(args_list[0])):
        args_list = ["view", *args_list]
    parser = build_parser()
    args = parser.parse_args(args_list)
    from ..scene import SceneError
    from .writers import OutputError, OutputFailed

    try:
        return int(args.handler(args) or EXIT_OK)
    except (SceneError, OutputError, UsageError) as e:
        print(f"ballpit: {one_line(str(e))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OutputFailed as e:
        print(f"ballpit: {one_line(str(e))}; nothing was written", file=sys.stderr)
        return EXIT_FAILED


def _looks_like_scene(arg: str) -> bool:
    return not arg.startswith("-") and (arg.endswith(".toml") or Path(arg).is_file())


def _load(scene_arg: str):
    from ..scene import read_scene, resolve_scene_path

    return read_scene(resolve_scene_path(scene_arg))


def _check(args: argparse.Namespace) -> int:
    info = _load(args.scene)
    world = info.world
    duration = f", suggested duration {info.duration:g} s" if info.duration else ""
    print(
        f"{info.path}: ok: {len(world.spheres)} balls, {len(world.planes)} planes, {world.integrator}, "
        f"timestep {info.timestep * 1000:.4g} ms{duration}"
    )
    return EXIT_OK


class StepTotals:
    """Adds up ``World.profile`` after every step of a run (``simulate --profile``), passing the world
    on to another observer (the energy plot) if there is one."""

    def __init__(self, then: Callable[[World], None] | None) -> None:
        from ..physics.core.profile import RunProfile

        self.totals = RunProfile()
        self.then = then
        self._started = False

    def observe(self, world: World) -> None:
        if self._started:  # the first call comes before the first step
            self.totals.add(world.profile)
        self._started = True
        if self.then is not None:
            self.then(world)


def _simulate(args: argparse.Namespace) -> int:
    from .simulate import MAX_STEPS, format_summary, run, step_count, step_longer_than_run
    from .trajectory import TrajectoryWriter
    from .writers import EventWriter, OutputError

    info = _load(args.scene)
    world = info.world
    if args.integrator:
        world.integrator = args.integrator
    dt = args.dt or info.timestep
    duration = args.duration or info.duration or 10.0
    source = f"--dt {args.dt:g}" if args.dt else f"{info.path}: timestep {dt:g} s"
    too_long = step_longer_than_run(duration, dt)
    if too_long:
        raise UsageError(f"{source}: {too_long}")
    if not step_count(duration, dt) <= MAX_STEPS:
        raise UsageError(
            f"{source}: {duration:g} s in steps of {dt:g} s is {step_count(duration, dt):.3g} steps; "
            f"the limit is {MAX_STEPS:.0e} (use a larger step or a shorter --duration)"
        )
    if args.out is not None and args.events is not None and args.out.resolve() == args.events.resolve():
        raise OutputError(f"{args.out}: --out and --events must be different files")
    writers: list = []
    try:
        from .plots import energy_plot  # opened first: a bad --plot path fails before the run

        plot = energy_plot(
            args.plot, f"{info.name}: energy ({world.integrator}, steps of {dt * 1000:.4g} ms)"
        )
        writers += [plot] if plot is not None else []
        trajectory = events = None
        if args.out is not None:
            trajectory = TrajectoryWriter(args.out, len(world.spheres))
            writers.append(trajectory)
        if args.events is not None:
            events = EventWriter(args.events)
            writers.append(events)
        profile = StepTotals(plot.record if plot is not None else None) if args.profile else None
        try:
            summary = run(
                world,
                duration,
                dt,
                observe=profile.observe if profile is not None else plot.record if plot is not None else None,
                every=args.every,
                trajectory=trajectory,
                events=events,
                events_kind=args.events_kind,
                progress=not args.quiet,
                name=info.name,
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
        if plot is not None:
            print(f"  wrote {args.plot} (energies at {len(plot.record)} times)")
    if profile is not None:
        print(f"step profile: mean per step over {profile.totals.steps} steps ({world.integrator})")
        for line in profile.totals.lines():
            print(f"  {line}")
        if events is not None:
            what = "impacts" if args.events_kind == "impacts" else "contacts"
            print(f"  wrote {args.events} ({events.count} {what})")
    return EXIT_OK


def _compare(args: argparse.Namespace) -> int:
    from .compare import main as compare_main

    return compare_main(args)


def _view(args: argparse.Namespace) -> int:
    from ..scene import resolve_scene_path
    from .writers import check_output_path

    if args.record is not None:
        check_output_path(args.record, "--record")  # a bad path is a one-line error before a window opens
    if args.record is not None and args.replay is not None:
        raise UsageError("--record and --replay cannot be used together")
    path = world = None
    if args.scene is not None:
        from ..scene.loading import unknown_scene

        unknown = unknown_scene(args.scene)
        if unknown is not None:
            print(f"ballpit: {unknown}", file=sys.stderr)
            return EXIT_BAD_INPUT
        path = resolve_scene_path(args.scene)
        world = _load(str(path)).world  # a bad scene gets its one-line error before a window opens
    trajectory = None
    if args.replay is not None:
        from .trajectory import TrajectoryError, read_trajectory

        world = world if world is not None else _load("slopes").world
        try:
            trajectory = read_trajectory(args.replay, n_balls=len(world.spheres))
        except TrajectoryError as e:
            print(f"ballpit: {e}", file=sys.stderr)
            return EXIT_BAD_INPUT
    try:
        from ..viewer.app import run
    except ImportError as e:
        print(
            f"ballpit: the viewer is not available ({e}); 'ballpit simulate' runs scenes headless",
            file=sys.stderr,
        )
        return EXIT_FAILED
    return int(run(path, trajectory=trajectory, record=args.record, quality=args.quality) or EXIT_OK)


def _render(args: argparse.Namespace) -> int:
    from ..scene import resolve_scene_path
    from .writers import OutputError, OutputFailed, check_name_lengths, check_output_place

    path = resolve_scene_path(args.scene)
    duration = args.duration or _load(str(path)).duration or 10.0
    out = Path(args.out)
    check_name_lengths(out, "--out")
    folder = args.out.endswith(("/", os.sep)) or out.is_dir() or not out.suffix
    if not folder and out.suffix.lower() not in (".gif", ".png", ".mp4"):
        raise OutputError(
            f"{args.out}: --out must be a .mp4, a .gif, a .png or a folder for frames, not {out.suffix!r}"
        )
    check_output_place(out, "--out", folder)
    if not folder and out.suffix.lower() == ".mp4":
        _check_video(args.out, args.size)
    try:
        from ..viewer.render import frame_count, render
    except ImportError as e:
        print(f"ballpit: offscreen rendering is not available ({e})", file=sys.stderr)
        return EXIT_FAILED
    kind = "frames" if folder else out.suffix.lower()[1:]
    try:
        frame_count(duration, args.fps, args.size, kind)
    except ValueError as e:
        raise UsageError(f"render --duration {duration:g}: {e}") from None
    created = [out] if folder and not out.exists() else []  # a folder for frames is made; nothing above it
    before = _render_files(out, folder)
    try:
        _check_writable(out if folder else out.parent, args.out)
        written = render(
            path,
            out,
            duration=duration,
            fps=args.fps,
            size=args.size,
            progress=True,
            each_frame=raise_if_stopped,
        )
    except OSError as e:  # the disk filled, or the file could not be made at the end
        _remove_render_output(out, folder, before, created)
        raise OutputFailed(f"{args.out}: cannot write: {e.strerror or e}") from None
    except BaseException:  # interrupted, stopped or failed: no frames or half-written file from this run
        _remove_render_output(out, folder, before, created)
        raise
    print(f"wrote {written or out}")
    return EXIT_OK


def _check_video(raw: str, size: tuple[int, int]) -> None:
    """OutputError or UsageError unless an MP4 of ``size`` can be written: PyAV installed and the size
    even each way (H.264's 4:2:0 colour)."""
    from ..viewer.mp4 import MISSING_AV, have_av
    from .writers import OutputError

    if not have_av():
        raise OutputError(f"{raw}: --out .mp4 {MISSING_AV}")
    if size[0] % 2 or size[1] % 2:
        raise UsageError(
            f"render --size {size[0]}x{size[1]}: an MP4's width and height must be even (4:2:0 colour)"
        )


def _check_writable(folder: Path, raw: str) -> None:
    """OutputError, before any frame is drawn, unless ``folder`` can be made (its parent is there) and a
    file written in it."""
    from .writers import OutputError

    try:
        folder.mkdir(exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError as e:
        raise OutputError(f"{raw}: --out: cannot write in {str(folder)!r}: {e.strerror or e}") from None


def _render_files(out: Path, folder: bool) -> dict[Path, tuple[int, int]]:
    """The files a render to ``out`` writes that exist now, with their (mtime, inode)."""
    files = sorted(out.glob("frame_*.png")) if folder and out.is_dir() else [out]
    found = {}
    for file in files:
        try:
            st = file.stat()
        except OSError:
            continue
        found[file] = (st.st_mtime_ns, st.st_ino)
    return found


def _remove_render_output(
    out: Path, folder: bool, before: dict[Path, tuple[int, int]], created: list[Path]
) -> None:
    """Remove what a stopped render wrote (files new or changed since ``before``) and the folder it made."""
    for file, stamp in _render_files(out, folder).items():
        if before.get(file) != stamp:
            try:
                file.unlink()
            except OSError:
                pass
    for made in created:  # only if empty
        try:
            made.rmdir()
        except OSError:
            break


def _bench(argv: list[str]) -> int:
    try:
        from .bench import main as bench_main
    except ImportError as e:
        print(f"ballpit: the benchmark is not available ({e})", file=sys.stderr)
        return EXIT_FAILED
    return int(bench_main(argv) or EXIT_OK)


def _scenes(args: argparse.Namespace) -> int:
    from ..scene import bundled_scenes

    for path in bundled_scenes():
        first = next(
            (ln.lstrip("# ").strip() for ln in path.read_text().splitlines() if ln.startswith("#")), ""
        )
        print(f"{path.stem:<12} {first}")
    return EXIT_OK
