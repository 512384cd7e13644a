"""`ballpit bench`: the workloads are the scenes they claim to be, and the table reports every row."""

import numpy as np
import pytest

from ballpit import bench


@pytest.mark.parametrize("n", [1, 30, 1000])
def test_pile_layout_starts_apart_inside_the_box_above_the_floor(n):
    centres, half = bench.pile_layout(n)
    assert centres.shape == (n, 3)
    assert np.all(np.abs(centres[:, [0, 2]]) <= half - bench.RADIUS)
    assert np.all(centres[:, 1] >= bench.RADIUS)
    if n > 1:
        d = np.linalg.norm(centres[:, None] - centres[None], axis=2) + np.eye(n) * 1e9
        assert d.min() > 2 * bench.RADIUS


def test_settled_layout_is_columns_of_touching_balls_on_the_floor():
    centres, half = bench.settled_layout(400)
    assert np.all(np.abs(centres[:, [0, 2]]) <= half - bench.RADIUS + 1e-12)
    assert centres[:, 1].min() == pytest.approx(bench.RADIUS)
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2) + np.eye(400) * 1e9
    assert d.min() == pytest.approx(2 * bench.RADIUS)  # touching, not overlapping
    assert len(np.unique(np.round(centres[:, 1], 9))) == bench.SETTLED_LAYERS  # 400 = 4 layers of 10²


def test_bench_prints_a_row_per_workload_and_size(capsys):
    assert bench.main(["--workload", "pile", "--sizes", "8,27", "--steps", "3"]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.startswith("ballpit  ")]
    table = rows[len(rows) // 2 :]  # rows print as they finish, then again as one table
    assert [(r[1], int(r[2]), int(r[3])) for r in table] == [("pile", 8, 3), ("pile", 27, 3)]
    assert all(float(r[4]) > 0 and float(r[5]) > 0 for r in table)


def test_bench_rejects_sizes_that_are_not_positive_integers(capsys):
    with pytest.raises(SystemExit) as exc:
        bench.main(["--sizes", "10,ten"])
    assert exc.value.code == 2
    assert "sizes must be integers" in capsys.readouterr().err
