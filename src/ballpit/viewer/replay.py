"""Replaying a trajectory written by ``ballpit simulate --out`` (or the viewer's ``--record``).

``read_trajectory`` loads a ``.csv`` or ``.npz`` trajectory into per-frame arrays and checks that it
fits a scene's balls; anything wrong is a ``TrajectoryError`` whose one-line message names the file.
``Replay`` is the viewer's timeline for it: frame k is written into the scene's World (positions,
velocities, spins, orientations, time), so everything that reads the world draws it. No GL here.
"""

from __future__ import annotations

import bisect
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ballpit.writers import TRAJECTORY_COLUMNS

# stacked .npz arrays → (their width, the CSV column they start at)
STACKED = {
    "position": (3, "x"),
    "velocity": (3, "vx"),
    "angular_velocity": (3, "wx"),
    "orientation": (4, "qx"),
}


class TrajectoryError(ValueError):
    """A trajectory that cannot be read or does not fit the scene."""


@dataclass
class Trajectory:
    """Frames of every ball's state: ``times`` (F,), ``position`` (F, N, 3), ``velocity`` (F, N, 3),
    ``angular_velocity`` (F, N, 3), ``orientation`` (F, N, 4)."""

    path: Path
    times: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    orientation: np.ndarray

    @property
    def frames(self) -> int:
        return len(self.times)

    @property
    def balls(self) -> int:
        return self.position.shape[1]


def _columns_from_csv(path: Path) -> dict[str, np.ndarray]:
    with path.open("r", encoding="utf-8") as f:
        header = [name.strip() for name in f.readline().strip().split(",")]
        if header == [""]:
            raise TrajectoryError(f"{path}: empty file, not a trajectory")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # no rows: checked below, by name
            data = np.loadtxt(f, delimiter=",", ndmin=2)
    if data.size and data.shape[1] != len(header):
        raise TrajectoryError(f"{path}: rows have {data.shape[1]} values but the header names {len(header)}")
    data = data.reshape(-1, len(header))
    return {name: data[:, k] for k, name in enumerate(header)}


def _columns_from_npz(path: Path) -> dict[str, np.ndarray]:
    if path.is_file() and not zipfile.is_zipfile(path):
        raise TrajectoryError(f"{path}: not an .npz archive")
    with np.load(path, allow_pickle=False) as npz:
        arrays = {name: np.asarray(npz[name]) for name in npz.files}
    for name, (width, column) in STACKED.items():  # stacked (rows, k) arrays → the CSV's columns
        if name in arrays and arrays[name].ndim == 2 and arrays[name].shape[1] == width:
            stacked = arrays.pop(name)
            start = TRAJECTORY_COLUMNS.index(column)
            for k in range(width):
                arrays.setdefault(TRAJECTORY_COLUMNS[start + k], stacked[:, k])
    return arrays


def read_trajectory(path: Path | str, n_balls: int | None = None) -> Trajectory:
    """Load a trajectory file (``.csv`` or ``.npz``); with ``n_balls``, check it has that many balls."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".npz"):
        raise TrajectoryError(f"{path}: a trajectory must be a .csv or .npz file")
    try:
        columns = _columns_from_csv(path) if suffix == ".csv" else _columns_from_npz(path)
    except TrajectoryError:
        raise
    except FileNotFoundError:
        raise TrajectoryError(f"{path}: no such file") from None
    except (OSError, ValueError, zipfile.BadZipFile, UnicodeDecodeError, EOFError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise TrajectoryError(f"{path}: cannot read the trajectory ({reason})") from None
    missing = [name for name in TRAJECTORY_COLUMNS if name not in columns]
    if missing:
        raise TrajectoryError(f"{path}: missing trajectory columns: {', '.join(missing)}")
    try:
        table = np.column_stack([np.asarray(columns[name], dtype=float).reshape(-1)
                                 for name in TRAJECTORY_COLUMNS])  # fmt: skip
    except ValueError:
        raise TrajectoryError(f"{path}: the trajectory columns have different lengths") from None
    if len(table) == 0:
        raise TrajectoryError(f"{path}: the trajectory has no rows")
    if not np.all(np.isfinite(table)):
        raise TrajectoryError(f"{path}: the trajectory holds values that are not finite numbers")
    ids = table[:, 1]
    count = int(ids.max()) + 1
    if count * (len(table) // count) != len(table) or not np.array_equal(
        ids.reshape(-1, count), np.broadcast_to(np.arange(count), (len(table) // count, count))
    ):
        raise TrajectoryError(f"{path}: rows must list ids 0..N-1 for every recorded time")
    if n_balls is not None and count != n_balls:
        raise TrajectoryError(f"{path}: the trajectory has {count} balls but the scene has {n_balls}")
    frames = table.reshape(-1, count, len(TRAJECTORY_COLUMNS))
    times = frames[:, 0, 0].copy()
    if np.any(np.diff(times) < 0) or np.any(frames[:, :, 0] != times[:, None]):
        raise TrajectoryError(f"{path}: the times must be the same for every ball of a record, never falling")
    return Trajectory(path, times, frames[:, :, 2:5].copy(), frames[:, :, 5:8].copy(),
                      frames[:, :, 8:11].copy(), frames[:, :, 11:15].copy())  # fmt: skip


class Replay:
    """A trajectory as the viewer's timeline: steps are frames; ``seek(k)`` shows frame k."""

    def __init__(self, world: Any, trajectory: Trajectory) -> None:
        self.world = world
        self.trajectory = trajectory
        self.first = 0
        self.latest = trajectory.frames - 1
        self.current = -1
        self.last_contacts: Any = None
        diffs = np.diff(trajectory.times)
        positive = diffs[diffs > 0]
        self.timestep = float(np.median(positive)) if len(positive) else 1.0 / 60.0
        self.clock = float(trajectory.times[0])  # replay time reached by ``step``
        self.seek(0)

    in_past = False  # resuming a replay plays on; nothing is dropped

    def time_of(self, step: int) -> float:
        return float(self.trajectory.times[step] - self.trajectory.times[0])

    def seek(self, step: int) -> int:
        """Write frame ``step`` (clamped) into the world."""
        step = int(min(max(step, self.first), self.latest))
        t = self.trajectory
        spheres = self.world.spheres
        spheres.positions[:] = t.position[step]
        spheres.velocities[:] = t.velocity[step]
        spheres.angular_velocities[:] = t.angular_velocity[step]
        spheres.orientations[:] = t.orientation[step]
        self.world.time = float(t.times[step])
        self.current = step
        self.clock = float(t.times[step])
        return step

    def step_by(self, steps: int) -> int:
        return self.seek(self.current + steps)

    def advance(self, seconds: float) -> bool:
        """Play on by ``seconds`` of recorded time; False once the last frame is shown."""
        times = self.trajectory.times
        self.clock += seconds
        frame = max(bisect.bisect_right(times.tolist(), self.clock + 1e-12) - 1, self.current)
        clock = self.clock
        if frame != self.current:
            self.seek(frame)
            self.clock = clock
        return self.current < self.latest

    def fraction(self) -> float:
        span = self.latest - self.first
        return 1.0 if span <= 0 else (self.current - self.first) / span
