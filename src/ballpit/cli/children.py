"""A measurement in a fresh interpreter (the benchmarks' rows): its one line of JSON, or why it failed.

The child runs with ``-P``: the current directory is not put on its path, so a folder named
``ballpit`` there (a clone, seen from the folder above it) cannot shadow the installed package.
"""

from __future__ import annotations

import json
import subprocess
import sys

from .arguments import one_line


def run_child(module: str, args: list[str], timeout: float) -> dict | str:
    """``python -P -m module *args``: the JSON object on the last line of its stdout, or one line
    saying why there is none (the child's last line on stderr, its exit status, or the timeout)."""
    cmd = [sys.executable, "-P", "-m", module, *args]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"no result within {timeout:g} s"
    try:
        if done.returncode != 0:
            raise ValueError
        result = json.loads(done.stdout.strip().splitlines()[-1])
        if not isinstance(result, dict):
            raise ValueError
        return result
    except (ValueError, IndexError):
        why = [line.strip() for line in done.stderr.splitlines() if line.strip()]
        if why:
            return one_line(why[-1], limit=300)
        return f"exit status {done.returncode}, no output" if done.returncode else "it printed no result"
