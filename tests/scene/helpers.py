"""Running the command line in this process, as a user would see it: exit status and stderr lines."""

from __future__ import annotations

import gc
import io
import os
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

from ballpit import cli

_collected_for: str | None = None  # the test before whose first command the collector last ran


def run_cli(*args: str | Path) -> tuple[int, list[str]]:
    """Run the command line in this process: (exit status, stderr lines and any warnings)."""
    global _collected_for
    err, out = io.StringIO(), io.StringIO()
    # Objects earlier tests in this worker left to the collector (a subprocess's text pipes, "unclosed
    # file") are collected before a test's first command, so that their warnings are not taken for its
    # own. Once a test, not once a command: a full collection costs 50-150 ms in a worker that has
    # imported the viewer, and the fuzz test runs 600 commands.
    test = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" (", 1)[0]
    if test != _collected_for or not test:
        gc.collect()
        _collected_for = test
    with redirect_stderr(err), redirect_stdout(out), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = cli.main([str(a) for a in args])
        except SystemExit as e:  # argparse
            code = e.code
    return code, err.getvalue().splitlines() + [f"warning: {w.message}" for w in caught]


def refused(path: Path, *fragments: str) -> str:
    """Assert that check and simulate both refuse ``path`` with one line; returns that line."""
    lines_seen = []
    for command in (["check", path], ["simulate", path, "--duration", "0.01", "--quiet"]):
        code, lines = run_cli(*command)
        assert code == 2 and len(lines) == 1, (command[0], code, lines[:5])
        line = lines[0]
        assert line.startswith(f"ballpit: {path}"), line
        for fragment in fragments:
            assert fragment in line, line
        lines_seen.append(line)
    assert lines_seen[0] == lines_seen[1]
    return lines_seen[0]
