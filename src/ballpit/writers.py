"""Trajectory and contact-event writers (CSV or NPZ), complete or not at all.

Each writer fills a temporary file beside its target and renames it into place only when the run
finishes, so a crash, a Ctrl+C or a bad option never leaves a truncated file that looks complete.
Rows are buffered as arrays and formatted a chunk at a time with one ``%`` operation, not per row.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import IO

import numpy as np

from .physics import Contacts
from .physics.contacts import KIND_NAMES

TRAJECTORY_COLUMNS = ("time", "id", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "qx", "qy", "qz", "qw")
EVENT_COLUMNS = ("time", "kind", "a", "b", "x", "y", "z", "nx", "ny", "nz", "impulse")
FORMATS = (".csv", ".npz")
_FLOAT = "%.9g"
_CHUNK_ROWS = 100_000  # rows formatted per write


class OutputError(ValueError):
    """An output path that cannot be written (bad suffix, missing directory, no permission)."""


def check_output_path(path: Path, what: str) -> str:
    """The output format (".csv" or ".npz") for ``path``, or OutputError saying what is wrong."""
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise OutputError(f"{path}: {what} must end in .csv or .npz, not {suffix or 'no suffix'!r}")
    if path.is_dir():
        raise OutputError(f"{path}: {what} is a directory")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{path}: {what}: directory {str(parent)!r} does not exist")
    return suffix


class AtomicFile:
    """A temporary file beside ``target`` that replaces it on ``commit`` and vanishes on ``discard``."""

    def __init__(self, target: Path, mode: str = "w") -> None:
        self.target = target
        self.temp = target.with_name(f".{target.name}.{os.getpid()}.partial")
        try:
            self.file: IO = open(self.temp, mode, encoding="utf-8" if "b" not in mode else None)
        except OSError as e:
            raise OutputError(f"{target}: cannot write: {e.strerror or e}") from None

    def commit(self) -> None:
        self.file.close()
        os.replace(self.temp, self.target)

    def discard(self) -> None:
        self.file.close()
        self.temp.unlink(missing_ok=True)


class TrajectoryWriter:
    """Every ball's state at the recorded times: one row per ball per record.

    ``record`` copies the state into a preallocated buffer; full buffers are flushed as CSV text, or
    kept as arrays for one ``.npz`` at the end. The number of balls may change between records (the
    viewer adds balls): ball ``i`` is always id ``i``, and new balls get the next ids.
    """

    def __init__(self, path: Path, n_balls: int, option: str = "--out") -> None:
        self.path = path
        self.format = check_output_path(path, option)
        self.out = AtomicFile(path, "w" if self.format == ".csv" else "wb")
        self._allocate(n_balls)
        self.records = 0
        self.chunks: list[np.ndarray] = []
        self.row_format = ",".join(["%.9g", "%d"] + [_FLOAT] * (len(TRAJECTORY_COLUMNS) - 2)) + "\n"
        if self.format == ".csv":
            self.out.file.write(",".join(TRAJECTORY_COLUMNS) + "\n")

    def _allocate(self, n_balls: int) -> None:
        self.n = n_balls
        self.records_per_chunk = max(1, _CHUNK_ROWS // max(1, n_balls))
        self.buffer = np.empty((self.records_per_chunk, n_balls, len(TRAJECTORY_COLUMNS)))
        self.buffer[:, :, 1] = np.arange(n_balls)
        self.filled = 0

    def record(self, time: float, position, velocity, angular_velocity, orientation) -> None:
        if len(position) != self.n:  # balls were added: rows of the new count from here on
            self._flush()
            self._allocate(len(position))
        row = self.buffer[self.filled]
        row[:, 0] = time
        row[:, 2:5] = position
        row[:, 5:8] = velocity
        row[:, 8:11] = angular_velocity
        row[:, 11:15] = orientation
        self.filled += 1
        self.records += 1
        if self.filled == self.records_per_chunk:
            self._flush()

    def _flush(self) -> None:
        rows = self.buffer[: self.filled].reshape(-1, len(TRAJECTORY_COLUMNS))
        if self.format == ".csv":
            self.out.file.write((self.row_format * len(rows)) % tuple(rows.ravel().tolist()))
        else:
            self.chunks.append(rows.copy())
        self.filled = 0

    def commit(self) -> None:
        self._flush()
        if self.format == ".npz":
            rows = np.concatenate(self.chunks) if self.chunks else np.zeros((0, len(TRAJECTORY_COLUMNS)))
            arrays = {name: rows[:, k] for k, name in enumerate(TRAJECTORY_COLUMNS)}
            arrays["id"] = arrays["id"].astype(np.int64)
            np.savez(self.out.file, **arrays)
        self.out.commit()

    def discard(self) -> None:
        self.out.discard()


class EventWriter:
    """Every contact the solver resolved: time, kind, the two bodies, point, normal and impulse."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.format = check_output_path(path, "--events")
        self.out = AtomicFile(path, "w" if self.format == ".csv" else "wb")
        self.pending: list[Contacts] = []
        self.pending_rows = 0
        self.chunks: list[Contacts] = []
        self.count = 0
        self.row_format = ",".join(["%.9g", "%s", "%d", "%d"] + [_FLOAT] * 7) + "\n"
        if self.format == ".csv":
            self.out.file.write(",".join(EVENT_COLUMNS) + "\n")

    def add(self, contacts: Contacts) -> None:
        if len(contacts) == 0:
            return
        self.pending.append(contacts)
        self.pending_rows += len(contacts)
        self.count += len(contacts)
        if self.pending_rows >= _CHUNK_ROWS:
            self._flush()

    def _flush(self) -> None:
        if not self.pending:
            return
        c = Contacts.concatenate(self.pending)
        self.pending, self.pending_rows = [], 0
        if self.format == ".npz":
            self.chunks.append(c)
            return
        rows = np.empty((len(c), len(EVENT_COLUMNS)), dtype=object)
        rows[:, 0] = c.time
        rows[:, 1] = np.asarray(KIND_NAMES, dtype=object)[c.kind]
        rows[:, 2] = c.a
        rows[:, 3] = c.b
        rows[:, 4:7] = c.point
        rows[:, 7:10] = c.normal
        rows[:, 10] = c.impulse
        self.out.file.write((self.row_format * len(c)) % tuple(rows.ravel().tolist()))

    def commit(self) -> None:
        self._flush()
        if self.format == ".npz":
            c = Contacts.concatenate(self.chunks)
            np.savez(
                self.out.file,
                time=c.time,
                kind=np.asarray(KIND_NAMES)[c.kind],
                a=c.a.astype(np.int64),
                b=c.b.astype(np.int64),
                x=c.point[:, 0],
                y=c.point[:, 1],
                z=c.point[:, 2],
                nx=c.normal[:, 0],
                ny=c.normal[:, 1],
                nz=c.normal[:, 2],
                impulse=c.impulse,
            )
        self.out.commit()

    def discard(self) -> None:
        self.out.discard()
