"""The physics reads in small pieces: no module over MODULE_LINES lines and no function over
FUNCTION_LINES (an ``ast`` reading of every module under src/ballpit/physics, docstrings included)."""

from __future__ import annotations

import ast
from pathlib import Path

PHYSICS = Path(__file__).resolve().parents[2] / "src" / "ballpit" / "physics"
MODULE_LINES = 350
FUNCTION_LINES = 80


def too_long(source: str, limit: int = FUNCTION_LINES) -> list[tuple[str, int]]:
    """Each function (or method) of ``source`` longer than ``limit`` lines, from its ``def`` line
    (decorators left out) to its last, with its length."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            length = node.end_lineno - node.lineno + 1
            if length > limit:
                found.append((node.name, length))
    return found


def test_the_reader_counts_a_function_from_its_def_to_its_last_line():
    body = "".join(f"    x{i} = {i}\n" for i in range(80))
    assert too_long(f"def short():\n{body[: -len('    x79 = 79') - 1]}") == []
    assert too_long(f"@decorated\ndef exactly_eighty():\n{body[: -len('    x79 = 79') - 1]}\n") == []
    assert too_long(f"class C:\n    def longer():\n    {body.replace(chr(10), chr(10) + '    ')}") == [
        ("longer", 81)
    ]


def test_no_physics_module_is_over_350_lines():
    modules = sorted(PHYSICS.rglob("*.py"))
    assert len(modules) > 40
    long = {
        str(p.relative_to(PHYSICS)): n
        for p in modules
        if (n := len(p.read_text().splitlines())) > MODULE_LINES
    }
    assert not long, long


def test_no_physics_function_is_over_80_lines():
    long = {
        str(p.relative_to(PHYSICS)): f
        for p in sorted(PHYSICS.rglob("*.py"))
        if (f := too_long(p.read_text()))
    }
    assert not long, long
