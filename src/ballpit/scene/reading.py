"""Reading a scene file: bytes -> text -> TOML tables, with one-line errors.

``SceneError`` is the one error a scene file gives; the helpers here keep its text on one line
whatever the file holds (escapes made visible, long values shortened). Where a table or key is in
the file is ``lines.LineIndex``'s job.
"""

from __future__ import annotations

import codecs
import re
import tomllib
from pathlib import Path

from ..cli.inputs import InputRefused, open_regular, read_capped

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
    """The file as UTF-8 text (without a byte-order mark); ``SceneError`` naming the reason when it
    cannot be read.

    Only regular files up to ``MAX_BYTES`` are read, opened so that a read cannot wait (inputs.py), so
    a pipe, a device, a kernel file like /proc/kmsg or a huge file can neither block nor fill the memory.
    """
    try:
        with open_regular(path, MAX_BYTES, "a scene file") as f:
            raw = read_capped(f, MAX_BYTES, "a scene file")
    except InputRefused as e:
        raise SceneError(path, str(e)) from None
    except OSError as e:
        raise SceneError(path, f"cannot read: {e.strerror or e}") from None
    if raw.startswith(_UTF16_MARKS):
        raise SceneError(path, "starts with a UTF-16 byte-order mark: save it as UTF-8 text", line=1)
    try:
        return raw.decode("utf-8-sig")  # a UTF-8 byte-order mark (Windows Notepad writes one) is skipped
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise SceneError(path, "not UTF-8 text; is this a scene file?", line=line) from None


_UTF16_MARKS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)  # UTF-32's begin with these too


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
