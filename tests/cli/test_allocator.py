"""The command line keeps freed memory in the process (glibc), so a step's temporaries are not
faulted in from the kernel again every step."""

import platform
import subprocess
import sys

import pytest

GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"

# Allocate and touch a 20 MB array, free it, and print how much of it the process still holds (MB).
PROBE = """
import sys
from ballpit.cli.allocator import keep_freed_memory
if sys.argv[1] == "keep":
    assert keep_freed_memory()
def resident():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 1e6
import numpy as np
before = resident()
a = np.ones(2_500_000)
del a
print(resident() - before)
"""


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_freed_arrays_stay_in_the_process_only_when_asked():
    def held(mode: str) -> float:
        done = subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True)
        return float(done.stdout)

    assert held("default") < 5.0  # glibc hands the 20 MB back at once
    assert held("keep") > 15.0  # kept for the next step's arrays


def test_the_command_line_asks_for_it(monkeypatch):
    from ballpit import cli
    from ballpit.cli import commands

    asked = []
    monkeypatch.setattr(commands, "keep_freed_memory", lambda: asked.append(True) or True)
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    assert asked
