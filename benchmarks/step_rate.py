"""Free-flight step rate: N balls under RK4, N = 10 … 100,000; steps/s and ns per ball-step.

.venv/bin/python benchmarks/step_rate.py [--sizes 10,100,1000]
"""

import sys

from ballpit.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(["--workload", "free", *sys.argv[1:]]))
