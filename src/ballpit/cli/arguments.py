"""Argument types and the one-line argument parser that every command shares (``cli.py``, ``bench.py``).

Bad input is one line naming the option and the value, exit status 2, no usage block and no traceback.
"""

from __future__ import annotations

import argparse
import math
import re
from typing import NoReturn

EXIT_BAD_INPUT = 2


class OneLineParser(argparse.ArgumentParser):
    """argparse with a one-line error message (no usage block), still exit status 2.

    Subcommand parsers made by ``add_subparsers`` are of the same class. Control characters in the
    message (an option value holding a newline or a terminal escape) are shown escaped.
    """

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        # A value that starts like a negative number ("-5x10", "-1e-3") is a value, so its own check
        # names what is wrong with it; argparse took only "-5" or "-.5" for a number, and "--size -5x10"
        # said "expected one argument". No option of ours is a dash and a digit.
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> NoReturn:  # type: ignore[override]
        text = one_line(message, limit=500)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {text} (see '{self.prog} --help')\n")


def one_line(text: str, limit: int | None = None) -> str:
    """``text`` with control characters escaped (so it stays one line), shortened to ``limit`` if given."""
    text = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)
    return text if limit is None or len(text) <= limit else text[: limit - 3] + "..."


def positive(text: str) -> float:
    """A positive, finite number of seconds."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not math.isfinite(x) or x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text!r}")
    return x


def count(text: str) -> int:
    """A whole number, at least 1."""
    try:
        k = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if k < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text!r}")
    return k


def size(text: str) -> tuple[int, int]:
    """WIDTHxHEIGHT in pixels, each 16 to 8192."""
    parts = text.lower().split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be WIDTHxHEIGHT in pixels, like 960x540, got {text!r}"
        ) from None
    if w < 16 or h < 16 or w > 8192 or h > 8192:
        raise argparse.ArgumentTypeError(f"must be between 16 and 8192 pixels each way, got {text!r}")
    return w, h
