"""Viewer frame time with 5, ~1,000 and 10,000 balls, offscreen through headless EGL (llvmpipe here).

``--quality low`` or ``high`` draws as the window does at that quality (quality.py: MSAA, shadow
detail, and the view drawn at a lower resolution and stretched over the frame); without it, the frame
is drawn at full size with ``--samples``.

Each frame does what the window does: advance the physics by one frame of simulated time (1/60 s at
the scene's fixed timestep), upload the interpolated balls (one instance buffer) and draw planes +
balls (one instanced call). ``glFinish`` after the draw makes the draw time include the GPU (here the
CPU rasteriser). Reports the median milliseconds of each part and the frames per second they allow,
with and without physics (the latter is what a paused or waiting viewer runs at).

    .venv/bin/python benchmarks/viewer_frame_time.py [--size 1280x720] [--frames 40] [--samples 4]
    .venv/bin/python benchmarks/viewer_frame_time.py --skip 0.6 scenes/pile10k.toml   # while it lands
    .venv/bin/python benchmarks/viewer_frame_time.py --quality low   # as the window on llvmpipe
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SCENES = ("slopes.toml", "pile.toml", "pile10k.toml")


def measure(
    scene: Path, size: tuple[int, int], frames: int, samples: int, max_seconds: float, skip: float = 0.0,
    quality: str | None = None,
) -> dict:  # fmt: skip
    from OpenGL import GL

    from ballpit.scene import read_scene
    from ballpit.viewer.camera import Camera
    from ballpit.viewer.render import Offscreen
    from ballpit.viewer.simulation import Simulation

    loaded = read_scene(scene)
    world = loaded.world
    sim = Simulation(loaded, step_budget=math.inf)  # time every step: nothing is dropped
    for _ in range(round(skip / sim.timestep)):  # untimed: e.g. to time a pile landing, not its fall
        sim.world.step(sim.timestep)
    look = sim.appearance
    camera = Camera.looking_at(look.camera_position, look.camera_look_at)
    physics, upload, draw = [], [], []
    with Offscreen(size, 0 if quality else samples) as screen:
        view = None
        if quality:
            from ballpit.viewer.framebuffer import WindowView
            from ballpit.viewer.quality import QUALITIES

            q = QUALITIES[quality]
            screen.renderer.shadows, screen.renderer.shadow_limit = q.shadow_limit > 0, max(q.shadow_limit, 1)
            view = WindowView(q.samples, q.scale)
        screen.feeder.upload(sim)  # warm up: shaders, buffers, first draw
        screen.draw(camera)
        sim.start()
        started = time.perf_counter()
        for _ in range(frames):
            t0 = time.perf_counter()
            sim.advance(1.0 / 60.0)
            t1 = time.perf_counter()
            screen.feeder.upload(sim, eye=camera.position)
            t2 = time.perf_counter()
            if view is None:
                screen.target.bind()
                multisample = screen.target.multisample
                screen.renderer.draw(camera, screen.width, screen.height, multisample=multisample)
            else:  # as the window: into the view's target, then resolved and stretched over the frame
                drawn = view.begin(screen.width, screen.height, screen.target.fbo)
                screen.renderer.draw(camera, *drawn, multisample=view.multisample)
                view.finish(screen.width, screen.height, screen.target.fbo)
            GL.glFinish()
            t3 = time.perf_counter()
            physics.append(t1 - t0)
            upload.append(t2 - t1)
            draw.append(t3 - t2)
            if t3 - started > max_seconds:
                break
        ball_draws = screen.renderer.draws.count("balls")
        if view is not None:
            view.delete()
    med = {
        k: statistics.median(v) * 1000 for k, v in (("physics", physics), ("upload", upload), ("draw", draw))
    }
    total = sum(med.values())
    render_only = med["upload"] + med["draw"]
    return {
        "scene": scene.name, "balls": len(world.spheres), "frames": len(draw), "steps_per_frame":
        round(1 / 60 / sim.timestep), **med, "fps": 1000 / total, "fps_render_only": 1000 / render_only,
        "ball_draw_calls": ball_draws,
    }  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1280x720", help="framebuffer WxH (default 1280x720)")
    parser.add_argument("--frames", type=int, default=40, help="frames per scene (default 40)")
    parser.add_argument("--samples", type=int, default=4, help="MSAA samples, as the window asks (default 4)")
    parser.add_argument("--max-seconds", type=float, default=60.0, help="stop a scene after this long")
    parser.add_argument("--skip", type=float, default=0.0, help="simulated seconds to run untimed first")
    parser.add_argument("--quality", choices=("low", "high"), help="draw as the window does at this quality")
    parser.add_argument("scenes", nargs="*", default=[str(REPO / "scenes" / s) for s in SCENES])
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))

    from ballpit.cli.allocator import keep_freed_memory
    from ballpit.viewer import backend

    keep_freed_memory()  # as `ballpit view` does
    backend.use_headless()
    from OpenGL import GL

    from ballpit.viewer.render import Offscreen

    with Offscreen((16, 16), 0):
        renderer = GL.glGetString(GL.GL_RENDERER).decode()
    drawn = f"quality {args.quality}" if args.quality else f"{args.samples}x MSAA"
    print(
        f"renderer: {renderer}; {width}x{height}, {drawn}; "
        f"medians over up to {args.frames} frames, after {args.skip:g} s untimed"
    )
    header = ("scene", "balls", "physics ms", "upload ms", "draw ms", "FPS", "FPS w/o physics", "ball draws")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for scene in args.scenes:
        r = measure(
            Path(scene), (width, height), args.frames, args.samples, args.max_seconds, args.skip, args.quality
        )
        print(
            f"| {r['scene']} | {r['balls']:,} | {r['physics']:.2f} ({r['steps_per_frame']} steps) | "
            f"{r['upload']:.2f} | {r['draw']:.2f} | {r['fps']:.1f} | {r['fps_render_only']:.1f} | "
            f"{r['ball_draw_calls']} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
