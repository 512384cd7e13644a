"""Opening an input file (a scene, a trajectory to replay) without trusting it.

Only a regular file is read, opened so that it cannot block (a FIFO, a device, or a kernel file such as
``/proc/kmsg`` that stat calls regular but whose reads wait for data), and never more than a limit, so
a hostile or mistaken path can neither hang the program nor fill its memory. Callers turn
``InputRefused`` into their own one-line error naming the file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO


class InputRefused(ValueError):
    """An input file that is not read: the message says why, without the path."""


def size_text(limit: int) -> str:
    """``limit`` bytes for a message: 16 MiB, 2 GiB."""
    for unit, size in (("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if limit >= size:
            return f"{limit / size:g} {unit}"
    return f"{limit} bytes"


def open_regular(path: Path, limit: int, what: str) -> BinaryIO:
    """``path`` opened for reading bytes, if it is a regular file of at most ``limit`` bytes; else
    InputRefused saying why (``what`` names the kind of file: "a scene file")."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise InputRefused("no such file") from None
    except PermissionError:
        raise InputRefused("permission denied") from None
    except IsADirectoryError:
        raise InputRefused(f"is a directory, not {what}") from None
    except (OSError, ValueError) as e:  # ValueError: a NUL byte in the name
        raise InputRefused(f"cannot read: {getattr(e, 'strerror', None) or e}") from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise InputRefused(f"is a directory, not {what}")
        if not stat.S_ISREG(info.st_mode):
            raise InputRefused("not a regular file (a pipe, device or socket)")
        if info.st_size > limit:
            raise InputRefused(f"{info.st_size} bytes, more than {what} may have ({size_text(limit)})")
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_capped(f: BinaryIO, limit: int, what: str) -> bytes:
    """All of ``f`` (from ``open_regular``), or InputRefused if it holds more than ``limit`` bytes (it
    grew after it was opened) or a read would wait for data."""
    try:
        raw = f.read(limit + 1)
    except BlockingIOError:
        raise InputRefused("reading it would wait for data: not an ordinary file") from None
    if raw is None:  # a non-blocking read with nothing there yet
        raise InputRefused("reading it would wait for data: not an ordinary file")
    if len(raw) > limit:
        raise InputRefused(f"more bytes than {what} may have ({size_text(limit)})")
    return raw
