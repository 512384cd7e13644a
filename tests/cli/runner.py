"""The command line run in this process: ``ballpit(...)`` as the tests call it, without starting Python.

``run_in_process`` calls ``ballpit.cli.main`` with the arguments, in the given working directory, and
hands back what a subprocess would have: the exit status (``SystemExit`` included, as argparse raises
it), stdout and stderr. An exception that escapes ``main`` becomes exit status 1 with its traceback on
stderr, as the interpreter would print it, so "no traceback" checks keep their meaning. Tests of what
only a process has (signals, pipes, the console script, a window, malloc settings) start one instead
(``run_process``).
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


class _Stream(io.TextIOWrapper):
    """A text stream over bytes (so code that writes to ``sys.stdout.buffer`` works), read back as text."""

    def __init__(self) -> None:
        super().__init__(io.BytesIO(), encoding="utf-8", errors="backslashreplace", write_through=True)

    def isatty(self) -> bool:
        return False

    def text(self) -> str:
        self.flush()
        return self.buffer.getvalue().decode("utf-8", errors="replace")  # type: ignore[attr-defined]


def run_in_process(*args: str | Path, cwd: Path = ROOT, **_: object) -> subprocess.CompletedProcess:
    """``ballpit ARGS`` in this process (extra keywords such as ``timeout`` are accepted and ignored)."""
    from ballpit import cli
    from ballpit.cli import commands

    argv = [str(a) for a in args]
    out, err = _Stream(), _Stream()
    here = Path.cwd()
    os.chdir(cwd)
    # the process-wide malloc setting the command line asks for is tested in a process of its own
    # (test_allocator.py); here it would stay with the test process
    keep, commands.keep_freed_memory = commands.keep_freed_memory, lambda: True
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main(argv)
            except SystemExit as e:
                status = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
                if e.code is not None and not isinstance(e.code, int):
                    print(e.code, file=sys.stderr)
            except Exception:
                traceback.print_exc()
                status = 1
    finally:
        commands.keep_freed_memory = keep
        os.chdir(here)
    return subprocess.CompletedProcess(["ballpit", *argv], int(status or 0), out.text(), err.text())


def run_process(*args: str | Path, cwd: Path = ROOT, timeout: float = 120) -> subprocess.CompletedProcess:
    """``python -m ballpit ARGS`` in a process of its own."""
    return subprocess.run(
        [sys.executable, "-m", "ballpit", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=timeout,
    )
