"""The window thread's own CPU per frame while a scene lands: the Python (and driver) work of a frame
that the physics thread beside it cannot have while the window's thread holds the GIL.

A real window (an X display: Xvfb here) is driven frame by frame in lockstep, each frame 1/33 s of
simulated time, with the panel shown and the pacer held slow as it is while the physics is busy (the
panel built at most 10 times a second, the HUD's text every 0.25 s). The physics of each frame is
stepped inside the frame on the window's thread (lockstep); its CPU time is taken out, so what is
left is the window's: uploads, shadows, uniforms, the panel, the HUD, the copy to the window, the flip.
Each run is a process of its own; the runs of the scenes are taken in turn.

    DISPLAY=:1 .venv/bin/python benchmarks/window_thread_cpu.py --runs 3 pile
    DISPLAY=:1 .venv/bin/python benchmarks/window_thread_cpu.py --runs 3 --ghosts slopes

``--env NAME=VALUE`` sets a variable for the child (PYTHONPATH=another checkout's src, to compare).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CHILD = r"""
import json, os, sys, time
from pyglet.window import key
from ballpit.scene import default_scene_path
from ballpit.viewer.app import Viewer

name, frames, ghosts = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1"
viewer = Viewer(size=(1280, 720), scene_path=default_scene_path().with_name(name + ".toml"))
if ghosts:
    viewer.window.dispatch_event("on_key_press", key.G, 0)
for _ in range(10):
    viewer.pump(1 / 33)
viewer.pacer.slow = True
viewer.window.dispatch_event("on_key_press", key.X, 0)
viewer.pump(1 / 33)
stepping = [0.0]
advance = viewer.physics.advance


def timed_advance(seconds):
    started = time.thread_time()
    try:
        return advance(seconds)
    finally:
        stepping[0] += time.thread_time() - started


viewer.physics.advance = timed_advance
views, started = viewer.views_drawn, time.thread_time()
for _ in range(frames):
    viewer.pump(1 / 33)
total = time.thread_time() - started
print("RESULT " + json.dumps({"window_cpu_ms": 1e3 * (total - stepping[0]) / frames,
                              "physics_cpu_ms": 1e3 * stepping[0] / frames,
                              "views": (viewer.views_drawn - views) / frames}), flush=True)
os._exit(0)
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=["pile"])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--frames", type=int, default=66, help="frames measured from X (1/33 s each)")
    parser.add_argument("--ghosts", action="store_true", help="the integrator ghosts (G) on before X")
    parser.add_argument("--env", action="append", default=[], help="NAME=VALUE for the viewer process")
    args = parser.parse_args(argv)
    env = dict(os.environ)
    env.update(item.split("=", 1) for item in args.env)
    results: dict[str, list[dict]] = {s: [] for s in args.scenes}
    for _ in range(args.runs):
        for scene in args.scenes:
            command = [sys.executable, "-c", CHILD, scene, str(args.frames), "1" if args.ghosts else "0"]
            proc = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
            lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
            if not lines:
                raise RuntimeError(f"{scene}: no result\n{proc.stderr[-2000:]}")
            results[scene].append(json.loads(lines[-1][len("RESULT ") :]))
    load = open("/proc/loadavg").read().split()[0] if os.path.exists("/proc/loadavg") else "?"
    print(f"1280x720, panel shown, ghosts {'on' if args.ghosts else 'off'}, medians of {args.runs} runs, "
          f"load average {load} at the end")  # fmt: skip
    print("| scene | window_cpu_ms | physics_cpu_ms | views |\n|---|---|---|---|")
    for scene, runs in results.items():
        cells = [
            f"{statistics.median(r[c] for r in runs):.2f}"
            for c in ("window_cpu_ms", "physics_cpu_ms", "views")
        ]
        print(f"| {scene} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
