"""The tuning constants (settings.py): every one says what it is for, with its unit, in a comment
above it or beside it; none is a bare number."""

from __future__ import annotations

import ast
from pathlib import Path

from ballpit.physics.core import settings

SETTINGS = Path(settings.__file__)


def test_every_constant_has_a_comment_above_or_beside_it():
    lines = SETTINGS.read_text().splitlines()
    bare = []
    for node in ast.parse(SETTINGS.read_text()).body:
        if isinstance(node, ast.Assign | ast.AnnAssign):
            line = lines[node.lineno - 1]
            above = lines[node.lineno - 2].lstrip() if node.lineno > 1 else ""
            if (
                "#" not in line
                and not above.startswith("#")
                and not _follows_a_commented_one(lines, node.lineno)
            ):
                bare.append(line)
    assert not bare, bare


def _follows_a_commented_one(lines: list[str], lineno: int) -> bool:
    """A constant directly below another that a comment explains (a pair like SOLVE_SWEEPS and
    RELAX_SWEEPS shares its comment)."""
    k = lineno - 2
    while k >= 0 and lines[k] and not lines[k].startswith("#") and "=" in lines[k]:
        k -= 1
    return k >= 0 and lines[k].startswith("#")


def test_the_constants_are_numbers_and_positive():
    values = {k: v for k, v in vars(settings).items() if k.isupper()}
    assert len(values) > 50
    assert all(isinstance(v, int | float) and v > 0 for v in values.values()), values
