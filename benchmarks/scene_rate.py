"""A bundled scene headless: its first S simulated seconds, timed, as steps per second and real-time
factor (simulated seconds per wall second). The crowded step's targets are read from here:

    .venv/bin/python benchmarks/scene_rate.py pile --seconds 1.5        # RTF >= 1 is the goal
    .venv/bin/python benchmarks/scene_rate.py pile10k --seconds 1.5     # RTF >= 0.25 is the goal
"""

import argparse
import time

from ballpit.scene import read_scene, resolve_scene_path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--seconds", type=float, default=1.5, help="simulated seconds to time")
    args = parser.parse_args()
    scene = read_scene(resolve_scene_path(args.scene))
    world, dt = scene.world, scene.timestep
    steps = round(args.seconds / dt)
    start = time.perf_counter()
    for _ in range(steps):
        world.step(dt)
    wall = time.perf_counter() - start
    print(
        f"{args.scene}: {len(world.spheres)} balls, dt = {dt:.6g} s x {world.substeps} substeps, "
        f"{steps} steps in {wall:.2f} s: {steps / wall:.1f} steps/s, "
        f"real-time factor {args.seconds / wall:.3f}, "
        f"crowded {world.crowded_steps}/{steps}"
    )


if __name__ == "__main__":
    main()
