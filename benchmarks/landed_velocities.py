"""Do a landed crowd's velocities tell its motion?

The bench's landing grid (``bench.pile_layout``) in its box, RK4, 1/60 s frames of 4 soft substeps,
restitution and friction 0.25. Over the last 0.1 s of the run it prints, frame by frame, the largest
displacement, the largest reported speed and the largest displacement the velocities do not account
for, |Δx − ½·dt·(v₀ + v₁)|; then the largest move over that 0.1 s against the largest speed reported in
it, how many different velocities the balls report at the end, and the deepest overlap then.

    .venv/bin/python benchmarks/landed_velocities.py --balls 3000 --seconds 2
    .venv/bin/python benchmarks/landed_velocities.py --balls 1000 --seconds 3 --no-frame-guard

In a landed pile the soft springs lift the balls every frame, more than their motion relative to the
centre of mass can pay for, and the frame's energy guard (``energy_guard.hold_frame``) takes that
back. It once did so by setting every frame ball's velocity to the centre of mass's and taking the
rising balls back by positions, which hid the motion: 3,000 balls, 1.9 to 2.0 s, one velocity for
every ball (1.4e-3 m/s) while balls moved 0.013 r a frame that the velocities did not tell.
Now it takes the rising balls back by at most half the slop, scales the motion relative to the centre
of mass, and where that cannot pay, makes each ball's velocity its move over the frame (the rising
balls taken back to pay for it): 3,000 balls, 1.9 to 2.0 s, at most 0.002 r a frame not told, 1,902
different velocities, the deepest overlap 0.067 r (0.073 r before); 1,000 balls at 3.5 s, 0.001 r
and 0.010 r. A 10,000-ball pile lands more slowly (0.28 m/s at 2 s, deepest overlap 0.22 r against
0.11 r before, with every ball at one velocity then).
"""

import argparse

import numpy as np

import ballpit
from ballpit.cli.peers.landing import RADIUS, pile_layout
from ballpit.physics.core.settings import EnergyGuards


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--balls", type=int, default=3000)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--no-frame-guard", action="store_true", help="switch energy_guard.hold_frame off")
    args = parser.parse_args()
    centres, half = pile_layout(args.balls)
    world = ballpit.World(integrator="rk4", substeps=4)
    world.add_plane(normal=(0, 1, 0), restitution=0.25, friction=0.25)
    for normal in ((1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)):
        world.add_plane(position=np.multiply(normal, -half), normal=normal, restitution=0.25, friction=0.25)
    world.add_spheres(centres, radius=RADIUS, restitution=0.25, friction=0.25)
    if args.no_frame_guard:
        world.model.guards = EnergyGuards(frame=False)
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
