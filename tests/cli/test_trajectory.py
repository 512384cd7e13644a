"""The trajectory format read against hostile files: a FIFO, a device, a deflate bomb, a header
claiming 10¹² rows, a column of another length or of other than real numbers, orientations that are
not unit quaternions, ids that are not 0..N-1 are one-line errors with exit status 2 from ``view
--replay``, before any window and before anything large is read."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from ballpit import cli
from ballpit.cli import trajectory as trajectory_module
from ballpit.cli.trajectory import TRAJECTORY_COLUMNS, read_trajectory

ROOT = Path(__file__).resolve().parents[2]
SLOPES = ROOT / "scenes" / "slopes.toml"


def _write_csv(path: Path, rows: list[list[float]]) -> Path:
    lines = [",".join(TRAJECTORY_COLUMNS)] + [",".join(map(repr, r)) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def _row(time: float, ball: float) -> list[float]:
    return [time, ball, 0.0, 1.0, 0.0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]


def _replay_status(path: Path, capsys) -> str:
    status = cli.main(["view", "slopes", "--replay", str(path)])
    err = capsys.readouterr().err
    assert status == cli.EXIT_BAD_INPUT, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


@pytest.mark.parametrize(
    ("ids", "fragment"),
    [
        ([-1, -1], "ball ids must be whole numbers from 0, got -1"),
        ([0, -2], "ball ids must be whole numbers from 0, got -2"),
        ([0, 0.5], "got 0.5"),
        ([1, 2], "ids 0..N-1"),
        ([0, 1, 0], "fewer than the 2 before"),
    ],
)
def test_ids_that_are_not_zero_to_n_minus_1_are_one_line_errors(tmp_path, capsys, ids, fragment):
    times = [0.0] * 2 + [0.1] * (len(ids) - 2) if len(ids) > 2 else [0.0] * len(ids)
    path = _write_csv(tmp_path / "ids.csv", [_row(t, i) for t, i in zip(times, ids, strict=True)])
    assert fragment in _replay_status(path, capsys)


def _view_replay(path: Path) -> subprocess.CompletedProcess:
    """In a child with a time limit: a read that blocks fails the test instead of hanging the suite."""
    return subprocess.run(
        [sys.executable, "-m", "ballpit", "view", "slopes", "--replay", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path, suffix):
    fifo = tmp_path / f"run{suffix}"
    os.mkfifo(fifo)
    r = _view_replay(fifo)
    assert r.returncode == 2, r.stderr
    assert "not a regular file" in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_an_endless_file_is_refused(tmp_path, device):
    endless = tmp_path / "endless.csv"
    endless.symlink_to(device)
    r = _view_replay(endless)
    assert r.returncode == 2, r.stderr
    assert "not a regular file" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def _npy_member(archive: zipfile.ZipFile, name: str, shape: tuple, payload: bytes, **kwargs) -> None:
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": shape})
    archive.writestr(name, header.getvalue() + payload, **kwargs)


def test_a_header_claiming_a_trillion_rows_is_refused_before_allocating(tmp_path, capsys):
    path = tmp_path / "huge.npz"
    with zipfile.ZipFile(path, "w") as archive:
        for column in TRAJECTORY_COLUMNS:
            _npy_member(archive, f"{column}.npy", (10**12,), np.zeros(4).tobytes())
    err = _replay_status(path, capsys)
    assert "claims shape (1000000000000,)" in err


def test_a_deflate_bomb_is_refused_before_it_is_inflated(tmp_path, capsys, monkeypatch):
    """Arrays whose inflated size is beyond the limit (here lowered to 1 MiB, so the bomb stays small to
    build; the real limit is 2 GiB) are refused from the archive's directory, unread."""
    monkeypatch.setattr(trajectory_module, "MAX_BYTES", 1 << 20)
    path = tmp_path / "bomb.npz"
    rows = (2 << 20) // 8
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for column in TRAJECTORY_COLUMNS:
            _npy_member(archive, f"{column}.npy", (rows,), bytes(rows * 8))
    assert path.stat().st_size < 200_000  # a small file that inflates to 30 MiB
    err = _replay_status(path, capsys)
    assert "more than a trajectory may have (1 MiB)" in err
    assert trajectory_module.MAX_BYTES == 1 << 20 and 2 << 30 == 2147483648


def test_a_bomb_that_understates_its_size_is_refused_unread(tmp_path, capsys):
    """A bomb whose directory says its members are small: their headers claim more than that, so they
    are refused before np.load allocates (and zipfile never inflates past the size it was told)."""
    path = tmp_path / "liar.npz"
    rows = 1 << 20
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for column in TRAJECTORY_COLUMNS:
            _npy_member(archive, f"{column}.npy", (rows,), bytes(rows * 8))
    blob = bytearray(path.read_bytes())
    # Rewrite each member's uncompressed size (local header and central directory) to 200 bytes.
    with zipfile.ZipFile(path) as archive:
        infos = archive.infolist()
    for info in infos:
        real = info.file_size.to_bytes(4, "little")
        blob = blob.replace(real, (200).to_bytes(4, "little"))
    path.write_bytes(bytes(blob))
    err = _replay_status(path, capsys)
    # zipfile stops at the 200 bytes it was told of, and finds their checksum wrong
    assert "claims shape (1048576,) but holds 200 bytes" in err or "Bad CRC-32" in err


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_a_kernel_file_whose_reads_block_is_refused_by_every_command():
    """/proc/kmsg is a 'regular' file to stat whose reads wait for kernel messages; read by root it
    hung check, simulate, compare and view. Without root it is 'permission denied'; either way, no wait."""
    kmsg = Path("/proc/kmsg")
    if not kmsg.exists():
        pytest.skip("no /proc/kmsg on this system")
    for command in (["check"], ["simulate", "-q"], ["compare", "-q"], ["view"]):
        r = subprocess.run(
            [sys.executable, "-m", "ballpit", command[0], str(kmsg), *command[1:]],
            capture_output=True,
            text=True,
            timeout=60,
            cwd=ROOT,
        )
        assert r.returncode == 2, (command, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_csv_rows_that_never_end_stop_at_the_size_limit(monkeypatch):
    """A CSV that keeps growing while it is read (a run still writing it) is read no further than the
    limit: here an endless stream of rows against a limit of 1 MiB."""
    import itertools

    monkeypatch.setattr(trajectory_module, "MAX_BYTES", 1 << 20)
    row = ",".join(["0"] * len(TRAJECTORY_COLUMNS)) + "\n"
    lines = trajectory_module._capped_lines(itertools.repeat(row), 1 << 20)
    read = 0
    with pytest.raises(trajectory_module.InputRefused, match=r"more than a trajectory may have \(1 MiB\)"):
        for line in lines:
            read += len(line)
    assert read <= 1 << 20


def _trajectory_npz(path: Path, rows: int = 10, **columns: tuple[tuple, str, bytes]) -> Path:
    """An .npz of the trajectory columns: ``rows`` zeros each (qw ones), except those given as
    (shape, dtype descr, payload)."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for column in TRAJECTORY_COLUMNS:
            default = (
                np.ones(rows) if column == "qw" else np.arange(rows) % 2 if column == "id" else np.zeros(rows)
            )
            shape, descr, payload = columns.get(column, ((rows,), "<f8", default.astype("<f8").tobytes()))
            header = io.BytesIO()
            np.lib.format.write_array_header_1_0(
                header, {"descr": descr, "fortran_order": False, "shape": shape}
            )
            archive.writestr(f"{column}.npy", header.getvalue() + payload)
    return path


def test_a_column_of_the_wrong_length_is_refused_from_its_header_before_it_is_inflated(tmp_path, capsys):
    # Its data is corrupt past the header (a wrong checksum): reading it whole would fail differently.
    rows = 1 << 17
    path = _trajectory_npz(tmp_path / "long.npz", x=((rows,), "<f8", bytes(rows * 8)))
    blob = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as archive:
        crc = archive.getinfo("x.npy").CRC.to_bytes(4, "little")
    path.write_bytes(bytes(blob).replace(crc, bytes(4 * [0x5A])))
    err = _replay_status(path, capsys)
    assert "the trajectory columns have different lengths: 'x' has 131,072 rows, 'time' 10" in err


@pytest.mark.slow
def test_a_1_mb_replay_whose_column_inflates_to_1_gib_is_refused_within_100_mb(tmp_path):
    # It was inflated first and then refused, at a peak of 1.08 GB.
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for column in TRAJECTORY_COLUMNS:
            rows = (1 << 30) // 8 if column == "x" else 10
            header = io.BytesIO()
            np.lib.format.write_array_header_1_0(
                header, {"descr": "<f8", "fortran_order": False, "shape": (rows,)}
            )
            with archive.open(f"{column}.npy", "w", force_zip64=True) as member:
                member.write(header.getvalue())
                for _ in range(rows * 8 // (1 << 20)) if column == "x" else ():
                    member.write(bytes(1 << 20))
                member.write(bytes(rows * 8) if column != "x" else b"")
    assert path.stat().st_size < 2e6
    code = (
        "import sys\n"
        "from ballpit import cli\n"
        "status = cli.main(['view', 'slopes', '--replay', sys.argv[1]])\n"
        "peak = next(line for line in open('/proc/self/status') if line.startswith('VmHWM'))\n"
        "print(status, peak.split()[1])  # this process's own peak (ru_maxrss may carry the parent's)\n"
    )
    r = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=300)
    status, peak_kib = map(int, r.stdout.split())
    assert status == 2 and "'x' has 134,217,728 rows, 'time' 10" in r.stderr, r.stderr
    assert peak_kib * 1024 < 100e6, f"{peak_kib / 1024:.0f} MiB"


@pytest.mark.parametrize(
    ("column", "dtype", "fragment"),
    [
        ("x", "<c16", "column 'x' holds complex numbers (complex128), not real numbers"),
        ("y", "<U3", "column 'y' holds text (<U3), not real numbers"),
        ("time", "|b1", "column 'time' holds true/false values (bool), not real numbers"),
    ],
)
def test_a_column_that_does_not_hold_real_numbers_is_refused(tmp_path, capsys, column, dtype, fragment):
    values = np.zeros(10, dtype=dtype) if dtype != "<U3" else np.array(["1"] * 10, dtype=dtype)
    path = _trajectory_npz(tmp_path / "typed.npz", **{column: ((10,), dtype, values.tobytes())})
    assert fragment in _replay_status(path, capsys)


@pytest.mark.parametrize(
    ("q", "fragment"),
    [
        ((0.0, 0.0, 0.0, 0.0), "orientation (0, 0, 0, 0) is not a unit quaternion (its length is 0"),
        (
            (0.0, 0.0, 0.0, 1.001),
            "orientation (0, 0, 0, 1.001) is not a unit quaternion (its length is 1.001, not 1 within 1e-05)",
        ),
    ],
)
def test_an_orientation_that_is_not_a_unit_quaternion_is_refused(tmp_path, capsys, q, fragment):
    rows = [_row(0.0, 0), _row(0.0, 1)]
    rows[1][-4:] = q
    path = _write_csv(tmp_path / "turned.csv", rows)
    assert f"record 1, ball 1: {fragment}" in _replay_status(path, capsys)


def test_an_npz_of_int_and_float32_columns_still_plays(tmp_path):
    rows = 10
    floats = {c: ((rows,), "<f4", np.zeros(rows, "<f4").tobytes()) for c in ("x", "y", "vx")}
    path = _trajectory_npz(
        tmp_path / "narrow.npz",
        rows,
        id=((rows,), "<i8", (np.arange(rows) % 5).astype("<i8").tobytes()),
        **floats,
    )
    t = read_trajectory(path, n_balls=5)
    assert (t.frames, t.balls) == (2, 5)
