"""Pile workload: balls on a grid 0.11 m apart (r = 0.05 m) falling into a box, dt = 1/240, RK4.

PyBullet runs the same pile side by side when installed (pip install '.[bench]'):

    .venv/bin/python benchmarks/pile.py --sizes 1000,10000 --pybullet --plot scaling.png
"""

import sys

from ballpit.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(["--workload", "pile", *sys.argv[1:]]))
