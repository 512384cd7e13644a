"""Physics beside the drawing: frame rate and step rate with the physics inline, on a thread, or in a
process, while a scene lands. Offscreen through headless EGL (llvmpipe here), at the window's size.

Each mode draws frames for ``--seconds`` of wall time while the scene steps at its fixed timestep:

- ``inline``: today's loop before the change: each frame steps what it owes (at most 50 ms of steps,
  as the viewer's step budget), then draws;
- ``thread``: a daemon thread steps without pause and hands over a copy of positions and orientations
  under a lock; the loop draws the latest copy (``--switch`` sets Python's GIL switch interval);
- ``process``: a child process steps and writes positions and orientations into shared memory under
  a lock; the loop draws the latest copy.

Reports frames/s and physics steps/s for each mode.

    .venv/bin/python benchmarks/physics_beside_drawing.py scenes/pile.toml --skip 0.4 --seconds 6
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import sys
import threading
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def _landing_world(scene: Path, skip: float):
    from ballpit.scene import read_scene

    loaded = read_scene(scene)
    dt = loaded.timestep
    for _ in range(round(skip / dt)):
        loaded.world.step(dt)
    return loaded, dt


def _child(scene: str, skip: float, shared_pos, shared_quat, lock, steps, stop, ready) -> None:
    loaded, dt = _landing_world(Path(scene), skip)
    world = loaded.world
    n = len(world.spheres)
    pos = np.frombuffer(shared_pos.get_obj(), dtype=float).reshape(n, 3)
    quat = np.frombuffer(shared_quat.get_obj(), dtype=float).reshape(n, 4)
    ready.set()
    while not stop.is_set():
        world.step(dt)
        with lock:
            pos[:] = world.spheres.positions
            quat[:] = world.spheres.orientations
        steps.value += 1


def run(mode: str, scene: Path, skip: float, seconds: float, size: tuple[int, int], switch: float) -> dict:
    from ballpit.viewer.camera import Camera
    from ballpit.viewer.render import Offscreen
    from ballpit.viewer.simulation import Simulation

    loaded, dt = _landing_world(scene, skip)
    world = loaded.world
    sim = Simulation(loaded)
    look = sim.appearance
    camera = Camera.looking_at(look.camera_position, look.camera_look_at)
    radii = np.asarray(world.spheres.radii)
    n = len(radii)
    sys.setswitchinterval(switch)
    steps = 0
    with Offscreen(size, 0) as screen:
        screen.feeder.upload(sim)
        screen.draw(camera)
        latest = [np.array(world.spheres.positions), np.array(world.spheres.orientations)]
        lock = threading.Lock()
        stop = threading.Event()
        worker = None
        counter = [0]
        if mode == "thread":

            def loop() -> None:
                while not stop.is_set():
                    world.step(dt)
                    pos, quat = np.array(world.spheres.positions), np.array(world.spheres.orientations)
                    with lock:
                        latest[:] = [pos, quat]
                    counter[0] += 1

            worker = threading.Thread(target=loop, daemon=True)
            worker.start()
        elif mode == "process":
            ctx = mp.get_context("spawn")
            shared_pos, shared_quat = ctx.Array("d", n * 3), ctx.Array("d", n * 4)
            plock, pstop, ready, psteps = ctx.Lock(), ctx.Event(), ctx.Event(), ctx.Value("q", 0)
            worker = ctx.Process(
                target=_child, args=(str(scene), skip, shared_pos, shared_quat, plock, psteps, pstop, ready)
            )
            worker.start()
            ready.wait(60)
            ppos = np.frombuffer(shared_pos.get_obj(), dtype=float).reshape(n, 3)
            pquat = np.frombuffer(shared_quat.get_obj(), dtype=float).reshape(n, 4)
        frames = 0
        started = time.perf_counter()
        last = started
        while time.perf_counter() - started < seconds:
            now = time.perf_counter()
            if mode == "inline":
                sim.start()
                steps += sim.advance(now - last)
                pos, quat = sim.render_state()
            elif mode == "thread":
                with lock:
                    pos, quat = latest
            else:
                with plock:
                    pos, quat = ppos.copy(), pquat.copy()
            last = now
            screen.renderer.upload_balls(pos, quat, radii, look.sphere_colors, camera.position)
            screen.draw(camera)
            frames += 1
        wall = time.perf_counter() - started
        if mode == "thread":
            stop.set()
            steps = counter[0]
        elif mode == "process":
            steps = psteps.value
            pstop.set()
            worker.join(5)
    return {"mode": mode, "fps": frames / wall, "steps_per_s": steps / wall, "balls": n}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=str(REPO / "scenes" / "pile.toml"))
    parser.add_argument("--skip", type=float, default=0.4, help="simulated seconds run first (untimed)")
    parser.add_argument("--seconds", type=float, default=6.0, help="wall seconds per mode")
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--modes", default="inline,thread,process")
    parser.add_argument("--switch", type=float, default=0.005, help="sys.setswitchinterval for threads")
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))
    from ballpit.viewer import backend

    backend.use_headless()
    print(f"{Path(args.scene).name}, {width}x{height}, no MSAA, switch interval {args.switch * 1000:g} ms")
    print("| mode | balls | frames/s | physics steps/s |\n|---|---|---|---|")
    for mode in args.modes.split(","):
        r = run(mode, Path(args.scene), args.skip, args.seconds, (width, height), args.switch)
        print(f"| {r['mode']} | {r['balls']:,} | {r['fps']:.1f} | {r['steps_per_s']:.1f} |", flush=True)
    return 0 if math.isfinite(args.seconds) else 1


if __name__ == "__main__":
    sys.exit(main())
