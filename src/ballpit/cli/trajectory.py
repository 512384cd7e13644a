"""The trajectory format, read and written here alone: ``ballpit simulate --out``, the viewer's
``--record`` and ``view --replay`` all go through this module.

A trajectory is one row per ball per recorded step, in the columns ``TRAJECTORY_COLUMNS``, as CSV text or
as an ``.npz`` of one array per column (or stacked ``position``, ``velocity``, ... arrays).
``TrajectoryWriter`` streams rows to disk, complete or not at all (``writers.py``); ``read_trajectory``
loads a file into per-frame arrays and checks that it fits a scene's balls: anything wrong is a
``TrajectoryError`` whose one-line message names the file, found before anything large is read.
"""

from __future__ import annotations

import io
import math
import warnings
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .inputs import InputRefused, open_regular, size_text
from .writers import (
    CHUNK_ROWS,
    FLOAT_FORMAT,
    AtomicFile,
    ColumnSpool,
    SpooledOutput,
    check_output_path,
    directory_of,
    writing,
)

TRAJECTORY_COLUMNS = ("time", "id", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "qx", "qy", "qz", "qw")
_TYPES = {"id": (np.dtype(np.int64), None)}  # as the .npz stores them; the rest float64


# stacked .npz arrays → (their width, the CSV column they start at)
STACKED = {
    "position": (3, "x"),
    "velocity": (3, "vx"),
    "angular_velocity": (3, "wx"),
    "orientation": (4, "qx"),
}


class TrajectoryError(ValueError):
    """A trajectory that cannot be read or does not fit the scene."""


# The most a trajectory may hold: 2 GiB of numbers (.npz members, uncompressed) or of CSV text, about
# 18 million rows (1,000 balls for 75 s at every 1/240 s step; 'simulate --every K' writes less). Reading
# one takes about twice that in memory. Anything beyond is refused before it is inflated or parsed.
MAX_BYTES = 2 << 30


@dataclass
class Trajectory:
    """Frames of every ball's state: ``times`` (F,), ``position`` (F, N, 3), ``velocity`` (F, N, 3),
    ``angular_velocity`` (F, N, 3), ``orientation`` (F, N, 4). ``counts`` (F,) is how many balls each
    frame has: balls added during a recording (B in the viewer) get the next ids, so frame k holds
    balls 0..counts[k]-1 (the rest of its rows are NaN); None when every frame has all N."""

    path: Path
    times: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    orientation: np.ndarray
    counts: np.ndarray | None = None

    @property
    def frames(self) -> int:
        return len(self.times)

    @property
    def balls(self) -> int:
        """The most balls any frame has."""
        return self.position.shape[1]

    def balls_at(self, frame: int) -> int:
        return self.balls if self.counts is None else int(self.counts[frame])


def _columns_from_csv(path: Path) -> dict[str, np.ndarray]:
    with open_regular(path, MAX_BYTES, "a trajectory") as raw, io.TextIOWrapper(raw, encoding="utf-8") as f:
        header_line = f.readline(64 * 1024)
        header = [name.strip() for name in header_line.strip().split(",")]
        if header == [""]:
            raise TrajectoryError(f"{path}: empty file, not a trajectory")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # no rows: checked below, by name
            data = np.loadtxt(_capped_lines(f, MAX_BYTES - len(header_line)), delimiter=",", ndmin=2)
    if data.size and data.shape[1] != len(header):
        raise TrajectoryError(f"{path}: rows have {data.shape[1]} values but the header names {len(header)}")
    data = data.reshape(-1, len(header))
    return {name: data[:, k] for k, name in enumerate(header)}


def _capped_lines(f: io.TextIOWrapper, limit: int) -> Iterator[str]:
    """The lines of ``f`` until ``limit`` characters have been read (a file that grows while it is read,
    being written on and on, stops there with an error instead of running forever)."""
    seen = 0
    for line in f:
        seen += len(line)
        if seen > limit:
            raise InputRefused(f"more than a trajectory may have ({size_text(MAX_BYTES)})")
        yield line


_REAL = "fiu"  # dtype kinds of real numbers: floats, signed and unsigned integers
_KIND_NAMES = {"c": "complex numbers", "U": "text", "S": "bytes", "b": "true/false values", "O": "objects"}
UNIT_TOLERANCE = 1e-5  # how far an orientation's length may be from 1 (9 digits in a CSV, float32 in an .npz)


def _npy_headers(archive: zipfile.ZipFile) -> dict[str, tuple[tuple[int, ...], np.dtype]]:
    """Every ``.npy`` member's shape and dtype, from its header alone. Refuses an archive before anything
    is inflated: more than MAX_BYTES of members, or a member whose header claims more rows than its
    bytes hold (np.load would allocate them first)."""
    members = archive.infolist()
    total = sum(m.file_size for m in members)
    if total > MAX_BYTES:
        raise InputRefused(
            f"its arrays hold {total} bytes, more than a trajectory may have ({size_text(MAX_BYTES)})"
        )
    read_header = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
    headers = {}
    for m in members:
        if not m.filename.endswith(".npy"):
            continue
        with archive.open(m) as member:
            version = np.lib.format.read_magic(member)
            if version not in read_header:
                raise InputRefused(f"array {m.filename!r} has an unknown .npy version {version}")
            shape, _, dtype = read_header[version](member)
        if math.prod(shape) * dtype.itemsize > m.file_size:
            raise InputRefused(f"array {m.filename!r} claims shape {shape} but holds {m.file_size} bytes")
        headers[m.filename] = (shape, dtype)
    return headers


def _npz_sources(path: Path, headers: dict) -> dict[str, tuple[str, int | None]]:
    """Where each trajectory column is in the archive: (member, None) for its own array, or (member, k)
    for column k of a stacked (rows, k) one. Refuses, from the headers alone, a column that does not
    hold real numbers or whose length differs from the others'."""
    sources: dict[str, tuple[str, int | None]] = {}
    for name in TRAJECTORY_COLUMNS:
        if f"{name}.npy" in headers:
            sources[name] = (f"{name}.npy", None)
    for name, (width, column) in STACKED.items():  # stacked (rows, k) arrays → the CSV's columns
        shape = headers.get(f"{name}.npy", ((),))[0]
        if len(shape) == 2 and shape[1] == width:
            start = TRAJECTORY_COLUMNS.index(column)
            for k in range(width):
                sources.setdefault(TRAJECTORY_COLUMNS[start + k], (f"{name}.npy", k))
    rows = {}
    for name, (member, k) in sources.items():
        shape, dtype = headers[member]
        if dtype.kind not in _REAL:
            what = _KIND_NAMES.get(dtype.kind, f"values of type {dtype}")
            raise TrajectoryError(f"{path}: column {name!r} holds {what} ({dtype}), not real numbers")
        rows[name] = shape[0] if k is not None else math.prod(shape)
    first = next(iter(rows), None)
    odd = next((name for name, n in rows.items() if n != rows[first]), None)
    if odd is not None:
        raise TrajectoryError(
            f"{path}: the trajectory columns have different lengths: {odd!r} has {rows[odd]:,} rows, "
            f"{first!r} {rows[first]:,}"
        )
    return sources


def _columns_from_npz(path: Path) -> dict[str, np.ndarray]:
    """The trajectory columns of an ``.npz``: only the members that hold them are inflated, once their
    headers have shown they fit together."""
    with open_regular(path, MAX_BYTES, "a trajectory") as f:
        if not zipfile.is_zipfile(f):
            raise TrajectoryError(f"{path}: not an .npz archive")
        f.seek(0)
        with zipfile.ZipFile(f) as archive:
            sources = _npz_sources(path, _npy_headers(archive))
            arrays: dict[str, np.ndarray] = {}
            for member in dict.fromkeys(m for m, _ in sources.values()):
                with archive.open(member) as data:
                    arrays[member] = np.lib.format.read_array(data, allow_pickle=False)
    return {name: arrays[m] if k is None else arrays[m][:, k] for name, (m, k) in sources.items()}


def read_trajectory(path: Path | str, n_balls: int | None = None) -> Trajectory:
    """Load a trajectory file (``.csv`` or ``.npz``); with ``n_balls``, check it starts with that many
    balls (the scene's). Balls may be added later in it (they get the next ids), never removed."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".npz"):
        raise TrajectoryError(f"{path}: a trajectory must be a .csv or .npz file")
    try:
        columns = _columns_from_csv(path) if suffix == ".csv" else _columns_from_npz(path)
    except TrajectoryError:
        raise
    except InputRefused as e:
        raise TrajectoryError(f"{path}: {e}") from None
    except BlockingIOError:
        raise TrajectoryError(f"{path}: reading it would wait for data: not an ordinary file") from None
    except MemoryError:
        raise TrajectoryError(f"{path}: too large to read into memory") from None
    except (OSError, ValueError, zipfile.BadZipFile, UnicodeDecodeError, EOFError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise TrajectoryError(f"{path}: cannot read the trajectory ({reason})") from None
    missing = [name for name in TRAJECTORY_COLUMNS if name not in columns]
    if missing:
        raise TrajectoryError(f"{path}: missing trajectory columns: {', '.join(missing)}")
    try:
        table = [np.asarray(columns.pop(name), dtype=float).reshape(-1) for name in TRAJECTORY_COLUMNS]
    except (TypeError, ValueError):
        raise TrajectoryError(f"{path}: the trajectory columns must hold numbers") from None
    rows = len(table[0])
    if any(len(c) != rows for c in table):
        raise TrajectoryError(f"{path}: the trajectory columns have different lengths")
    if rows == 0:
        raise TrajectoryError(f"{path}: the trajectory has no rows")
    if not all(np.isfinite(c).all() for c in table):
        raise TrajectoryError(f"{path}: the trajectory holds values that are not finite numbers")
    times, ids = table[0], table[1]
    frame, counts = _records(path, ids)
    _check_orientations(path, table[-4:], frame, ids)
    if n_balls is not None and counts[0] != n_balls:
        raise TrajectoryError(f"{path}: the trajectory has {counts[0]} balls but the scene has {n_balls}")
    n = int(counts.max())
    if len(counts) * n * (len(TRAJECTORY_COLUMNS) - 2) * 8 > MAX_BYTES:
        raise TrajectoryError(
            f"{path}: {len(counts)} records of up to {n} balls are more than a replay holds "
            f"({size_text(MAX_BYTES)})"
        )
    starts = np.flatnonzero(ids == 0)
    frame_times = times[starts]
    if np.any(np.diff(frame_times) < 0) or np.any(times != frame_times[frame]):
        raise TrajectoryError(f"{path}: the times must be the same for every ball of a record, never falling")
    slot = ids.astype(np.intp)

    def frames_of(first: int, width: int) -> np.ndarray:
        out = (
            np.full((len(counts), n, width), np.nan)
            if counts.min() < n
            else np.empty((len(counts), n, width))
        )
        for k in range(width):
            out[frame, slot, k] = table[first + k]
        return out

    return Trajectory(path, frame_times.copy(), frames_of(2, 3), frames_of(5, 3), frames_of(8, 3),
                      frames_of(11, 4), counts if counts.min() < n else None)  # fmt: skip


def _check_orientations(path: Path, q: list[np.ndarray], frame: np.ndarray, ids: np.ndarray) -> None:
    """Refuse an orientation that is not a unit quaternion (all zeros once played as NaN)."""
    length = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    bad = np.flatnonzero(~(np.abs(length - 1.0) <= UNIT_TOLERANCE))
    if len(bad):
        r = int(bad[0])
        shown = ", ".join(f"{c[r]:g}" for c in q)
        raise TrajectoryError(
            f"{path}: record {frame[r] + 1}, ball {ids[r]:g}: orientation ({shown}) is not a unit "
            f"quaternion (its length is {length[r]:.6g}, not 1 within {UNIT_TOLERANCE:g})"
        )


def _records(path: Path, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's record (frame) index and each record's ball count, from the id column: every record
    lists ids 0..n-1 in order, and n never falls (balls are only added)."""
    whole = (ids >= 0) & (ids < 2**31) & (ids == np.floor(ids))
    if not whole.all():
        bad = ids[~whole][0]
        raise TrajectoryError(f"{path}: ball ids must be whole numbers from 0, got {bad:g}")
    first = ids == 0
    if not first[0]:
        raise TrajectoryError(
            f"{path}: rows must list ids 0..N-1 for every recorded time (the first is {ids[0]:g})"
        )
    starts = np.flatnonzero(first)
    frame = np.cumsum(first) - 1
    if not np.array_equal(ids, np.arange(len(ids)) - starts[frame]):
        raise TrajectoryError(f"{path}: rows must list ids 0..N-1 for every recorded time")
    counts = np.diff(np.append(starts, len(ids)))
    fell = np.flatnonzero(np.diff(counts) < 0)
    if len(fell):
        k = int(fell[0])
        raise TrajectoryError(
            f"{path}: record {k + 2} has {counts[k + 1]} balls, fewer than the {counts[k]} before: "
            "balls can be added during a run, not removed"
        )
    return frame, counts


class TrajectoryWriter(SpooledOutput):
    """Every ball's state at the recorded times: one row per ball per record.

    ``record`` copies the state into a preallocated buffer; full buffers go to disk as CSV text, or
    to the ``.npz``'s column spool. The number of balls may change between records (the viewer adds
    balls): ball ``i`` is always id ``i``, and new balls get the next ids.
    """

    types = _TYPES

    def __init__(
        self, path: Path, n_balls: int, option: str = "--out", records_per_chunk: int | None = None
    ) -> None:
        self.path = path
        self.format = check_output_path(path, option)
        self.chunk_records = records_per_chunk  # 1: every record is its own chunk, so it can be cut off
        self._marks: list[int] = []  # where each chunk begins: a byte offset (.csv) or spool chunk (.npz)
        self.spool = ColumnSpool(TRAJECTORY_COLUMNS, directory_of(path)) if self.format == ".npz" else None
        self.out = AtomicFile(
            path, "w" if self.format == ".csv" else "wb"
        )  # after the spool: its error leaves nothing
        self._allocate(n_balls)
        self.records = 0
        self.row_format = ",".join(["%.9g", "%d"] + [FLOAT_FORMAT] * (len(TRAJECTORY_COLUMNS) - 2)) + "\n"
        if self.format == ".csv":
            self.out.file.write(",".join(TRAJECTORY_COLUMNS) + "\n")

    def _allocate(self, n_balls: int) -> None:
        self.n = n_balls
        self.records_per_chunk = self.chunk_records or max(1, CHUNK_ROWS // max(1, n_balls))
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
        if self.filled == 0:
            return
        rows = self.buffer[: self.filled].reshape(-1, len(TRAJECTORY_COLUMNS))
        with writing(self.path):
            if self.spool is None:
                self._marks.append(self.out.file.tell())
                self.out.file.write((self.row_format * len(rows)) % tuple(rows.ravel().tolist()))
            else:
                self._marks.append(len(self.spool.chunks))
                self.spool.add(rows)
        self.filled = 0

    def truncate(self, records: int) -> None:
        """Keep only the first ``records`` records (the viewer resuming from the past drops its future).
        Records already written can be cut off only when each is its own chunk (``records_per_chunk=1``)."""
        if records >= self.records:
            return
        written = self.records - self.filled
        if records >= written:  # still in the buffer
            self.filled = records - written
        else:
            if self.chunk_records != 1:
                raise ValueError("records already written can be cut off only with records_per_chunk=1")
            self._flush()
            mark = self._marks[records]
            del self._marks[records:]
            if self.spool is None:
                self.out.file.truncate(mark)
                self.out.file.seek(mark)
            else:
                self.spool.truncate(mark)
        self.records = records
