"""``ballpit simulate --plot``: the energies recorded every step (checked against the closed form of
an Euler ball's fall, see bouncing_box.py) and the PNG written complete or not at all."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ballpit.cli.energy_trace import EnergyRecorder
from ballpit.cli.simulate import run
from ballpit.scene import load_scene

from .bouncing_box import DT, E0, MASS, V0, Y0, G, euler_gain_per_step_law, write_scene
from .runner import run_in_process
from .test_commands import interrupt_while_writing

ROOT = Path(__file__).resolve().parents[2]


def ballpit(*args: str | Path) -> subprocess.CompletedProcess:
    return run_in_process(*args, cwd=ROOT)


def test_run_records_the_energies_every_step(tmp_path):
    """Euler's fall from rest, state by state: v_n = −g·n·dt, y_n = y0 − g·dt²·n(n−1)/2."""
    world = load_scene(write_scene(tmp_path))
    world.integrator = "euler"
    record = EnergyRecorder()
    summary = run(world, 2.0, DT, observe=record)
    trace = record.trace()
    assert len(trace) == summary.steps + 1 == round(2.0 / DT) + 1
    np.testing.assert_allclose(trace.time, np.arange(len(trace)) * DT, atol=1e-12)
    n = np.arange(int((V0 / G) / DT) - 1)  # the steps before the first landing
    np.testing.assert_allclose(trace.kinetic[n], 0.5 * MASS * (G * n * DT) ** 2, rtol=1e-12, atol=1e-12)
    y = Y0 - G * DT**2 * n * (n - 1) / 2
    np.testing.assert_allclose(trace.potential[n], MASS * G * y, rtol=1e-12)
    assert trace.total[0] == pytest.approx(E0, rel=1e-12)
    # and over the whole run (two landings, split steps gain a little less): ½·m·g²·dt² a step
    assert trace.drift[-1] == pytest.approx(euler_gain_per_step_law(summary.steps), rel=0.01)


def test_simulate_plot_writes_a_png(tmp_path):
    scene = write_scene(tmp_path)
    png = tmp_path / "energy.png"
    r = ballpit("simulate", scene, "--duration", "2", "--integrator", "euler", "--plot", png)
    assert r.returncode == 0, r.stderr
    assert f"wrote {png} (energies at {round(2 / DT) + 1} times)" in r.stdout
    with Image.open(png) as im:
        assert im.format == "PNG"
        assert 600 <= im.width <= 2000 and 400 <= im.height <= 1500
        colours = im.convert("RGB").getcolors(maxcolors=1 << 16)
    assert colours is None or len(colours) > 20  # lines and text, not a blank canvas
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.toml", "energy.png"]


@pytest.mark.parametrize("suffix", [".svg", ".pdf"])
def test_simulate_plot_other_formats(tmp_path, suffix):
    scene = write_scene(tmp_path)
    out = tmp_path / f"energy{suffix}"
    r = ballpit("simulate", scene, "--duration", "0.2", "--plot", out, "-q")
    assert r.returncode == 0, r.stderr
    head = out.read_bytes()[:5]
    assert head == (b"%PDF-" if suffix == ".pdf" else b"<?xml")


@pytest.mark.parametrize(
    ("plot", "fragment"),
    [
        ("energy.gif", "--plot must end in .png, .svg or .pdf"),
        ("missing/energy.png", "does not exist"),
        (".", "--plot"),
    ],
)
def test_bad_plot_path_is_one_line_and_nothing_runs(tmp_path, plot, fragment):
    scene = write_scene(tmp_path)
    r = ballpit("simulate", scene, "--duration", "100", "--plot", tmp_path / plot)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and fragment in r.stderr, r.stderr
    assert r.stdout == ""  # refused before the run
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.toml"]


@pytest.mark.slow
def test_interrupted_run_leaves_no_plot(tmp_path):
    scene = write_scene(tmp_path, dt=1e-4)
    png = tmp_path / "energy.png"
    status, stderr = interrupt_while_writing(["simulate", scene, "--duration", "60", "--plot", png], tmp_path)
    assert status == 130, stderr
    assert "Traceback" not in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.toml"]
