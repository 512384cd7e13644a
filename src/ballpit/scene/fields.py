"""Typed field readers: one table of a scene file, read key by key into checked Python/NumPy values.

Every reader raises a one-line ``SceneError`` naming the file, the line, the entry (``sphere #3``), the
key and the bad value, so the user can find and fix it without reading a traceback.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from .colours import hex_to_rgb
from .lines import Table
from .reading import SHOWN, SceneError, quote_key, quoted, shorten, visible


def show(value: object, limit: int = SHOWN) -> str:
    """A value as it would be written in TOML, for error messages: on one line, with unprintable
    characters escaped, shortened to ``limit`` characters (nesting past 8 levels as ``[…]``)."""
    out, size = [], 0
    for piece in _pieces(value, 0):
        out.append(piece)
        size += len(piece)
        if size > limit:
            break
    return shorten("".join(out), limit)


def _pieces(value: object, depth: int) -> Iterator[str]:
    """``show``'s text in pieces, so a huge value is never written out whole."""
    if depth > 8 and isinstance(value, list | dict):
        yield "[…]" if isinstance(value, list) else "{…}"
    elif isinstance(value, bool):
        yield "true" if value else "false"
    elif isinstance(value, float):
        if math.isnan(value):
            yield "nan"
        elif math.isinf(value):
            yield "inf" if value > 0 else "-inf"
        else:
            yield repr(value)
    elif isinstance(value, str):
        yield quoted(value)
    elif isinstance(value, list):
        yield "["
        for i, v in enumerate(value):
            yield ", " if i else ""
            yield from _pieces(v, depth + 1)
        yield "]"
    elif isinstance(value, dict):
        yield "{"
        for i, (k, v) in enumerate(value.items()):
            yield (", " if i else "") + (k if _BARE.fullmatch(k) else quoted(k)) + " = "
            yield from _pieces(v, depth + 1)
        yield "}"
    else:
        yield visible(str(value))


def is_number(value: object) -> bool:
    """An int or float from TOML (``true`` is not a number)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def did_you_mean(word: str, options: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest option, or "" when none is close."""
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


_BARE = re.compile(r"[A-Za-z0-9_-]+")
_COLOR_SHAPE = 'must be "#rrggbb" or [r, g, b] with components 0..1'
# The range of every number a scene file gives (lengths in m, masses in kg, speeds in m/s, ...), and
# the least a size, mass or time may be. Within it, whatever the physics forms from the numbers (m·r²,
# 1/(m·r²), m·v², a position over a ball's size) stays finite and well away from overflow.
LARGEST = 1e9
SMALLEST = 1e-9


class Entry:
    """One table of the file under validation: typed getters that raise ``SceneError`` with context.

    A getter returns its ``default`` when the key is absent; ``data`` is the parsed table, ``where``
    the table's place in the file (None when the line index could not find it), or how to find it:
    looked for only when an error names a line.
    """

    def __init__(
        self, path: Path, label: str, data: dict, where: Table | Callable[[], Table | None] | None
    ) -> None:
        self.path = path
        self.label = label
        self.data = data
        self._where = where

    @property
    def where(self) -> Table | None:
        if callable(self._where):
            self._where = self._where()
        return self._where

    def line(self, key: str | None = None) -> int | None:
        """The line of ``key``, else of the table's header, else None."""
        where = self.where
        if where is None:
            return None
        if key is not None and key in where.key_lines:
            return where.key_lines[key]
        return where.header_line

    def error(self, key: str | None, problem: str, value: object = ...) -> SceneError:
        """A ``SceneError`` about ``key`` of this entry, quoting ``value`` when one is given."""
        if value is not ...:
            problem = f"{problem}, got {show(value)}"
        return SceneError(self.path, problem, line=self.line(key), entry=self.label, key=key)

    def check_keys(self, allowed: Iterable[str]) -> None:
        """Refuse the first key not in ``allowed``, suggesting the closest one."""
        allowed = list(allowed)
        for key in self.data:
            if key not in allowed:
                hint = did_you_mean(key, allowed)
                raise SceneError(
                    self.path, f"unknown key {quote_key(key)}{hint}", line=self.line(key), entry=self.label
                )

    def require(self, key: str) -> None:
        """Refuse the entry when ``key`` is missing."""
        if key not in self.data:
            raise self.error(None, f"missing required key '{key}'")

    def number(
        self,
        key: str,
        default: float | None,
        *,
        positive: bool = False,
        nonnegative: bool = False,
        within: tuple[float, float] | None = None,
    ) -> float | None:
        """A number within ±1e9 (optionally > 0, then at least 1e-9, ≥ 0, or ``within`` a range) as a
        float."""
        if key not in self.data:
            return default
        value = self.data[key]
        if not is_number(value):
            raise self.error(key, "must be a number", value)
        bound = "between 1e-9 and 1e9" if positive else f"between {'0' if nonnegative else '-1e9'} and 1e9"
        (x,) = self._floats(key, [value], value, f"must be {bound}")
        if not math.isfinite(x):
            raise self.error(key, "must be finite", value)
        if positive and x <= 0:
            raise self.error(key, "must be positive", value)
        if nonnegative and x < 0:
            raise self.error(key, "must not be negative", value)
        if within is not None and not within[0] <= x <= within[1]:
            raise self.error(key, f"must be between {within[0]:g} and {within[1]:g}", value)
        if (positive and not SMALLEST <= x) or abs(x) > LARGEST:
            raise self.error(key, f"must be {bound}", value)
        return x

    def _floats(self, key: str, items: list, whole: object, bound: str) -> list[float]:
        """``items`` (numbers) as floats; an integer too large for a float is refused as beyond ``bound``."""
        try:
            return [float(v) for v in items]
        except OverflowError:
            raise self.error(key, bound, whole) from None

    def integer(self, key: str, default: int, *, minimum: int = 0, maximum: int | None = None) -> int:
        """A whole number (``true`` is not one) of at least ``minimum`` (and at most ``maximum``)."""
        if key not in self.data:
            return default
        value = self.data[key]
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, "must be a whole number", value)
        if value < minimum:
            raise self.error(key, f"must be at least {minimum}", value)
        if maximum is not None and value > maximum:
            raise self.error(key, f"must be at most {maximum:,}", value)
        return value

    def boolean(self, key: str, default: bool) -> bool:
        """``true`` or ``false``."""
        if key not in self.data:
            return default
        value = self.data[key]
        if not isinstance(value, bool):
            raise self.error(key, "must be true or false", value)
        return value

    def vector(self, key: str, default: object, length: int = 3) -> np.ndarray | None:
        """A list of ``length`` finite numbers as a float array (``default`` converted when absent)."""
        if key not in self.data:
            return None if default is None else np.array(default, dtype=float)
        value = self.data[key]
        if not isinstance(value, list) or not all(is_number(v) for v in value):
            raise self.error(key, f"must be a list of {length} numbers", value)
        if len(value) != length:
            raise self.error(key, f"must have {length} components, not {len(value)}", value)
        bound = "components must be between -1e9 and 1e9"
        floats = self._floats(key, value, value, bound)  # checked in Python: a scene may have a million
        if not all(math.isfinite(x) for x in floats):
            raise self.error(key, "must be finite", value)
        if not all(-LARGEST <= x <= LARGEST for x in floats):
            raise self.error(key, bound, value)
        return np.array(floats)

    def nonzero_vector(self, key: str, length: int = 3) -> np.ndarray | None:
        """A vector that must not be zero (a direction); None when absent."""
        arr = self.vector(key, None, length)
        if arr is not None and float(np.linalg.norm(arr)) < 1e-12:
            raise self.error(key, "must not be the zero vector", self.data[key])
        return arr

    def extents(self, key: str, count: int) -> np.ndarray | None:
        """A positive finite number, or a list of ``count`` of them, as ``count`` floats."""
        if key not in self.data:
            return None
        value = self.data[key]
        items = value if isinstance(value, list) else [value]
        shape = "a number" if count == 1 else f"a number or a list of {count} numbers"
        if not all(is_number(v) for v in items) or (isinstance(value, list) and len(value) != count):
            raise self.error(key, f"must be {shape}", value)
        arr = np.array(self._floats(key, items, value, "must be between 1e-9 and 1e9"))
        if not np.isfinite(arr).all():
            raise self.error(key, "must be finite", value)
        if (arr <= 0).any():
            raise self.error(key, "must be positive", value)
        if ((arr < SMALLEST) | (arr > LARGEST)).any():
            raise self.error(key, "must be between 1e-9 and 1e9", value)
        return np.broadcast_to(arr, (count,)).copy()

    def choice(self, key: str, default: str, options: tuple[str, ...]) -> str:
        """One of ``options``, case-insensitive, returned in lower case."""
        if key not in self.data:
            return default
        value = self.data[key]
        if not isinstance(value, str):
            raise self.error(key, f"must be one of {', '.join(options)}", value)
        if value.lower() not in options:
            hint = did_you_mean(value.lower(), options)
            raise self.error(key, f"must be one of {', '.join(options)}{hint}", value)
        return value.lower()

    def color(self, key: str) -> np.ndarray | None:
        """A colour (``"#rrggbb"`` or ``[r, g, b]``) as three floats 0..1; None when absent."""
        if key not in self.data:
            return None
        return self.parse_color(key, self.data[key])

    def parse_color(self, key: str, value: object, whole: object = ...) -> np.ndarray:
        """``value`` as a colour; errors quote ``whole`` (the list it came from) when given."""
        whole = value if whole is ... else whole
        if isinstance(value, str):
            if not re.fullmatch(r"#?[0-9a-fA-F]{6}", value.strip()):
                raise self.error(key, _COLOR_SHAPE, whole)
            return hex_to_rgb(value)
        if isinstance(value, list) and len(value) == 3 and all(is_number(v) for v in value):
            rgb = np.array(self._floats(key, value, whole, "components must be between 0 and 1"))
            if not np.isfinite(rgb).all() or (rgb < 0).any() or (rgb > 1).any():
                raise self.error(key, "components must be between 0 and 1", whole)
            return rgb
        raise self.error(key, _COLOR_SHAPE, whole)
