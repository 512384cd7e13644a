"""The real window's frame rate, as the title shows it: a 1280x720 viewer on an X display (Xvfb here),
before X and while the drop runs, each run in a process of its own, runs of the scenes taken in turn.

    DISPLAY=:1 .venv/bin/python benchmarks/viewer_window_fps.py --runs 3 slopes pile pile10k seesaw

Prints, per scene, the median frames per second over the runs before X and after it (from one second
after X, for ``--seconds``), the physics' steps per second then, and the real-time factor the HUD
showed. With ``--escape`` it also times Esc, Esc in the middle of a step: from the second key event to
the window closed.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

CHILD = r"""
import json, re, sys, time
from pyglet.window import key
from ballpit.scene import default_scene_path
from ballpit.viewer.app import Viewer

name, seconds, quality, escape = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4] == "1"
path = default_scene_path().with_name(name + ".toml")
try:
    viewer = Viewer(size=(1280, 720), scene_path=path, quality=quality)
except TypeError:  # a viewer without the quality option
    viewer = Viewer(size=(1280, 720), scene_path=path)
sim = viewer.sim

def run_for(s):
    end = time.perf_counter() + s
    while time.perf_counter() < end:
        viewer.pump()

def rate(s):
    frames, steps, t = viewer.frames, sim.steps_total, time.perf_counter()
    run_for(s)
    wall = time.perf_counter() - t
    return (viewer.frames - frames) / wall, (sim.steps_total - steps) / wall

run_for(1.0)
out = {}
out["fps_before_x"], _ = rate(seconds)
viewer.window.dispatch_event("on_key_press", key.X, 0)
run_for(1.0)
out["fps_after_x"], out["steps_per_second"] = rate(seconds)
factor = re.search(r"real-time factor (\d+\.\d+)", viewer.hud.text)
out["real_time_factor"] = float(factor.group(1)) if factor else None
if escape:
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    viewer.pump()
    lock = getattr(getattr(viewer, "physics", None), "lock", None)
    if lock is not None:  # wait for a step in progress: the worst moment to quit
        end = time.perf_counter() + 10
        while not lock.locked() and time.perf_counter() < end:
            viewer.pump()
    pressed = time.perf_counter()
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    while not viewer.closed:
        viewer.pump()
    viewer.pump()
    out["escape_seconds"] = time.perf_counter() - pressed
else:
    viewer.close()
    viewer.pump()
print("RESULT " + json.dumps(out), flush=True)
"""


def one_run(scene: str, seconds: float, quality: str, escape: bool) -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, scene, str(seconds), quality, "1" if escape else "0"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if not lines:
        raise RuntimeError(f"{scene}: no result\n{proc.stderr[-2000:]}")
    return json.loads(lines[-1][len("RESULT ") :])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=["slopes", "pile", "pile10k", "seesaw"])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--quality", default="auto", help="auto, low or high (the viewer's option)")
    parser.add_argument("--escape", action="store_true", help="also time Esc, Esc in the middle of a step")
    args = parser.parse_args(argv)
    results: dict[str, list[dict]] = {s: [] for s in args.scenes}
    for _ in range(args.runs):
        for scene in args.scenes:
            results[scene].append(one_run(scene, args.seconds, args.quality, args.escape))
    print(f"{time.strftime('%Y-%m-%d %H:%M')}, medians of {args.runs} runs, quality {args.quality}")
    cols = ["fps_before_x", "fps_after_x", "steps_per_second", "real_time_factor"]
    if args.escape:
        cols.append("escape_seconds")
    print("| scene | " + " | ".join(cols) + " |\n|---|" + "---|" * len(cols))
    for scene, runs in results.items():
        cells = []
        for c in cols:
            values = [r[c] for r in runs if r.get(c) is not None]
            cells.append(f"{statistics.median(values):.2f}" if values else "-")
        print(f"| {scene} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
