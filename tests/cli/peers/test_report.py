"""`ballpit bench --peers`: the engines take turns, the table's medians and ratios are right, and a real
run of a small grid writes a CSV whose every engine landed the balls in the box."""

import csv
import importlib.util
import statistics

import pytest

from ballpit.cli import bench
from ballpit.cli.peers import report
from ballpit.cli.peers.engines import ENGINES
from ballpit.cli.peers.landing import RESTITUTION
from ballpit.cli.peers.measure import Landed

from .test_engines import ALL, BOUNCE_TOLERANCE

SHARED = ("small_grid",)  # a real run of every installed engine, made once (tests/conftest.py: on one worker)
RATES = {"ballpit": [300.0, 100.0, 200.0], "mujoco": [50.0, 40.0, 60.0], "pybullet": [20.0, 25.0, 30.0]}


class FakeLandings:
    """Stands in for the child processes: each engine's rates in turn, and the order it was asked in."""

    def __init__(self, fail: set[tuple[str, int]] = frozenset()):
        self.calls: list[tuple[str, int]] = []
        self.fail = fail

    def __call__(self, engine: str, n: int, steps: int, timeout: float):
        self.calls.append((engine, n))
        if (engine, n) in self.fail:
            return "RuntimeError: it broke"
        rate = RATES[engine][sum(1 for e, m in self.calls if (e, m) == (engine, n)) - 1]
        return Landed(engine, "1.0", f"{engine} settings", n, steps, steps / rate, 0.1, 0.01, n, 0.25)


@pytest.fixture
def every_engine_installed(monkeypatch):
    monkeypatch.setattr(report, "installed_peers", lambda engines: (engines, []))


def test_the_engines_take_turns_round_after_round_at_each_size(every_engine_installed, capsys):
    fake = FakeLandings()
    assert report.run_peers([10, 20], 48, 3, 60.0, land_one=fake) == 0
    assert fake.calls == [
        (e, n) for n in (10, 20) for _ in range(3) for e in ("ballpit", "mujoco", "pybullet")
    ]


def test_the_table_shows_each_engines_median_and_its_ratio_to_the_faster_peer(every_engine_installed, capsys):
    assert report.run_peers([10], 48, 3, 60.0, land_one=FakeLandings()) == 0
    rows = {
        line.split()[1]: line.split() for line in capsys.readouterr().out.splitlines() if line[:6] == "    10"
    }
    medians = {engine: statistics.median(rates) for engine, rates in RATES.items()}  # 200, 50, 25
    for engine, fields in rows.items():
        assert float(fields[2]) == medians[engine]
        assert fields[4] == f"{medians[engine] / medians['mujoco']:.2f}x"
    assert rows["ballpit"][4] == "4.00x"


def test_a_failed_run_is_named_and_the_status_is_one(every_engine_installed, capsys):
    fake = FakeLandings(fail={("mujoco", 10)})
    assert report.run_peers([10], 48, 1, 60.0, land_one=fake) == 1
    err = capsys.readouterr().err
    assert "MuJoCo N=10 round 1: failed: RuntimeError: it broke" in err
    assert "1 of 3 runs failed" in err


def test_without_any_peer_installed_it_says_what_to_install(monkeypatch, capsys):
    monkeypatch.setattr(report, "installed_peers", lambda engines: (["ballpit"], ["mujoco", "pybullet"]))
    assert report.run_peers([10], 48, 1, 60.0, land_one=FakeLandings()) == 2
    err = capsys.readouterr().err
    assert "MuJoCo is not installed" in err
    assert err.strip().splitlines()[-1] == (
        "ballpit bench: --peers needs MuJoCo or PyBullet: pip install 'ballpit[bench]'"
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--rounds", "2"], "--rounds goes with --peers"),
        (["--csv", "x.csv"], "--csv goes with --peers"),
        (["--peers", "--workload", "free"], "--workload does not go with --peers"),
        (["--peers", "--pybullet"], "--pybullet does not go with --peers"),
    ],
)
def test_options_that_do_not_go_together_are_one_line_and_status_two(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        bench.main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_csv_path_that_is_not_a_csv_is_refused_before_any_run(every_engine_installed, tmp_path, capsys):
    fake = FakeLandings()
    assert report.run_peers([10], 48, 1, 60.0, csv_path=tmp_path / "runs.txt", land_one=fake) == 2
    assert fake.calls == []
    assert "runs.txt: --csv must end in .csv" in capsys.readouterr().err


@pytest.fixture(scope="module")
def small_grid(tmp_path_factory):
    """A real run: 27 balls, the first second (240 steps), one round, every installed engine."""
    folder = tmp_path_factory.mktemp("peers")
    argv = ["--peers", "--sizes", "27", "--steps", "240", "--rounds", "1"]
    status = bench.main([*argv, "--csv", str(folder / "runs.csv"), "--plot", str(folder / "runs.png")])
    with open(folder / "runs.csv", newline="") as f:
        reader = csv.DictReader(f)
        return status, reader.fieldnames, {row["engine"]: row for row in reader}, folder


@pytest.mark.slow
def test_the_csv_has_a_row_per_installed_engine_with_its_columns(small_grid):
    status, columns, rows, folder = small_grid
    assert status == 0
    assert tuple(columns) == report.CSV_COLUMNS
    installed = {
        name for name, e in ENGINES.items() if e.package is None or importlib.util.find_spec(e.package)
    }
    assert set(rows) == installed
    assert (folder / "runs.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
@pytest.mark.parametrize("engine", ALL)
def test_each_engine_lands_the_small_grid_in_its_box_without_passing_through(small_grid, engine):
    row = small_grid[2][engine]
    assert (int(row["balls"]), int(row["round"]), int(row["steps"])) == (27, 1, 240)
    assert float(row["steps_per_second"]) == pytest.approx(240 / float(row["seconds"]), rel=1e-5)
    assert int(row["inside"]) == 27
    assert 0.0 <= float(row["max_overlap_r"]) < 0.5  # the deepest contact well under a radius
    # The landing is over after 1 s: the top layer lands at 2.3 m/s and each bounce keeps a quarter of
    # the approach speed; what still moves rolls on the floor (no rolling resistance, room to roll).
    assert 0.0 <= float(row["final_max_speed"]) < 0.5
    assert float(row["bounce_e"]) == pytest.approx(RESTITUTION, abs=BOUNCE_TOLERANCE[engine])
    assert row["settings"] == ENGINES[engine].settings().describe()


def test_each_peer_names_its_fastest_stable_settings():
    assert ENGINES["mujoco"].settings().describe().startswith("implicitfast, elliptic cones, CG solver")
    assert ENGINES["pybullet"].settings().describe().startswith("rigid bodies (useMaximalCoordinates=True)")


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_the_plot_has_the_sizes_run_on_its_x_axes_and_plain_numbers_for_the_rates():
    summaries = [
        report.Summary(engine, n, [rate * 1000 / n], 0.2, 0.01, n, 0.25)
        for engine, rate in (("ballpit", 40.0), ("mujoco", 30.0), ("pybullet", 20.0))
        for n in (1000, 3000, 10000)
    ]
    fig = report.figure(summaries)
    fig.canvas.draw()
    rate, overlap = fig.axes
    for ax in (rate, overlap):
        assert [t.get_text() for t in ax.xaxis.get_majorticklabels()] == ["1,000", "3,000", "10,000"]
    labels = [t.get_text() for t in rate.yaxis.get_majorticklabels() + rate.yaxis.get_minorticklabels()]
    labels = [label for label in labels if label]
    assert len(labels) >= 2
    for label in labels:  # "2", "10", "40": no mathtext, no ×10ⁿ
        assert float(label.replace(",", "")) > 0, label
    assert [line.get_label() for line in overlap.get_lines()] == ["ballpit", "MuJoCo", "PyBullet"]
