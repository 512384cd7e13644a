"""The peers' settings tried on the landing grid at 240 Hz, to find each one's fastest stable settings.

Each setting lands the grid in its own process, the settings taking turns over the rounds (as in
``ballpit bench --peers``); "stable" is every ball still in the box and the deepest overlap well under
a radius. The defaults in ``ballpit/cli/peers/mujoco_engine.py`` and ``pybullet_engine.py`` are the
fastest stable ones found here (docs/benchmarks.md has the figures).

    .venv/bin/python benchmarks/peer_settings.py [--balls 1000] [--steps 480] [--rounds 2] [--only mujoco]
    .venv/bin/python benchmarks/peer_settings.py --numbers 1,7,8,11,12,13   # the iteration counts
"""

import argparse
import statistics

from ballpit.cli.peers.engines import ENGINES
from ballpit.cli.peers.rounds import land_isolated

# MuJoCo's settings are varied from implicitfast, elliptic cones, CG, 100 iterations (MuJoCo's own
# iteration count), PyBullet's from rigid bodies at 50 iterations (PyBullet's own); the defaults in
# ballpit/cli/peers are entries 8 and 12.
M100 = {"iterations": "100"}
TRIED = [
    ("mujoco", "implicitfast, elliptic, CG, 100 iterations", M100),
    ("mujoco", "Euler, elliptic, CG, 100 iterations", {**M100, "integrator": "Euler"}),
    ("mujoco", "implicitfast, pyramidal, CG, 100 iterations", {**M100, "cone": "pyramidal"}),
    ("mujoco", "implicitfast, elliptic, PGS, 100 iterations", {**M100, "solver": "PGS"}),
    (
        "mujoco",
        "implicitfast, pyramidal, PGS, 100 iterations",
        {**M100, "cone": "pyramidal", "solver": "PGS"},
    ),
    ("mujoco", "implicitfast, elliptic, CG, 100 iterations, tolerance 1e-6", {**M100, "tolerance": "1e-6"}),
    ("mujoco", "implicitfast, elliptic, CG, 20 iterations", {"iterations": "20"}),
    ("mujoco", "implicitfast, elliptic, CG, 10 iterations (the default here)", {"iterations": "10"}),
    ("mujoco", "implicitfast, elliptic, Newton (MuJoCo's default solver)", {**M100, "solver": "Newton"}),
    ("mujoco", "implicitfast, elliptic, CG, 100 iterations, solref 0.01 s", {**M100, "timeconst": "0.01"}),
    ("pybullet", "rigid bodies, 50 iterations (PyBullet's default)", {"solver_iterations": "50"}),
    ("pybullet", "rigid bodies, 20 iterations (the default here)", {"solver_iterations": "20"}),
    ("pybullet", "rigid bodies, 10 iterations (Bullet's own default)", {"solver_iterations": "10"}),
    ("pybullet", "rigid bodies, 4 iterations", {"solver_iterations": "4"}),
    (
        "pybullet",
        "multibodies, 50 iterations (PyBullet's default body)",
        {"solver_iterations": "50", "maximal_coordinates": "false"},
    ),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--balls", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=480)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds allowed per run")
    parser.add_argument("--only", choices=sorted({engine for engine, _, _ in TRIED}))
    parser.add_argument("--numbers", help="comma-separated: run only these settings (1 is the first above)")
    args = parser.parse_args()
    tried = [t for t in TRIED if args.only in (None, t[0])]
    if args.numbers:
        tried = [TRIED[int(k) - 1] for k in args.numbers.split(",")]
    rates: dict[str, list[float]] = {label: [] for _, label, _ in tried}
    last = {}
    for r in range(1, args.rounds + 1):
        for engine, label, overrides in tried:
            result = land_isolated(engine, args.balls, args.steps, args.timeout, overrides)
            if isinstance(result, str):
                print(f"round {r}  {ENGINES[engine].label:8} {label}: failed: {result}", flush=True)
                continue
            rates[label].append(result.steps_per_second)
            last[label] = result
            print(
                f"round {r}  {ENGINES[engine].label:8} {label}: {result.steps_per_second:.1f} steps/s, "
                f"overlap {result.max_overlap:.3f} r, max speed at end {result.final_speed:.4f} m/s, "
                f"inside {result.inside}/{result.n}, bounce e {result.bounce:.3f}",
                flush=True,
            )
    print(f"\n{args.balls} balls, the first {args.steps} steps of 1/240 s, median of {args.rounds} rounds:")
    for engine, label, _ in tried:
        if label in last:
            r = last[label]
            print(
                f"{ENGINES[engine].label:8} {label:58} {statistics.median(rates[label]):8.1f} steps/s  "
                f"overlap {r.max_overlap:.3f} r  speed {r.final_speed:.4f} m/s  inside {r.inside}/{r.n}"
            )
        else:
            print(f"{ENGINES[engine].label:8} {label:58}   no result within {args.timeout:g} s")


if __name__ == "__main__":
    main()
