"""The line index: where each table header and key of a scene file is.

``tomllib`` reports line numbers only for syntax errors, so ``LineIndex`` scans the raw text for the
table headers and keys itself; the field readers use it to say which line a bad value is on. Every
scan is linear in the length of a line, whatever the line holds.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass


@dataclass
class Table:
    """Where one table of the file is: its header line and the line of each of its keys."""

    header_line: int | None
    key_lines: dict[str, int]


_NAME_END = re.compile(r"[\[\]#]")
_KEY = re.compile(r"""^\s*("(?:[^"\\]|\\.)*"|'[^']*'|[A-Za-z0-9_-]+)\s*[.=]""")


def _header(line: str) -> tuple[str, str] | None:
    """``("[", name)`` or ``("[[", name)`` when the line is a table header, else None.

    A name ends at the first ``[``, ``]`` or ``#``; after the closing brackets only a comment may
    follow. Linear in the line's length, whatever it holds.
    """
    s = line.lstrip()
    if not s.startswith("["):
        return None
    opener = "[[" if s.startswith("[[") else "["
    rest = s[len(opener) :]
    end = _NAME_END.search(rest)
    if end is None:
        return None
    name, tail = rest[: end.start()].strip(), rest[end.start() :]
    closer = "]" * len(opener)
    if not name or not tail.startswith(closer):
        return None
    after = tail[len(closer) :].lstrip()
    if after and not after.startswith("#"):
        return None
    return opener, name


def _parts(name: str) -> list[str]:
    """A dotted TOML name's parts with their quotes removed: ``a."b.c"`` -> ``a``, ``b.c``.

    Linear in the name's length.
    """
    parts, start, quote, i = [], 0, None, 0
    while i < len(name):
        c = name[i]
        if quote is not None:
            if quote == '"' and c == "\\":
                i += 1
            elif c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif c == ".":
            parts.append(name[start:i])
            start = i + 1
        i += 1
    parts.append(name[start:])
    parts = [p.strip() for p in parts]
    return [p[1:-1] if len(p) >= 2 and p[0] == p[-1] and p[0] in "\"'" else p for p in parts]


def _events(text: str) -> Iterator[tuple[int, str, list[str]]]:
    """The table headers and keys of ``text`` in order: (line, what it is ("[" or "[[" for a header,
    "key"), the name's parts). Lines inside multi-line strings and multi-line arrays are skipped, so a
    value that happens to look like ``[x]`` or ``key =`` is not mistaken for a header or a key."""
    depth = 0  # open brackets/braces of a value continuing onto later lines
    multiline: str | None = None  # the closing delimiter of an open multi-line string
    for number, line in enumerate(text.splitlines(), start=1):
        if multiline is None and depth == 0:
            header = _header(line)
            if header:
                yield number, header[0], _parts(header[1])
                continue
            key = _KEY.match(line)
            if key:
                yield number, "key", _parts(key.group(1))
        depth, multiline = _scan_line(line, depth, multiline)


class LineIndex:
    """Header and key line numbers, found by scanning the raw TOML text (see ``_events``)."""

    def __init__(self, text: str) -> None:
        self.root = Table(None, {})
        self.tables: dict[str, Table] = {}
        self.arrays: dict[str, list[Table]] = {}
        self.first_header: dict[str, int] = {}  # by a header's first name part: where it first appears
        current = self.root
        for number, kind, parts in _events(text):
            if kind == "key":
                current.key_lines.setdefault(".".join(parts), number)
                continue
            name = ".".join(parts)
            self.first_header.setdefault(parts[0], number)
            current = Table(number, {})
            if kind == "[[":
                self.arrays.setdefault(name, []).append(current)
            else:
                self.tables.setdefault(name, current)

    def table(self, name: str) -> Table | None:
        """Where ``[name]`` is, if the file has it."""
        return self.tables.get(name)

    def array_item(self, name: str, index: int) -> Table | None:
        """Where the ``index``-th (from 0) ``[[name]]`` is, if the file has it."""
        items = self.arrays.get(name, [])
        return items[index] if index < len(items) else None


def find_array_item(text: str, name: str, index: int) -> Table | None:
    """Where the ``index``-th (from 0) ``[[name]]`` of ``text`` is, found by one scan that keeps only
    that table: what an error about one of half a million spheres needs, without indexing them all."""
    seen = -1
    found: Table | None = None
    for number, kind, parts in _events(text):
        if kind == "key":
            if found is not None:
                found.key_lines.setdefault(".".join(parts), number)
            continue
        if found is not None:
            break
        if kind == "[[" and ".".join(parts) == name:
            seen += 1
            if seen == index:
                found = Table(number, {})
    return found


def _scan_line(line: str, depth: int, multiline: str | None) -> tuple[int, str | None]:
    """Bracket depth and open multi-line string after one line of TOML."""
    i, n = 0, len(line)
    while i < n:
        if multiline is not None:
            end = _find_closing(line, i, multiline)
            if end < 0:
                return depth, multiline
            i, multiline = end + 3, None
            continue
        c = line[i]
        if c == "#":
            break
        if c in "\"'":
            if line.startswith(c * 3, i):
                multiline = c * 3
                i += 3
                continue
            i = _skip_string(line, i + 1, c)
            continue
        if c in "[{":
            depth += 1
        elif c in "]}":
            depth = max(0, depth - 1)
        i += 1
    return depth, multiline


def _find_closing(line: str, start: int, delim: str) -> int:
    i = start
    while True:
        j = line.find(delim, i)
        if j < 0:
            return -1
        if delim == '"""':
            k = j  # count the backslashes just before the quotes, without copying the line
            while k > 0 and line[k - 1] == "\\":
                k -= 1
            if (j - k) % 2:
                i = j + 1
                continue
        return j


def _skip_string(line: str, i: int, quote: str) -> int:
    while i < len(line):
        if quote == '"' and line[i] == "\\":
            i += 2
            continue
        if line[i] == quote:
            return i + 1
        i += 1
    return i
