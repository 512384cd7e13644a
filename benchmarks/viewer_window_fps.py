"""The real window's frame rate, as the title shows it, and the physics' real-time factor beside it: a
viewer on an X display (Xvfb here) run by pyglet's own loop as ``ballpit view`` runs it, each run in a
process of its own, runs of the scenes taken in turn.

    DISPLAY=:1 .venv/bin/python benchmarks/viewer_window_fps.py --runs 5 --size 800x450 pile
    DISPLAY=:1 .venv/bin/python benchmarks/viewer_window_fps.py --runs 3 --escape slopes pile pile10k

Per scene, medians over the runs of:

- ``fps_before_x``: the title's frame rate while the scene waits for X (``--seconds`` long);
- the landing, from X until the simulated clock reaches ``--land`` seconds (pile.toml lands in its
  first 2 s): ``land_fps`` frames per wall second, ``land_rtf`` simulated over wall seconds (1.00 is
  real time; the time is that of the state the window shows, not of the World, which may be stepped
  up to ``stepper.LEAD_SECONDS`` ahead of it), ``hud_rtf`` and ``hud_rtf_min`` the median and
  lowest real-time factor the HUD showed meanwhile (read every 0.25 s from 0.75 s after X);
- ``fps_after_x``, ``steps_per_second`` (of the states shown) and ``real_time_factor`` (the HUD's)
  over ``--seconds`` from one second after the landing;
- with ``--threads``, the CPU each kind of thread used while the pile landed, in cores: the physics
  thread, the integrator ghosts' process (ghostproc.py; ``cpu_ghosts``), the window's (main) thread,
  llvmpipe's rasteriser threads and the rest; ``physics_cpu_per_sim_s`` counts the physics thread and
  the ghosts' process;
- with ``--escape``, Esc, Esc in the middle of a step: from the second key event to the loop's end;
- with ``--video S``, F9 at X and again once the video holds S seconds (S·30 frames): the landing
  columns then cover the recording, and ``video_frames``, ``video_seconds`` are what ffprobe reads
  from the file, ``read_ms`` the window's time per video frame reading pixels back, ``encode_wait``
  the share of the recording the window waited for the encoder (its queue full).
- ``panel_ms_before`` and ``panel_ms_land``: the mean time the panel took per frame (building it with
  ImGui and handing its triangles to GL, on the window's thread) before X and while the scene lands;
  ``panel_cpu_ms_*`` the same in the window thread's CPU time (without the waits for the GIL and for a
  core that the wall time holds while the physics thread runs).
  ``--panel off`` opens the viewer with the panel hidden (F4), for a paired comparison of frame rates.
- ``--ghosts on`` presses G as the window opens (a second before the frames before X are counted): the
  three integrator ghosts drop with the main run and are stepped and drawn beside it throughout, in a
  process of their own (``--env BALLPIT_GHOSTS=thread``: on the physics thread, as before, to compare).

``--env NAME=VALUE`` sets a variable for the child before anything loads (LP_NUM_THREADS, ...); the
load average of the machine at the start is printed, since the two cores may be shared.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

CHILD = r"""
import json, os, re, statistics, subprocess, sys, time
import pyglet
from pyglet.window import key
from ballpit.scene import default_scene_path
from ballpit.viewer.app import Viewer

name, seconds, quality, escape = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4] == "1"
width, height, land = int(sys.argv[5]), int(sys.argv[6]), float(sys.argv[7])
video = float(sys.argv[8])
panel = sys.argv[9] == "on"
ghosts = sys.argv[10] == "on"
path = default_scene_path().with_name(name + ".toml")
viewer = Viewer(size=(width, height), scene_path=path, quality=quality, panel=panel)
sim = viewer.sim
TICK = os.sysconf("SC_CLK_TCK")


def thread_cpu():
    # CPU seconds of each thread of this process, by kind
    thread = getattr(viewer.physics, "_thread", None)
    physics = thread.native_id if thread is not None else None
    out = {"physics": 0.0, "main": 0.0, "llvmpipe": 0.0, "other": 0.0}
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        comm = stat[stat.index("(") + 1 : stat.rindex(")")]
        fields = stat[stat.rindex(")") + 2 :].split()
        cpu = (int(fields[11]) + int(fields[12])) / TICK
        if int(tid) == physics:
            out["physics"] += cpu
        elif int(tid) == os.getpid():
            out["main"] += cpu
        elif comm.startswith("llvmpipe"):
            out["llvmpipe"] += cpu
        else:
            out["other"] += cpu
    child = getattr(getattr(viewer, "physics", None), "child_cpu", None)  # the ghosts' process, if any
    out["ghosts"] = child() if child is not None else 0.0
    try:  # the physics thread's time waiting for a core (the rest of its wall time not on one: asleep)
        with open(f"/proc/self/task/{physics}/schedstat") as f:
            out["physics_queued"] = int(f.read().split()[1]) / 1e9
    except (OSError, TypeError):
        out["physics_queued"] = 0.0
    return out


def hud_factor():
    found = re.search(r"real-time factor (\d+\.\d+)", viewer.hud.text)
    return float(found.group(1)) if found else None


out = {}
state = {"phase": "warm", "at": time.perf_counter() + 1.0, "ghosts": ghosts}


def mark():
    return viewer.frames, sim_steps(), time.perf_counter()


def sim_steps():
    # the step of the state the window shows (the physics may have stepped it long before: held before X)
    shown = viewer.physics.shown.step
    return shown if shown is not None else sim.steps_total


def sim_time():
    # the simulated time of the state the window shows now (the physics may have stepped ahead of it)
    return viewer.physics.shown.time


def tick(_dt):
    now = time.perf_counter()
    phase = state["phase"]
    if phase == "warm" and state["ghosts"]:  # G first (their process starts meanwhile): they drop with X
        state["ghosts"] = False
        viewer.window.dispatch_event("on_key_press", key.G, 0)
    if phase == "warm" and now >= state["at"]:
        state.update(phase="before", at=now + seconds, mark=mark(), cpu=thread_cpu())
    elif phase == "before" and now >= state["at"]:
        frames, _, t = state["mark"]
        out["fps_before_x"] = (viewer.frames - frames) / (now - t)
        cpu = thread_cpu()
        for kind in ("main", "llvmpipe"):  # CPU ms a frame: the view is drawn once and shown again
            used = cpu[kind] - state["cpu"][kind]
            out[f"{kind}_ms_frame_before"] = used * 1e3 / max(viewer.frames - frames, 1)
        out["panel_ms_before"] = viewer.panel.cost_ms() if panel else None
        out["panel_cpu_ms_before"] = viewer.panel.cost_ms(cpu=True) if panel else None
        viewer.panel.seconds.clear()
        viewer.panel.cpu_seconds.clear()
        viewer.window.dispatch_event("on_key_press", key.X, 0)
        if video:
            viewer.window.dispatch_event("on_key_press", key.F9, 0)
        idle = getattr(viewer.physics, "idle_seconds", 0.0)
        captured = getattr(viewer.physics, "capture_seconds", 0.0)
        state.update(phase="landing", mark=mark(), cpu=thread_cpu(), samples=[], sample_at=now + 0.75,
                     idle=idle, captured=captured)
    elif phase == "landing":
        frames, _, t = state["mark"]
        if now >= state["sample_at"]:
            state["sample_at"] = now + 0.25
            state["samples"].append(hud_factor())
        simulated = sim_time()
        recorded = viewer.video.writer.frames if video and viewer.video.writer is not None else 0
        done = recorded >= round(video * viewer.video.fps) if video else simulated >= land
        if done or now - t > 6 * max(land, video) + 5:
            if video:
                writer = viewer.video.writer
                viewer.window.dispatch_event("on_key_press", key.F9, 0)
                probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-show_entries",
                                        "stream=nb_read_frames,duration", "-of", "json",
                                        str(viewer.video.last_video.path)], capture_output=True, text=True)
                stream = json.loads(probe.stdout)["streams"][0]
                out["video_frames"] = int(stream["nb_read_frames"])
                out["video_seconds"] = float(stream["duration"])
                out["read_ms"] = viewer.video.read_seconds / max(recorded, 1) * 1e3
                out["encode_wait"] = writer.wait_seconds / (now - t)
            wall = now - t
            out["land_fps"] = (viewer.frames - frames) / wall
            out["panel_ms_land"] = viewer.panel.cost_ms() if panel else None
            out["panel_cpu_ms_land"] = viewer.panel.cost_ms(cpu=True) if panel else None
            out["land_rtf"] = simulated / wall
            samples = [s for s in state["samples"] if s is not None]
            out["hud_rtf"] = statistics.median(samples) if samples else None
            out["hud_rtf_min"] = min(samples) if samples else None
            cpu = thread_cpu()
            for kind, used in cpu.items():
                out[f"cpu_{kind}"] = (used - state["cpu"][kind]) / wall
            for kind in ("main", "llvmpipe"):  # CPU ms a frame, the view drawn at every frame
                used = cpu[kind] - state["cpu"][kind]
                out[f"{kind}_ms_frame_land"] = used * 1e3 / max(viewer.frames - frames, 1)
            physics = out["cpu_physics"] + out["cpu_ghosts"]
            out["physics_cpu_per_sim_s"] = physics * wall / max(simulated, 1e-9)
            out["physics_asleep"] = 1.0 - out["cpu_physics"] - out["cpu_physics_queued"]
            out["physics_idle"] = (getattr(viewer.physics, "idle_seconds", 0.0) - state["idle"]) / wall
            captured = getattr(viewer.physics, "capture_seconds", 0.0) - state["captured"]
            out["physics_capture"] = captured / wall
            state.update(phase="settle", at=now + 1.0)
    elif phase == "settle" and now >= state["at"]:
        state.update(phase="after", at=now + seconds, mark=mark())
    elif phase == "after" and now >= state["at"]:
        frames, steps, t = state["mark"]
        out["fps_after_x"] = (viewer.frames - frames) / (now - t)
        out["steps_per_second"] = (sim_steps() - steps) / (now - t)
        out["real_time_factor"] = hud_factor()
        if escape:
            viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
            state.update(phase="escape", at=now + 10)
        else:
            pyglet.clock.unschedule(tick)
            viewer.close()
    elif phase == "escape":
        busy = getattr(viewer.physics, "busy", None)
        if (busy() if busy is not None else viewer.physics.lock.locked()) or now >= state["at"]:
            pyglet.clock.unschedule(tick)  # a step is in progress: the worst moment to quit
            state["pressed"] = time.perf_counter()
            viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)


pyglet.clock.schedule_interval(tick, 0.01)
viewer.run()
if escape:
    out["escape_seconds"] = time.perf_counter() - state["pressed"]
print("RESULT " + json.dumps(out), flush=True)
os._exit(0)  # the physics may be mid-step (a daemon): do not wait for it
"""

HEADLESS = r"""
import json, sys, time
from ballpit.scene import default_scene_path, read_scene

name, land = sys.argv[1], float(sys.argv[2])
scene = read_scene(default_scene_path().with_name(name + ".toml"))
world, dt = scene.world, scene.timestep
wall, cpu = time.perf_counter(), time.process_time()
for _ in range(round(land / dt)):
    world.step(dt)
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
print("RESULT " + json.dumps({"land_rtf": world.time / wall, "physics_cpu_per_sim_s": cpu / world.time}))
"""

COLUMNS = ["fps_before_x", "land_fps", "land_rtf", "hud_rtf", "hud_rtf_min", "fps_after_x",
           "steps_per_second", "real_time_factor", "panel_ms_before", "panel_ms_land"]  # fmt: skip
COLUMNS += ["panel_cpu_ms_before", "panel_cpu_ms_land"]
VIDEO_COLUMNS = ["video_frames", "video_seconds", "read_ms", "encode_wait"]
THREAD_COLUMNS = ["cpu_physics", "cpu_ghosts", "cpu_main", "cpu_llvmpipe", "cpu_other",
                  "main_ms_frame_before", "llvmpipe_ms_frame_before", "main_ms_frame_land",
                  "llvmpipe_ms_frame_land",
                  "physics_cpu_per_sim_s", "cpu_physics_queued", "physics_asleep", "physics_idle",
                  "physics_capture"]  # fmt: skip


def one_run(scene: str, args: argparse.Namespace, size: tuple[int, int], env: dict[str, str],
            headless: bool = False) -> dict:  # fmt: skip
    """One viewer process on ``scene`` (or, ``headless``, its landing stepped with no window); returns
    its measurements."""
    command = [sys.executable, "-c", CHILD, scene, str(args.seconds), args.quality,
               "1" if args.escape else "0", str(size[0]), str(size[1]), str(args.land),
               str(args.video)]  # fmt: skip
    command += [args.panel, args.ghosts]
    if headless:
        command = [sys.executable, "-c", HEADLESS, scene, str(args.land)]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if not lines:
        raise RuntimeError(f"{scene}: no result\n{proc.stderr[-2000:]}")
    return json.loads(lines[-1][len("RESULT ") :])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=["slopes", "pile", "pile10k", "seesaw"])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--land", type=float, default=2.0, help="simulated seconds the landing lasts")
    parser.add_argument("--size", default="1280x720", help="window size, WIDTHxHEIGHT")
    parser.add_argument("--quality", default="auto", help="auto, low or high (the viewer's option)")
    parser.add_argument("--panel", default="on", choices=("on", "off"), help="the panel shown or hidden")
    parser.add_argument(
        "--ghosts", default="off", choices=("on", "off"), help="the integrator ghosts (G) on before X"
    )
    parser.add_argument("--escape", action="store_true", help="also time Esc, Esc in the middle of a step")
    parser.add_argument("--threads", action="store_true", help="CPU per kind of thread while it lands")
    parser.add_argument("--env", action="append", default=[], help="NAME=VALUE for the viewer process")
    parser.add_argument("--json", action="store_true", help="also print every run's numbers")
    parser.add_argument(
        "--video",
        type=float,
        default=0.0,
        metavar="S",
        help="record S seconds of MP4 (F9) from X; the landing columns cover it",
    )
    parser.add_argument("--headless", action="store_true", help="also step each landing with no window")
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))
    env = dict(os.environ)
    env.update(item.split("=", 1) for item in args.env)
    load = open("/proc/loadavg").read().split()[0] if os.path.exists("/proc/loadavg") else "?"
    results: dict[str, list[dict]] = {s: [] for s in args.scenes}
    if args.headless:
        results.update({f"{s} (headless)": [] for s in args.scenes})
    for _ in range(args.runs):
        for scene in args.scenes:
            results[scene].append(one_run(scene, args, size, env))
            if args.headless:
                results[f"{scene} (headless)"].append(one_run(scene, args, size, env, headless=True))
    extra = f", {' '.join(args.env)}" if args.env else ""
    print(f"{time.strftime('%Y-%m-%d %H:%M')}, {size[0]}x{size[1]}, medians of {args.runs} runs, "
          f"quality {args.quality}, panel {args.panel}, ghosts {args.ghosts}{extra}, "
          f"load average {load} at the start")  # fmt: skip
    cols = COLUMNS + (THREAD_COLUMNS if args.threads else []) + (["escape_seconds"] if args.escape else [])
    cols += VIDEO_COLUMNS if args.video else []
    print("| scene | " + " | ".join(cols) + " |\n|---|" + "---|" * len(cols))
    for scene, runs in results.items():
        cells = []
        for c in cols:
            values = [r[c] for r in runs if r.get(c) is not None]
            cells.append(f"{statistics.median(values):.2f}" if values else "-")
        print(f"| {scene} | " + " | ".join(cells) + " |", flush=True)
        if args.json:
            for r in runs:
                print(
                    "  " + json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in r.items()})
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
