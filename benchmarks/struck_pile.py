"""A ball written fast inside a sleeping pile: the split steps with hundreds of impact intervals.

The pile is tests/physics/test_robustness.py's ``sleeping_pile`` (200 balls of 6, 8 and 10 cm settled
asleep in a closed 2 m box, RK4, 1/60 s, 4 substeps). Each write sets one ball's velocity (the bottom
one, the top one, the middle one up at 1,000 m/s and down at 10,000 m/s, as the robustness test does)
and takes 30 steps of 1/60 s; a step with such a ball in it splits into hundreds of intervals.

    .venv/bin/python benchmarks/struck_pile.py [WRITE ...] [--save FILE] [--against FILE] [--profile]

prints each write's CPU seconds. ``--save`` keeps every write's final positions, velocities and spins
in an .npz file; ``--against`` says, write by write, whether the final state is bit for bit the one an
earlier run saved (np.array_equal): a change meant to keep the physics must print "same" four times.
``--profile`` prints cProfile's top functions of each write. WRITE picks writes by name (bottom, top,
up, down; all four by default).
"""

import argparse
import cProfile
import pstats
import time

import numpy as np

import ballpit

# name: which ball (by height) is written, and its new velocity (m/s)
WRITES = {
    "bottom": ("bottom", (0, -1e3, 0)),
    "top": ("top", (0, -1e3, 0)),
    "up": ("middle", (0, 1e3, 0)),
    "down": ("middle", (0, -1e4, 0)),
}


def sleeping_pile() -> ballpit.World:
    """The robustness test's pile: 200 balls dropped into a closed 2 m box, stepped until all sleep."""
    rng = np.random.default_rng(0)
    world = ballpit.World(sleep=True, integrator="rk4", substeps=4)
    for normal, position in [
        ((0, 1, 0), (0, 0, 0)),
        ((0, -1, 0), (0, 2, 0)),
        ((1, 0, 0), (-1, 1, 0)),
        ((-1, 0, 0), (1, 1, 0)),
        ((0, 0, 1), (0, 1, -1)),
        ((0, 0, -1), (0, 1, 1)),
    ]:
        world.add_plane(
            position=position, normal=normal, restitution=0.5, friction=0.5, rolling_friction=0.02
        )
    n, k, spacing = 200, 7, 0.21
    r = rng.choice([0.06, 0.08, 0.1], n)
    cells = np.stack(np.meshgrid(np.arange(k), np.arange(k + 1), np.arange(k), indexing="ij"), -1)
    cells = cells.reshape(-1, 3)[rng.permutation(k * (k + 1) * k)[:n]]
    positions = (cells - [(k - 1) / 2, 0, (k - 1) / 2]) * spacing + [0, 0.12, 0]
    positions += rng.uniform(-1, 1, positions.shape) * 0.02
    world.add_spheres(positions, radius=r, restitution=0.6, mass=r**3 * 100, rolling_friction=0.02)
    while not world.asleep.all():
        world.step(1 / 60)
    return world


def write(pile: ballpit.World, where: str, velocity: tuple, profile: bool) -> tuple[float, ballpit.World]:
    """The pile with one ball written to ``velocity``, stepped 30 times; CPU seconds taken, and the world."""
    world = pile.copy()
    order = np.argsort(world.spheres.positions[:, 1])
    ball = int(order[{"bottom": 0, "middle": len(order) // 2, "top": -1}[where]])
    world.spheres[ball].velocity = velocity
    prof = cProfile.Profile() if profile else None
    start = time.process_time()
    if prof:
        prof.enable()
    for _ in range(30):
        world.step(1 / 60)
    if prof:
        prof.disable()
    taken = time.process_time() - start
    if prof:
        pstats.Stats(prof).sort_stats("tottime").print_stats(30)
    return taken, world


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("writes", nargs="*", metavar="WRITE", help=", ".join(WRITES))
    parser.add_argument("--save", help="keep every write's final state in this .npz file")
    parser.add_argument("--against", help="compare every write's final state with this .npz file's")
    parser.add_argument("--profile", action="store_true", help="print cProfile's top functions")
    args = parser.parse_args()
    unknown = [name for name in args.writes if name not in WRITES]
    if unknown:
        parser.error(f"no write named {unknown[0]!r} (the writes: {', '.join(WRITES)})")
    start = time.process_time()
    pile = sleeping_pile()
    print(f"settled: {time.process_time() - start:.2f} s CPU, t = {pile.time:.4f} s")
    earlier = np.load(args.against) if args.against else None
    kept = {}
    for name in args.writes or WRITES:
        taken, world = write(pile, *WRITES[name], args.profile)
        final = {
            f"{name}_x": world.spheres.positions,
            f"{name}_v": world.spheres.velocities,
            f"{name}_w": world.spheres.angular_velocities,
        }
        kept.update(final)
        line = f"{name}: {taken:.2f} s CPU"
        if earlier is not None:
            same = all(np.array_equal(value, earlier[key]) for key, value in final.items())
            line += "; final state " + ("same" if same else "DIFFERENT")
        print(line, flush=True)
    if args.save:
        np.savez(args.save, **kept)


if __name__ == "__main__":
    main()
