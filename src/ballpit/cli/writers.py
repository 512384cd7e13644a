"""Outputs written complete or not at all, and the contact-event writer (CSV or NPZ).

The trajectory's writer is in ``trajectory.py``, beside its reader; both writers are built on these.
Each writer fills a temporary file beside its target (``run.npz.<pid>.partial``) and renames it into
place only when the run finishes, so a crash, a Ctrl+C or a bad option never leaves a truncated file
that looks complete. A process killed outright (SIGKILL, a power cut) cannot remove its temporary file;
it is left in plain sight, named as unfinished, and the next write to the same target removes it.
Rows are buffered as arrays a chunk at a time and streamed to disk as the run goes, so memory does not
grow with the duration: CSV text is formatted a chunk at a time with one ``%`` operation, not per row;
for ``.npz``, each chunk's columns go to an unnamed scratch file, and ``commit`` copies them column by
column into the archive's ``.npy`` members, a chunk at a time.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

import numpy as np

from ..physics import Contacts
from ..physics.core.contacts import KIND_NAMES

EVENT_COLUMNS = ("time", "kind", "a", "b", "x", "y", "z", "nx", "ny", "nz", "impulse")
FORMATS = (".csv", ".npz")
FLOAT_FORMAT = "%.9g"
CHUNK_ROWS = 100_000  # rows formatted per write


class OutputError(ValueError):
    """An output path that cannot be written (bad suffix, missing directory, no permission)."""


class OutputFailed(Exception):
    """Writing an output failed part way (a full disk, a file size limit, an I/O error)."""


@contextmanager
def writing(path: Path) -> Iterator[None]:
    """Turn an OSError while writing ``path`` into OutputFailed naming the file and the reason."""
    try:
        yield
    except OSError as e:
        raise OutputFailed(f"{shorten(path)}: cannot write: {e.strerror or e}") from e


NAME_MAX = 255  # bytes in one file name on Linux, macOS and Windows file systems
_TEMP_NAME = "{name}.{pid}.partial"  # visible: one left by a killed run is plainly unfinished


def shorten(path: Path | str, limit: int = 80) -> str:
    """``path`` for a message: kept whole when short, else its start and end around an ellipsis."""
    text = str(path)
    return text if len(text) <= limit else f"{text[: limit // 2 - 2]}...{text[-(limit // 2 - 1) :]}"


def check_name_lengths(path: Path, what: str) -> None:
    """OutputError if a part of ``path`` is longer than a file name can be (NAME_MAX bytes)."""
    for part in path.parts:
        size = len(os.fsencode(part))
        if size > NAME_MAX:
            raise OutputError(
                f"{shorten(path)}: {what}: a file name of {size} bytes is too long; the limit is {NAME_MAX}"
            )


def check_output_path(path: Path, what: str) -> str:
    """The output format (".csv" or ".npz") for ``path``, or OutputError saying what is wrong."""
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise OutputError(f"{path}: {what} must end in .csv or .npz, not {suffix or 'no suffix'!r}")
    check_output_place(path, what)
    return suffix


def check_output_place(path: Path, what: str, folder: bool = False) -> None:
    """OutputError unless ``path`` (a file, or with ``folder`` a folder of frames) can be made where it
    is: names that fit, not a folder where a file goes, and the folder it goes into already there.
    Every command that writes checks its outputs here, so none makes folders on the way (a mistyped
    path once made one at the root of the file system)."""
    check_name_lengths(path, what)
    try:
        if path.is_dir() and not folder:
            raise OutputError(f"{path}: {what} is a directory")
        if path.exists() and not path.is_dir() and folder:
            raise OutputError(f"{path}: {what}: {str(path)!r} is a file, not a folder")
        parent = directory_of(path)
        for above in (parent, *parent.parents):  # the nearest part that exists must be a folder
            if above.exists():
                if not above.is_dir():
                    raise OutputError(f"{path}: {what}: {str(above)!r} is a file, not a folder")
                break
        if not parent.is_dir():
            raise OutputError(f"{path}: {what}: directory {str(parent)!r} does not exist")
    except OSError as e:
        raise OutputError(f"{shorten(path)}: {what}: {e.strerror or e}") from None


def temp_path(target: Path, pid: int | None = None) -> Path:
    """The temporary name beside ``target`` for process ``pid`` (this one by default), its name
    shortened if need be to fit NAME_MAX."""
    name, pid = target.name, os.getpid() if pid is None else pid
    while len(os.fsencode(_TEMP_NAME.format(name=name, pid=pid))) > NAME_MAX:
        name = name[:-1]
    return target.with_name(_TEMP_NAME.format(name=name, pid=pid))


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    except (OverflowError, ValueError):  # too large to be a process id
        return False
    return True


def remove_stale_temps(target: Path) -> list[Path]:
    """Remove the temporary files of ``target`` left by runs that were killed outright (their
    process is gone); returns them. Older runs hid theirs (a leading dot): those go too."""
    removed = []
    try:
        entries = list(os.scandir(directory_of(target)))
    except OSError:
        return removed
    for entry in entries:
        name = entry.name
        if not name.endswith(".partial"):
            continue
        pid_text = name.removesuffix(".partial").rpartition(".")[2]
        if not pid_text.isdigit() or int(pid_text) == os.getpid():
            continue
        pid = int(pid_text)
        if name.removeprefix(".") != temp_path(target, pid).name or _running(pid):
            continue
        try:
            os.unlink(entry.path)
            removed.append(Path(entry.path))
        except OSError:
            pass
    return removed


class AtomicFile:
    """A temporary file beside ``target`` that replaces it on ``commit`` and vanishes on ``discard``."""

    def __init__(self, target: Path, mode: str = "w") -> None:
        self.target = target
        self.temp = temp_path(target)
        remove_stale_temps(target)
        try:
            self.file: IO = open(self.temp, mode, encoding="utf-8" if "b" not in mode else None)
        except OSError as e:
            raise OutputError(f"{target}: cannot write: {e.strerror or e}") from None

    def commit(self) -> None:
        self.file.close()
        os.replace(self.temp, self.target)

    def discard(self) -> None:
        """Remove the temporary file, even when closing it fails (a full disk fails the last flush)."""
        try:
            self.file.close()
        except OSError:
            pass
        finally:
            self.temp.unlink(missing_ok=True)


class ColumnSpool:
    """Rows of float64 columns spooled to an unnamed scratch file, written out as ``.npy`` members.

    Each chunk is stored column after column, so a column can be read back a chunk at a time. The
    scratch file has no name (it is deleted as soon as it is made, or made without one), so nothing
    of it can be left behind, whatever ends the process.
    """

    def __init__(self, names: tuple[str, ...], directory: Path) -> None:
        self.names = names
        try:
            self.file = tempfile.TemporaryFile(dir=directory)
        except OSError as e:
            raise OutputError(
                f"{shorten(directory)}: cannot write a scratch file: {e.strerror or e}"
            ) from None
        self.chunks: list[tuple[int, int]] = []  # (byte offset, rows)
        self.rows = 0

    def add(self, rows: np.ndarray) -> None:
        """Append (R, len(names)) rows."""
        if len(rows) == 0:
            return
        self.chunks.append((self.file.tell(), len(rows)))
        self.file.write(np.ascontiguousarray(rows.T, dtype=np.float64).data)  # a full disk: ENOSPC
        self.rows += len(rows)

    def truncate(self, chunks: int) -> None:
        """Keep only the first ``chunks`` chunks (the rest of the scratch file is cut off)."""
        if chunks >= len(self.chunks):
            return
        offset = self.chunks[chunks][0]
        self.rows -= sum(rows for _, rows in self.chunks[chunks:])
        del self.chunks[chunks:]
        self.file.truncate(offset)
        self.file.seek(offset)

    def column(self, k: int):
        """Column ``k``, one chunk at a time."""
        for offset, rows in self.chunks:
            self.file.seek(offset + k * rows * 8)
            chunk = np.empty(rows, dtype=np.float64)
            if self.file.readinto(chunk.data.cast("B")) != chunk.nbytes:
                raise OSError(f"the scratch file ended early, in column {self.names[k]!r}")
            yield chunk

    def write_npz(self, out: IO[bytes], convert: dict[str, tuple[np.dtype, Callable]]) -> None:
        """Write every column to ``out`` as ``np.savez`` would (one stored ``<name>.npy`` member each).

        ``convert`` gives a column's dtype and a function from float64 chunk to that dtype.
        """
        self.file.flush()
        with zipfile.ZipFile(out, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True) as archive:
            for k, name in enumerate(self.names):
                dtype, cast = convert.get(name, (np.dtype(np.float64), None))
                header = np.lib.format.header_data_from_array_1_0(np.empty(0, dtype))
                header["shape"] = (self.rows,)
                with archive.open(f"{name}.npy", "w", force_zip64=True) as member:  # as np.savez does
                    np.lib.format.write_array_header_1_0(member, header)
                    for chunk in self.column(k):
                        member.write((chunk if cast is None else cast(chunk)).astype(dtype).tobytes())

    def close(self) -> None:
        self.file.close()


def directory_of(path: Path) -> Path:
    return path.parent if str(path.parent) else Path(".")


_EVENT_TYPES = {
    "kind": (
        np.dtype(f"<U{max(map(len, KIND_NAMES))}"),
        lambda code: np.asarray(KIND_NAMES)[code.astype(np.intp)],
    ),
    "a": (np.dtype(np.int64), None),
    "b": (np.dtype(np.int64), None),
}


class SpooledOutput:
    """Commit or discard for a writer whose rows go to ``out`` (CSV text) or ``spool`` (.npz columns,
    typed by ``types`` when the archive is written)."""

    path: Path
    out: AtomicFile
    spool: ColumnSpool | None
    types: dict

    def _flush(self) -> None:
        raise NotImplementedError

    def commit(self) -> None:
        self._flush()
        with writing(self.path):
            if self.spool is not None:
                self.spool.write_npz(self.out.file, self.types)
                self.spool.close()
            self.out.commit()

    def discard(self) -> None:
        try:
            if self.spool is not None:
                self.spool.close()
        finally:
            self.out.discard()


class EventWriter(SpooledOutput):
    """Every contact the solver resolved: time, kind, the two bodies, point, normal and impulse."""

    types = _EVENT_TYPES

    def __init__(self, path: Path) -> None:
        self.path = path
        self.format = check_output_path(path, "--events")
        self.spool = ColumnSpool(EVENT_COLUMNS, directory_of(path)) if self.format == ".npz" else None
        self.out = AtomicFile(path, "w" if self.format == ".csv" else "wb")
        self.pending: list[Contacts] = []
        self.pending_rows = 0
        self.count = 0
        self.row_format = ",".join(["%.9g", "%s", "%d", "%d"] + [FLOAT_FORMAT] * 7) + "\n"
        if self.format == ".csv":
            self.out.file.write(",".join(EVENT_COLUMNS) + "\n")

    def add(self, contacts: Contacts) -> None:
        if len(contacts) == 0:
            return
        self.pending.append(contacts)
        self.pending_rows += len(contacts)
        self.count += len(contacts)
        if self.pending_rows >= CHUNK_ROWS:
            self._flush()

    def _flush(self) -> None:
        if not self.pending:
            return
        c = Contacts.concatenate(self.pending)
        self.pending, self.pending_rows = [], 0
        with writing(self.path):
            self._write(c)

    def _write(self, c: Contacts) -> None:
        if self.spool is not None:
            rows = np.empty((len(c), len(EVENT_COLUMNS)))
            rows[:, 0] = c.time
            rows[:, 1] = c.kind
            rows[:, 2] = c.a
            rows[:, 3] = c.b
            rows[:, 4:7] = c.point
            rows[:, 7:10] = c.normal
            rows[:, 10] = c.impulse
            self.spool.add(rows)
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
