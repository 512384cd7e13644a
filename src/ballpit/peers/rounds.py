"""Each landing in a fresh interpreter, the engines taking turns round after round (A B C A B C ...).

A child runs ``python -P -m ballpit.peers ENGINE N STEPS [KEY=VALUE ...]`` and prints its ``Landed``
as one line of JSON. Taking turns spreads a busy machine's slow spells over every engine, and a fresh
process gives none of them another's caches or heap.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable, Iterator
from dataclasses import asdict

from ..allocator import keep_freed_memory
from ..arguments import one_line
from .engines import ENGINES
from .measure import Landed, land


def child_main(argv: list[str]) -> int:
    """The child's side: land one engine and print the result as JSON on the last line of stdout."""
    keep_freed_memory()  # as ``ballpit`` runs the engine (allocator.py); the same for every engine here
    engine, n, steps, *pairs = argv
    overrides = dict(pair.split("=", 1) for pair in pairs)
    print(json.dumps(asdict(land(engine, int(n), int(steps), overrides))))
    return 0


def land_isolated(
    engine: str, n: int, steps: int, timeout: float, overrides: dict[str, str] | None = None
) -> Landed | str:
    """``land`` in a fresh interpreter: its ``Landed``, or one line saying why it failed.

    ``-P`` keeps the current directory off the child's path, so a folder named ``ballpit`` there (a
    clone, seen from the folder above it) cannot shadow the installed package.
    """
    pairs = [f"{k}={v}" for k, v in (overrides or {}).items()]
    cmd = [sys.executable, "-P", "-m", "ballpit.peers", engine, str(n), str(steps), *pairs]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"no result within {timeout:g} s"
    try:
        if done.returncode != 0:
            raise ValueError
        return Landed(**json.loads(done.stdout.strip().splitlines()[-1]))
    except (ValueError, IndexError, TypeError):
        why = [line.strip() for line in done.stderr.splitlines() if line.strip()]
        return one_line(why[-1], limit=300) if why else f"exit status {done.returncode}, no output"


def interleaved(
    engines: list[str],
    sizes: list[int],
    steps: int,
    rounds: int,
    timeout: float,
    land_one: Callable[..., Landed | str] = land_isolated,
) -> Iterator[tuple[int, Landed | str, str, int]]:
    """For each size, ``rounds`` rounds of every engine in turn; yields (round, result, engine, n)."""
    for n in sizes:
        for r in range(1, rounds + 1):
            for engine in engines:
                yield r, land_one(engine, n, steps, timeout), engine, n


def installed_peers(engines: list[str]) -> tuple[list[str], list[str]]:
    """``engines`` split into those whose package is installed and those whose is not."""
    have = [e for e in engines if ENGINES[e].installed()]
    return have, [e for e in engines if e not in have]
