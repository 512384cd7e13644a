"""Trajectory and event files: streamed to disk as the run goes, identical to the run itself.

The reference is computed here by stepping the World directly, with nothing streamed.
"""

from __future__ import annotations

import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import ballpit
from ballpit import cli, writers
from ballpit.physics import Contacts
from ballpit.simulate import step_plan

ROOT = Path(__file__).resolve().parents[1]
SLOPES = ROOT / "scenes" / "slopes.toml"
TRAJECTORY = "time,id,x,y,z,vx,vy,vz,wx,wy,wz,qx,qy,qz,qw".split(",")
EVENTS = "time,kind,a,b,x,y,z,nx,ny,nz,impulse".split(",")
KIND = {0: "sphere-plane", 1: "sphere-sphere"}

# 1,024 balls resting on a floor, apart: every step records 1,024 rows and 1,024 contacts.
MANY = """
[[plane]]
normal = [0, 1, 0]

[[grid]]
count = [32, 1, 32]
corner = [0, 0.05, 0]
radius = 0.05
spacing = 0.2
"""


def reference(scene: Path, duration: float, every: int) -> tuple[dict, dict]:
    """The trajectory and event columns of a run, straight from World.step."""
    world = ballpit.load_scene(scene)
    balls = world.spheres
    n = len(balls)
    records: list[np.ndarray] = []
    contacts: list[Contacts] = []

    def record() -> None:
        row = np.empty((n, 15))
        row[:, 0] = world.time
        row[:, 1] = np.arange(n)
        row[:, 2:5] = balls.positions
        row[:, 5:8] = balls.velocities
        row[:, 8:11] = balls.angular_velocities
        row[:, 11:15] = balls.orientations
        records.append(row)

    record()
    plan = step_plan(duration, world.scene.timestep)
    total, done = sum(k for k, _ in plan), 0
    for k, h in plan:
        for _ in range(k):
            contacts.append(world.step(h))
            done += 1
            if done % every == 0 or done == total:
                record()
    rows = np.concatenate(records)
    trajectory = {name: rows[:, k] for k, name in enumerate(TRAJECTORY)}
    trajectory["id"] = trajectory["id"].astype(np.int64)
    c = Contacts.concatenate([c for c in contacts if len(c)])
    events = {
        "time": c.time,
        "kind": np.asarray([KIND[int(k)] for k in c.kind]),
        "a": c.a.astype(np.int64),
        "b": c.b.astype(np.int64),
        "x": c.point[:, 0],
        "y": c.point[:, 1],
        "z": c.point[:, 2],
        "nx": c.normal[:, 0],
        "ny": c.normal[:, 1],
        "nz": c.normal[:, 2],
        "impulse": c.impulse,
    }
    return trajectory, events


def csv_text(columns: dict, names: list[str]) -> str:
    """The CSV the writers promise: a header, then %.9g floats, whole numbers and kind names."""
    lines = [",".join(names)]
    for i in range(len(columns[names[0]])):
        cells = []
        for name in names:
            v = columns[name][i]
            cells.append(str(v) if isinstance(v, str | np.str_) else f"{v:d}" if name in ("id", "a", "b")
                         else f"{v:.9g}")  # fmt: skip
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def assert_npz_equals(path: Path, columns: dict, names: list[str]) -> None:
    with np.load(path) as npz:
        assert list(npz.keys()) == names
        for name in names:
            assert npz[name].dtype == columns[name].dtype, name
            assert np.array_equal(npz[name], columns[name]), name


def simulate(*args: str | Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "ballpit", "simulate", *map(str, args), "-q"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr


@pytest.fixture(scope="module")
def slopes_reference() -> tuple[dict, dict]:
    return reference(SLOPES, 1.5, 3)


def test_csv_and_npz_hold_exactly_the_run(tmp_path, slopes_reference):
    trajectory, events = slopes_reference
    assert set(events["kind"]) == {"sphere-plane", "sphere-sphere"}
    common = (SLOPES, "--duration", "1.5", "--every", "3")
    simulate(*common, "--out", tmp_path / "t.csv", "--events", tmp_path / "e.csv")
    simulate(*common, "--out", tmp_path / "t.npz", "--events", tmp_path / "e.npz")
    assert (tmp_path / "t.csv").read_text() == csv_text(trajectory, TRAJECTORY)
    assert (tmp_path / "e.csv").read_text() == csv_text(events, EVENTS)
    assert_npz_equals(tmp_path / "t.npz", trajectory, TRAJECTORY)
    assert_npz_equals(tmp_path / "e.npz", events, EVENTS)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.csv", "e.npz", "t.csv", "t.npz"]


def test_many_small_chunks_give_the_same_files(tmp_path, monkeypatch, slopes_reference):
    """Chunks of 7 rows: trajectory records and step contacts are split across many chunks."""
    monkeypatch.setattr(writers, "_CHUNK_ROWS", 7)
    trajectory, events = slopes_reference
    for suffix in ("csv", "npz"):
        out, ev = tmp_path / f"t.{suffix}", tmp_path / f"e.{suffix}"
        argv = ["simulate", str(SLOPES), "--duration", "1.5", "--every", "3", "--out", str(out)]
        assert cli.main([*argv, "--events", str(ev), "-q"]) == 0
    assert (tmp_path / "t.csv").read_text() == csv_text(trajectory, TRAJECTORY)
    assert (tmp_path / "e.csv").read_text() == csv_text(events, EVENTS)
    assert_npz_equals(tmp_path / "t.npz", trajectory, TRAJECTORY)
    assert_npz_equals(tmp_path / "e.npz", events, EVENTS)


def test_a_run_without_contacts_writes_empty_event_columns(tmp_path):
    scene = tmp_path / "fall.toml"
    scene.write_text("[[sphere]]\nposition = [0, 1, 0]\n")
    assert (
        cli.main(["simulate", str(scene), "--duration", "0.1", "--events", str(tmp_path / "e.npz"), "-q"])
        == 0
    )
    with np.load(tmp_path / "e.npz") as npz:
        assert list(npz.keys()) == EVENTS
        assert all(len(npz[k]) == 0 for k in EVENTS)
        assert npz["kind"].dtype == np.dtype("<U13") and npz["a"].dtype == np.int64


def peak_bytes(argv: list[str]) -> int:
    """The peak of memory traced (Python and NumPy allocations) while ``ballpit`` runs in-process."""
    tracemalloc.start()
    try:
        assert cli.main(argv) == 0
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_peak_memory_does_not_grow_with_the_duration(tmp_path):
    """2 s of 1,024 balls writes about 124 MB as .npz; held in memory, the peak grew by 140 MB.

    (CSV text was always written a chunk at a time.)
    """
    suffix = "npz"
    scene = tmp_path / "many.toml"
    scene.write_text(MANY)
    peaks = {}
    for duration in ("0.5", "2"):
        out, ev = tmp_path / f"t{duration}.{suffix}", tmp_path / f"e{duration}.{suffix}"
        argv = ["simulate", str(scene), "--duration", duration, "--out", str(out), "--events", str(ev), "-q"]
        peaks[duration] = peak_bytes(argv)
    assert (tmp_path / f"t2.{suffix}").stat().st_size > 50e6
    assert peaks["2"] - peaks["0.5"] < 4e6, peaks
    assert peaks["2"] < 80e6, peaks
