"""Reading a scene file: bytes -> text -> TOML tables, with one-line errors.

``tomllib`` reports line numbers only for syntax errors, so ``LineIndex`` scans the raw text for the
table headers and keys itself; the field readers use it to say which line a bad value is on.
"""

from __future__ import annotations

import re
import stat
import tomllib
from dataclasses import dataclass
from pathlib import Path

SHOWN = 60  # characters: a value or key longer than this is shortened in messages, ending in …
_NAMED = {"\n": "\\n", "\t": "\\t", "\r": "\\r", "\b": "\\b", "\f": "\\f"}
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _visible(c: str, quoting: bool) -> str:
    if quoting and c in '\\"':
        return "\\" + c
    if c.isprintable():
        return c
    return _NAMED.get(c) or (f"\\u{ord(c):04x}" if ord(c) <= 0xFFFF else f"\\U{ord(c):08x}")


def visible(text: str) -> str:
    """``text`` with newlines, terminal escapes and other unprintable characters written as escapes."""
    return "".join(_visible(c, False) for c in text)


def quoted(text: str, limit: int = SHOWN) -> str:
    """``text`` as a TOML basic string, escapes visible, shortened to ``limit`` characters."""
    out, size = ['"'], 1
    for c in text:
        out.append(_visible(c, True))
        size += len(out[-1])
        if size >= limit:
            break
    return shorten("".join(out) + '"', limit)


def shorten(text: str, limit: int = SHOWN) -> str:
    """``text`` cut to ``limit`` characters, the last one ``…``, when it is longer."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def quote_key(key: str) -> str:
    """A key for a message: ``'radius'`` when it is a bare key, else a quoted, shortened string."""
    return f"'{key}'" if _BARE_KEY.fullmatch(key) else quoted(key)


class SceneError(ValueError):
    """A problem with a scene file, as one line naming the file, line, entry, key and value."""

    def __init__(
        self,
        path: Path | str,
        problem: str,
        *,
        line: int | None = None,
        entry: str | None = None,
        key: str | None = None,
    ) -> None:
        self.path = Path(path)
        self.line = line
        self.entry = entry
        self.key = key
        self.problem = problem
        where = visible(str(path))
        parts = [f"{where}:{line}" if line is not None else where]
        if entry:
            parts.append(entry)
        if key:
            parts.append(f"key {quote_key(key)}")
        parts.append(problem)
        super().__init__(": ".join(parts))


def read_toml(path: Path) -> tuple[str, dict]:
    """The file's text and its parsed tables; ``SceneError`` if it cannot be read or parsed."""
    text = read_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise syntax_error(path, text, e) from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise SceneError(path, "values are nested too deeply (arrays or inline tables)") from None
    return text, data


MAX_BYTES = 16 * 1024 * 1024  # a scene file larger than this is refused unread


def read_text(path: Path) -> str:
    """The file as UTF-8 text; ``SceneError`` naming the reason when it cannot be read.

    Only regular files up to ``MAX_BYTES`` are read, so a pipe, a device or a huge file can neither
    block nor fill the memory.
    """
    try:
        info = path.stat()
        if stat.S_ISDIR(info.st_mode):
            raise SceneError(path, "is a directory, not a scene file")
        if not stat.S_ISREG(info.st_mode):
            raise SceneError(path, "not a regular file (a pipe, device or socket)")
        if info.st_size > MAX_BYTES:
            raise SceneError(path, f"{info.st_size} bytes, more than a scene file may have (16 MiB)")
        with path.open("rb") as f:
            raw = f.read(MAX_BYTES + 1)
    except FileNotFoundError:
        raise SceneError(path, "no such file") from None
    except PermissionError:
        raise SceneError(path, "permission denied") from None
    except OSError as e:
        raise SceneError(path, f"cannot read: {e.strerror or e}") from None
    if len(raw) > MAX_BYTES:  # it grew after the check
        raise SceneError(path, "more bytes than a scene file may have (16 MiB)")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise SceneError(path, "not UTF-8 text; is this a scene file?", line=line) from None


_AT_LINE = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")
_AT_END = re.compile(r"\s*\(at end of document\)\s*$")


def syntax_error(path: Path, text: str, e: tomllib.TOMLDecodeError) -> SceneError:
    """A TOML syntax error as a ``SceneError`` on the line where the parser stopped."""
    msg = str(e)
    m = _AT_LINE.search(msg)
    if m:
        problem = f"TOML syntax error: {msg[: m.start()]} (column {m.group(2)})"
        return SceneError(path, problem, line=int(m.group(1)))
    m = _AT_END.search(msg)
    if m:
        # Something left open (an array, a string): point at the last line that has anything on it.
        lines = text.splitlines()
        last = max((i + 1 for i, ln in enumerate(lines) if ln.strip()), default=None)
        return SceneError(path, f"TOML syntax error: {msg[: m.start()]} at the end of the file", line=last)
    return SceneError(path, f"TOML syntax error: {msg}")


# ---------------------------------------------------------------------------------------- line index


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


class LineIndex:
    """Header and key line numbers, found by scanning the raw TOML text.

    Lines inside multi-line strings and multi-line arrays are skipped, so a value that happens to look
    like ``[x]`` or ``key =`` is not mistaken for a header or a key.
    """

    def __init__(self, text: str) -> None:
        self.root = Table(None, {})
        self.tables: dict[str, Table] = {}
        self.arrays: dict[str, list[Table]] = {}
        self.first_header: dict[str, int] = {}  # by a header's first name part: where it first appears
        current = self.root
        depth = 0  # open brackets/braces of a value continuing onto later lines
        multiline: str | None = None  # the closing delimiter of an open multi-line string
        for number, line in enumerate(text.splitlines(), start=1):
            if multiline is None and depth == 0:
                header = _header(line)
                if header:
                    parts = _parts(header[1])
                    name = ".".join(parts)
                    self.first_header.setdefault(parts[0], number)
                    current = Table(number, {})
                    if header[0] == "[[":
                        self.arrays.setdefault(name, []).append(current)
                    else:
                        self.tables.setdefault(name, current)
                    continue
                key = _KEY.match(line)
                if key:
                    current.key_lines.setdefault(".".join(_parts(key.group(1))), number)
            depth, multiline = _scan_line(line, depth, multiline)

    def table(self, name: str) -> Table | None:
        """Where ``[name]`` is, if the file has it."""
        return self.tables.get(name)

    def array_item(self, name: str, index: int) -> Table | None:
        """Where the ``index``-th (from 0) ``[[name]]`` is, if the file has it."""
        items = self.arrays.get(name, [])
        return items[index] if index < len(items) else None


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
