"""Do a landed crowd's velocities tell its motion?

The bench's landing grid (``bench.pile_layout``) in its box, RK4, 1/60 s frames of 4 soft substeps,
restitution and friction 0.25. Over the last 0.1 s of the run it prints, frame by frame, the largest
displacement, the largest reported speed and the largest displacement the velocities do not account
for, |Δx − ½·dt·(v₀ + v₁)|; then the largest move over that 0.1 s against the largest speed reported in
it, how many different velocities the balls report at the end, and the deepest overlap then.

    .venv/bin/python benchmarks/landed_velocities.py --balls 3000 --seconds 2
"""

import argparse

import numpy as np

import ballpit
from ballpit.cli.bench import RADIUS, pile_layout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--balls", type=int, default=3000)
    parser.add_argument("--seconds", type=float, default=2.0)
    args = parser.parse_args()
    centres, half = pile_layout(args.balls)
    world = ballpit.World(integrator="rk4", substeps=4)
    world.add_plane(normal=(0, 1, 0), restitution=0.25, friction=0.25)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -half), normal=normal, restitution=0.25, friction=0.25)
    world.add_spheres(centres, radius=RADIUS, restitution=0.25, friction=0.25)
    dt = 1 / 60
    steps = round(args.seconds / dt)
    watch = steps - round(0.1 / dt)
    mark, fastest = None, 0.0
    for k in range(steps):
        x0, v0 = world.spheres.positions.copy(), world.spheres.velocities.copy()
        if k == watch:
            mark = x0
        world.step(dt)
        if mark is None:
            continue
        x1, v1 = world.spheres.positions, world.spheres.velocities
        speed = float(np.linalg.norm(v1, axis=1).max())
        fastest = max(fastest, speed)
        unexplained = float(np.linalg.norm((x1 - x0) - 0.5 * dt * (v0 + v1), axis=1).max())
        move = float(np.linalg.norm(x1 - x0, axis=1).max())
        told = f"not told by the velocities {unexplained:.2e} m ({unexplained / RADIUS:.3f} r)"
        print(f"t = {world.time:.3f} s: largest move {move:.2e} m, largest |v| {speed:.2e} m/s, {told}")
    x = world.spheres.positions
    moved = float(np.linalg.norm(x - mark, axis=1).max())
    print(f"last 0.1 s: largest move {moved:.2e} m, largest reported speed {fastest:.2e} m/s")
    print(f"different velocities at the end: {len(np.unique(world.spheres.velocities, axis=0))} of {len(x)}")
    order = np.argsort(x[:, 0])
    xs, deepest = x[order], 0.0
    for shift in range(1, 400):  # pairs near in x; a ball has its neighbours within a few hundred there
        d = np.linalg.norm(xs[shift:] - xs[:-shift], axis=1)
        deepest = max(deepest, float(((2 * RADIUS - d) / RADIUS).max()))
    print(f"deepest overlap at {world.time:.2f} s: {deepest:.3f} r")


if __name__ == "__main__":
    main()
