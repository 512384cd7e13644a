"""``ballpit compare``: Euler, RK2 and RK4 on a ball bouncing in a closed box (e = 1, no friction),
checked against the energies known in closed form (see bouncing_box.py), not against earlier output."""

from __future__ import annotations

import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ballpit.cli.compare import compare, format_table, open_scene

from .bouncing_box import (
    DT,
    E0,
    FLIGHT,
    MASS,
    V0,
    G,
    euler_gain_per_flight_formula,
    euler_gain_per_step_law,
    write_scene,
)
from .runner import run_in_process

SHARED = ("cli_run",)  # one real compare run, made once (tests/conftest.py: on one worker)
ROOT = Path(__file__).resolve().parents[2]
FLIGHTS = 3
DURATION = 3.03  # s: a whole number of steps, just past 3 flights of the exact motion (3.029 s)
STEPS = round(DURATION / DT)


def ballpit(*args: str | Path, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return run_in_process(*args, cwd=cwd)


def parse_table(stdout: str) -> dict[str, dict[str, float | str]]:
    """The rows of compare's table by integrator name (the reference as "reference")."""
    lines = stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("integrator"))
    rows = {}
    for line in lines[start + 1 :]:
        if not line.strip():
            break
        cells = line.split()
        name = "reference" if "reference" in line else cells[0]
        steps, drift, percent, max_drift, versus, far_max, far_rms = cells[-7:]
        rows[name] = {
            "steps": int(steps),
            "drift": float(drift),
            "percent": float(percent),
            "max_drift": float(max_drift),
            "versus": versus,
            "far_max": far_max,
            "far_rms": far_rms,
        }
    return rows


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    """One real ``ballpit compare`` run on the box, with a plot."""
    folder = tmp_path_factory.mktemp("compare")
    scene = write_scene(folder)
    png = folder / "drift.png"
    r = ballpit("compare", scene, "--duration", DURATION, "--plot", png)
    return r, png, folder


def test_flights_counted_from_the_exact_flight_time():
    assert math.floor(DURATION / FLIGHT) == FLIGHTS
    assert DURATION - FLIGHTS * FLIGHT < DT  # the run ends within a step of the 3rd flight's end


def test_cli_runs_and_prints_a_row_per_integrator(cli_run):
    r, _, _ = cli_run
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    rows = parse_table(r.stdout)
    assert list(rows) == ["euler", "rk2", "rk4", "symplectic", "reference"]
    assert [rows[k]["steps"] for k in rows] == [STEPS, STEPS, STEPS, STEPS, 4 * STEPS]
    assert f"initial energy {E0:.6g} J" in r.stdout  # m·g·y0


def test_cli_rk2_and_rk4_hold_the_energy(cli_run):
    rows = parse_table(cli_run[0].stdout)
    for name in ("rk2", "rk4", "reference"):
        assert abs(rows[name]["drift"]) < 1e-6 * E0, name
        assert rows[name]["max_drift"] < 1e-6 * E0, name


def test_cli_euler_drift_matches_the_per_flight_formula(cli_run):
    """After k flights explicit Euler's arrival speed is about v0 + k·g·dt, so its energy has grown by
    about ½m(v_k² − v0²). Tolerance 5 %: its flights also lengthen (by about 2·dt each), so by the
    end it has done slightly fewer than k whole flights; the formula's extra ½m·k²·g²·dt² is
    k·g·dt/(2·v0) ≈ 3 % of the gain here, and the split bounce steps gain a little less."""
    rows = parse_table(cli_run[0].stdout)
    expected = euler_gain_per_flight_formula(FLIGHTS)
    assert rows["euler"]["drift"] == pytest.approx(expected, rel=0.05)
    assert rows["euler"]["percent"] == pytest.approx(100 * expected / E0, rel=0.05)
    assert FLIGHTS * G * DT / (2 * V0) < 0.04  # the size of the neglected term, as claimed


def test_cli_euler_drift_matches_the_per_step_law(cli_run):
    """Every whole step of free flight adds exactly ½·m·g²·dt². The k bounce steps are split at the
    impact and a split step gains between half and all of that (at most k·¼·m·g²·dt² less in all,
    0.5 % here): 1 %."""
    rows = parse_table(cli_run[0].stdout)
    assert rows["euler"]["drift"] == pytest.approx(euler_gain_per_step_law(STEPS), rel=0.01)
    assert FLIGHTS * 0.25 * MASS * G**2 * DT**2 < 0.005 * euler_gain_per_step_law(STEPS)
    assert rows["euler"]["max_drift"] == pytest.approx(rows["euler"]["drift"], rel=0.01)  # it only grows


def test_cli_rk4_ends_much_closer_to_the_reference_than_euler(cli_run):
    rows = parse_table(cli_run[0].stdout)
    euler, rk4 = float(rows["euler"]["far_max"]), float(rows["rk4"]["far_max"])
    assert rk4 < 1e-3 * euler
    assert float(rows["rk4"]["far_rms"]) == pytest.approx(rk4)  # one ball: RMS = max
    assert rows["reference"]["far_max"] == "-"


def test_cli_plot_is_a_real_png(cli_run):
    r, png, folder = cli_run
    with Image.open(png) as im:
        assert im.format == "PNG"
        assert 600 <= im.width <= 2000 and 400 <= im.height <= 1500
        colours = im.convert("RGB").getcolors(maxcolors=1 << 16)
    assert colours is None or len(colours) > 20  # lines and text, not a blank canvas
    assert f"wrote {png}" in r.stdout
    assert not [p.name for p in folder.iterdir() if p.name.endswith(".partial")]


def test_python_api_matches_closed_form(tmp_path):
    """Step by step: Euler's energy in the first fall gains exactly ½·m·g²·dt² per step; RK4's holds."""
    scene = open_scene(write_scene(tmp_path))
    assert scene.timestep == DT
    result = compare(scene.world, 1.0, scene.timestep, name="box")
    assert scene.world.time == 0.0  # every run stepped its own copy
    euler, rk2, rk4, symplectic = result.runs
    assert (euler.integrator, rk2.integrator, rk4.integrator) == ("euler", "rk2", "rk4")
    assert symplectic.integrator == "symplectic"
    assert result.reference.dt == pytest.approx(DT / 4)
    landing = math.floor((V0 / G) / DT)  # steps before the first landing (exact motion)
    n = np.arange(landing - 1)
    expected = n * 0.5 * MASS * G**2 * DT**2
    np.testing.assert_allclose(euler.energy.drift[: len(n)], expected, rtol=1e-9, atol=1e-12 * E0)
    # symplectic Euler loses what Euler gains: v_n = −g·n·dt, y_n = y0 − g·dt²·n(n+1)/2
    np.testing.assert_allclose(symplectic.energy.drift[: len(n)], -expected, rtol=1e-9, atol=1e-12 * E0)
    # the same fall, state by state: v_n = −g·n·dt, y_n = y0 − g·dt²·n(n−1)/2
    np.testing.assert_allclose(euler.energy.kinetic[: len(n)], 0.5 * MASS * (G * n * DT) ** 2, atol=1e-12)
    assert rk4.max_abs_drift < 1e-9 * E0 and rk2.max_abs_drift < 1e-9 * E0
    far_euler, far_rk4 = result.distance(euler)[0], result.distance(rk4)[0]
    assert far_rk4 < 1e-3 * far_euler
    text = "\n".join(format_table(result, 1))
    assert "box: 1 ball, 1 s in steps of 10 ms" in text


def test_bad_scene_is_one_line(tmp_path):
    r = ballpit("compare", tmp_path / "missing.toml")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and "missing.toml" in r.stderr


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--duration", "-1"], "--duration"),
        (["--dt", "fast"], "--dt"),
        (["--plot", "drift.jpg"], "--plot"),
        (["--plot", "no/such/folder/drift.png"], "does not exist"),
        (["--duration", "1e12"], "limit"),
    ],
)
def test_bad_options_are_one_line(tmp_path, args, fragment):
    scene = write_scene(tmp_path)
    r = ballpit("compare", scene, *args, cwd=tmp_path)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and r.stderr.count("\n") == 1 and fragment in r.stderr, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.toml"]


def test_plot_under_a_file_is_one_line(tmp_path):
    scene = write_scene(tmp_path)
    (tmp_path / "notes.txt").write_text("not a folder\n")
    r = ballpit("compare", scene, "--duration", "0.1", "--plot", tmp_path / "notes.txt" / "drift.png")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "not a directory" in r.stderr, r.stderr


def test_unwritable_plot_folder_is_one_line(tmp_path):
    scene = write_scene(tmp_path)
    if os.geteuid() == 0:  # root writes anywhere a mode allows; sysfs takes no new files from anyone
        locked = Path("/sys")
    else:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o555)
    before = sorted(locked.iterdir())
    try:
        r = ballpit("compare", scene, "--duration", "0.1", "--plot", locked / "drift.png")
        assert r.returncode == 2 and r.stderr.count("\n") == 1 and "cannot write" in r.stderr, r.stderr
        assert sorted(locked.iterdir()) == before
    finally:
        if locked != Path("/sys"):
            locked.chmod(0o755)


def test_a_stop_recorded_but_not_raised_ends_the_comparison_at_its_next_step():
    """As simulate's loop does: a stop signal whose exception Python dropped (cli.raise_if_stopped)
    is raised again by the stepping loop, not left to run every integrator to the end."""
    import signal

    import ballpit
    import ballpit.cli as cli

    world = ballpit.World()
    world.add_sphere(position=(0, 1, 0), radius=0.1)
    cli._stopped_by[:] = [signal.SIGTERM]
    try:
        with pytest.raises(cli.Terminated):
            compare(world, 1.0, 0.01)
    finally:
        cli._stopped_by.clear()
