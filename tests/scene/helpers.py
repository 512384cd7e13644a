"""Running the command line in this process, as a user would see it: exit status and stderr lines."""

from __future__ import annotations

import gc
import io
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

from ballpit import cli


def run_cli(*args: str | Path) -> tuple[int, list[str]]:
    """Run the command line in this process: (exit status, stderr lines and any warnings)."""
    err, out = io.StringIO(), io.StringIO()
    # objects earlier tests in this worker left to the collector (a subprocess's text pipes, "unclosed
    # file") are collected now, so that their warnings are not taken for this command's
    gc.collect()
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
