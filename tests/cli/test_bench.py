"""`ballpit bench`: the workloads are the scenes they claim to be, and the table reports every row."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ballpit.cli import bench


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
    # ballpit takes a pile in 1/60 s frames of four 1/240 s substeps: 3 steps round up to one frame
    assert bench.main(["--workload", "pile", "--sizes", "8,27", "--steps", "3"]) == 0
    out = capsys.readouterr().out
    assert out.count("steps/s") == 1, "one table, printed once"
    table = [line.split() for line in out.splitlines() if line.startswith("ballpit  ")]
    assert [(r[1], int(r[2]), int(r[3])) for r in table] == [("pile", 8, 4), ("pile", 27, 4)]
    assert all(float(r[4]) > 0 and float(r[5]) > 0 for r in table)


def test_bench_rejects_sizes_that_are_not_positive_integers(capsys):
    with pytest.raises(SystemExit) as exc:
        bench.main(["--sizes", "10,ten"])
    assert exc.value.code == 2
    assert "sizes must be integers" in capsys.readouterr().err


def test_bench_from_the_folder_above_a_clone_is_not_shadowed_by_it(tmp_path):
    """A folder named ``ballpit`` in the working directory (a clone) must not replace the package."""
    (tmp_path / "ballpit" / "src").mkdir(parents=True)
    script = Path(sys.executable).parent / "ballpit"
    args = ["bench", "--workload", "free", "--sizes", "8", "--steps", "2"]
    r = subprocess.run([str(script), *args], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert r.returncode == 0, r.stderr
    assert [line.split()[:3] for line in r.stdout.splitlines() if line.startswith("ballpit  ")] == [
        ["ballpit", "free", "8"]
    ]


def test_a_failing_row_shows_the_childs_error_and_exits_non_zero(tmp_path, monkeypatch, capsys):
    """Children that cannot import ballpit: each row names the child's error; the status is 1."""
    broken = tmp_path / "broken" / "ballpit"
    broken.mkdir(parents=True)
    (broken / "__init__.py").write_text('raise RuntimeError("this ballpit is broken")\n')
    monkeypatch.setenv("PYTHONPATH", str(broken.parent))  # read by the children only
    assert bench.main(["--workload", "free", "--sizes", "8,27", "--steps", "2"]) == 1
    out, err = capsys.readouterr()
    assert not [line for line in out.splitlines() if line.startswith("ballpit  ")]
    lines = err.strip().splitlines()
    assert lines[:2] == [
        "ballpit bench: ballpit free N=8: failed: RuntimeError: this ballpit is broken",
        "ballpit bench: ballpit free N=27: failed: RuntimeError: this ballpit is broken",
    ]
    assert lines[2:] == ["ballpit bench: 2 of 2 measurements failed"]


@pytest.mark.parametrize("demo", ["slopes", "seesaw"])
def test_bench_times_a_demo_with_its_own_five_balls(capsys, demo):
    assert bench.main(["--workload", demo, "--steps", "3", "--pybullet-up-to", "10"]) == 0
    table = [line.split() for line in capsys.readouterr().out.splitlines() if line.startswith("ballpit  ")]
    assert [(r[1], int(r[2]), int(r[3])) for r in table] == [(demo, 5, 3)]
    assert float(table[0][4]) > 0


def test_bench_help_says_its_whole_first_sentence(capsys):
    with pytest.raises(SystemExit) as exc:
        bench.main(["--help"])
    assert exc.value.code == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "a pile at rest, and the slopes and see-saw demos." in help_text


@pytest.mark.parametrize(
    "seconds",
    [(0.16, 0.19), (0.01, 20.0)],  # step times within one decade (the axis labels 1.75), and across four
    ids=["one decade", "four decades"],
)
def test_the_bench_plot_labels_its_axes_with_plain_numbers(seconds):
    results = [
        bench.Result("ballpit", "pile", n, 100, s, 0.0) for n, s in zip((1000, 100_000), seconds, strict=True)
    ]
    fig = bench.figure(results)
    fig.canvas.draw()
    ax = fig.axes[0]
    for axis in (ax.xaxis, ax.yaxis):
        labels = [t.get_text() for t in axis.get_majorticklabels() + axis.get_minorticklabels()]
        labels = [label for label in labels if label]
        assert len(labels) >= 2
        for label in labels:  # "1.75", "0.1", "10,000": no mathtext, no ×10ⁿ
            assert float(label.replace(",", "")) > 0, label
    assert "100,000" in [t.get_text() for t in ax.xaxis.get_majorticklabels()]
