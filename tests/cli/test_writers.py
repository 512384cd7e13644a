"""Trajectory and event files: streamed to disk as the run goes, identical to the run itself.

The reference is computed here by stepping the World directly, with nothing streamed.
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from ballpit import cli
from ballpit.cli import trajectory as trajectory_module
from ballpit.cli import writers
from ballpit.cli.simulate import step_plan
from ballpit.physics import Contacts
from ballpit.scene import read_scene

from .runner import run_in_process

SHARED = ("slopes_reference",)  # the reference run, made once (tests/conftest.py: on one worker)
ROOT = Path(__file__).resolve().parents[2]
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


def reference(scene: Path, duration: float, every: int) -> tuple[dict, dict, dict]:
    """The trajectory, event and impact columns of a run, straight from World.step.

    Impacts are the contacts whose pair (kind, a, b) was not among the step before's contacts.
    """
    loaded = read_scene(scene)
    world = loaded.world
    balls = world.spheres
    n = len(balls)
    records: list[np.ndarray] = []
    contacts: list[Contacts] = []
    impacts: list[Contacts] = []

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
    plan = step_plan(duration, loaded.timestep)
    total, done = sum(k for k, _ in plan), 0
    before: set[tuple[int, int, int]] = set()
    for k, h in plan:
        for _ in range(k):
            step = world.step(h)
            pairs = list(zip(step.kind.tolist(), step.a.tolist(), step.b.tolist(), strict=True))
            new = np.array([pair not in before for pair in pairs], dtype=bool)
            impacts.append(Contacts(**{f: getattr(step, f)[new] for f in Contacts.__dataclass_fields__}))
            before = set(pairs)
            contacts.append(step)
            done += 1
            if done % every == 0 or done == total:
                record()
    rows = np.concatenate(records)
    trajectory = {name: rows[:, k] for k, name in enumerate(TRAJECTORY)}
    trajectory["id"] = trajectory["id"].astype(np.int64)
    return trajectory, event_columns(contacts), event_columns(impacts)


def event_columns(contacts: list[Contacts]) -> dict:
    c = Contacts.concatenate([c for c in contacts if len(c)])
    return {
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
    r = run_in_process("simulate", *args, "-q", cwd=ROOT)
    assert r.returncode == 0, r.stderr


@pytest.fixture(scope="module")
def slopes_reference() -> tuple[dict, dict, dict]:
    return reference(SLOPES, 1.5, 3)


def test_csv_and_npz_hold_exactly_the_run(tmp_path, slopes_reference):
    trajectory, events, _ = slopes_reference
    assert set(events["kind"]) == {"sphere-plane", "sphere-sphere"}
    common = (SLOPES, "--duration", "1.5", "--every", "3", "--events-kind", "all")
    simulate(*common, "--out", tmp_path / "t.csv", "--events", tmp_path / "e.csv")
    simulate(*common, "--out", tmp_path / "t.npz", "--events", tmp_path / "e.npz")
    assert (tmp_path / "t.csv").read_text() == csv_text(trajectory, TRAJECTORY)
    assert (tmp_path / "e.csv").read_text() == csv_text(events, EVENTS)
    assert_npz_equals(tmp_path / "t.npz", trajectory, TRAJECTORY)
    assert_npz_equals(tmp_path / "e.npz", events, EVENTS)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.csv", "e.npz", "t.csv", "t.npz"]


@pytest.mark.slow
def test_many_small_chunks_give_the_same_files(tmp_path, monkeypatch, slopes_reference):
    """Chunks of 7 rows: trajectory records and step contacts are split across many chunks."""
    monkeypatch.setattr(writers, "CHUNK_ROWS", 7)
    monkeypatch.setattr(trajectory_module, "CHUNK_ROWS", 7)
    trajectory, events, _ = slopes_reference
    for suffix in ("csv", "npz"):
        out, ev = tmp_path / f"t.{suffix}", tmp_path / f"e.{suffix}"
        argv = ["simulate", str(SLOPES), "--duration", "1.5", "--every", "3", "--out", str(out)]
        assert cli.main([*argv, "--events", str(ev), "--events-kind", "all", "-q"]) == 0
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


@pytest.mark.slow
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
        argv = ["simulate", str(scene), "--duration", duration, "--out", str(out), "--events", str(ev)]
        argv += ["--events-kind", "all", "-q"]
        peaks[duration] = peak_bytes(argv)
    assert (tmp_path / f"t2.{suffix}").stat().st_size > 50e6
    assert peaks["2"] - peaks["0.5"] < 4e6, peaks
    assert peaks["2"] < 80e6, peaks


@pytest.mark.slow
def test_events_default_to_impacts_the_first_step_of_each_contact(tmp_path):
    """The slopes demo over 5 s, its balls kept awake (asleep, a ball's resting contacts are written
    by the command line, not returned by World.step, which the reference reads): 1,710 contact rows,
    of which 47 are impacts (the bounces, the two mid-air collisions, the landings); the rest are balls
    resting or rolling on."""
    awake = tmp_path / "slopes.toml"
    awake.write_text(SLOPES.read_text().replace("\nsleep = true ", "\nsleep = false "))
    assert read_scene(awake).world.sleep is False
    _, every, impacts = reference(awake, 5.0, 1000)
    simulate(awake, "--duration", "5", "--events", tmp_path / "e.csv")
    simulate(awake, "--duration", "5", "--events", tmp_path / "all.npz", "--events-kind", "all")
    assert (tmp_path / "e.csv").read_text() == csv_text(impacts, EVENTS)
    assert_npz_equals(tmp_path / "all.npz", every, EVENTS)
    assert len(impacts["time"]) == 47
    assert len(every["time"]) > 30 * len(impacts["time"])
    mid_air = impacts["kind"] == "sphere-sphere"
    assert [(a, b) for a, b in zip(impacts["a"][mid_air], impacts["b"][mid_air], strict=True)] == [
        (2, 3),
        (0, 1),
    ]
    # each ball's last impact is on the ground, and its bounces there get weaker
    for ball in range(5):
        mine = (impacts["a"] == ball) & (impacts["kind"] == "sphere-plane")
        assert impacts["b"][mine][-1] == 0
        ground = impacts["impulse"][mine & (impacts["b"] == 0)]
        assert len(ground) >= 3 and np.all(np.diff(ground) < 0), ground
