"""``python -m ballpit.cli.peers ENGINE N STEPS [KEY=VALUE ...]``: one landing, its result as JSON."""

import sys

from .rounds import child_main

if __name__ == "__main__":
    sys.exit(child_main(sys.argv[1:]))
