"""Each landing in a fresh interpreter, the engines taking turns round after round (A B C A B C ...).

A child runs ``python -P -m ballpit.cli.peers ENGINE N STEPS [KEY=VALUE ...]`` and prints its ``Landed``
as one line of JSON. Taking turns spreads a busy machine's slow spells over every engine, and a fresh
process gives none of them another's caches or heap.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import asdict

from ..allocator import keep_freed_memory
from ..arguments import one_line
from ..children import run_child
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
    """``land`` in a fresh interpreter (``children.py``): its ``Landed``, or one line saying why it failed."""
    pairs = [f"{k}={v}" for k, v in (overrides or {}).items()]
    result = run_child("ballpit.cli.peers", [engine, str(n), str(steps), *pairs], timeout)
    if isinstance(result, str):
        return result
    try:
        return Landed(**result)
    except TypeError:
        return f"an unexpected result: {one_line(str(result), limit=200)}"


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
