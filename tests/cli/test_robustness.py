"""The command line under hostile conditions (issue #25, section 3): a closed stdout, a stop signal
while the modules still import, a step longer than the run. In-process where the process itself is
not the point."""

from __future__ import annotations

import importlib.metadata
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import ballpit
from ballpit import cli
from ballpit.cli.simulate import run

ROOT = Path(__file__).resolve().parents[2]


def test_a_closed_stdout_ends_the_run_quietly():
    """`ballpit scenes | head -0`: the reader is gone before anything is written."""
    with subprocess.Popen(
        [sys.executable, "-m", "ballpit", "scenes"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    ) as proc:  # on the way out its pipes are closed and it is reaped
        proc.stdout.close()
        stderr = proc.stderr.read()
        proc.wait(timeout=60)
    assert "Traceback" not in stderr and "BrokenPipeError" not in stderr, stderr
    assert stderr == ""
    assert proc.returncode == cli.EXIT_BROKEN_PIPE


_SIGNAL_WHILE_IMPORTING = """
import builtins, os, signal, sys
import ballpit.cli as cli
assert not any(m.split(".")[0] == "numpy" for m in sys.modules), "the command line imported NumPy"
real = builtins.__import__
def hooked(name, *args, **kwargs):
    if name.split(".")[0] == "numpy":  # the first heavy import: the physics, inside main
        builtins.__import__ = real
        os.kill(os.getpid(), signal.{signal})
    return real(name, *args, **kwargs)
builtins.__import__ = hooked
sys.exit(cli.main(["check", "slopes"]))
"""


@pytest.mark.parametrize(("name", "status"), [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_stop_signal_while_the_modules_import_exits_quietly(name, status):
    code = _SIGNAL_WHILE_IMPORTING.replace("{signal}", name)
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == status, r.stderr
    assert "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr


@pytest.mark.parametrize(
    "command", [["scenes"], ["check", "slopes"], ["simulate", "slopes", "--duration", "0.1"]]
)
def test_a_closed_stdout_is_one_line_and_status_1(command):
    # `ballpit scenes >&-` was an 8-line AttributeError traceback.
    r = subprocess.run(
        [sys.executable, "-m", "ballpit", *command],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        pass_fds=(),
        preexec_fn=lambda: os.close(1),
    )
    assert (r.returncode, r.stderr) == (cli.EXIT_FAILED, "ballpit: cannot write to stdout: it is closed\n")


def test_a_quiet_run_with_stdout_closed_writes_its_files_and_succeeds(tmp_path):
    out = tmp_path / "run.csv"  # opened while descriptor 1 is free: it must not become stdout
    command = ["simulate", "slopes", "--duration", "0.1", "-q", "--out", str(out)]
    r = subprocess.run(
        [sys.executable, "-m", "ballpit", *command],
        cwd=ROOT,
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        preexec_fn=lambda: os.close(1),
    )
    assert (r.returncode, r.stderr) == (0, "")
    assert out.read_text().startswith("time,id,x,y,z,")


@pytest.mark.parametrize(
    "command", [["scenes"], ["check", "slopes"], ["simulate", "slopes", "--duration", "0.1"]]
)
def test_a_full_stdout_is_one_line_and_status_1(command):
    with open("/dev/full", "w") as full:
        r = subprocess.run(
            [sys.executable, "-m", "ballpit", *command],
            cwd=ROOT,
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert (r.returncode, r.stderr) == (
        cli.EXIT_FAILED,
        "ballpit: cannot write to stdout: No space left on device\n",
    )


_STARTED_THEN_MAIN = """
import os, sys
import ballpit
os.write(2, b"!")  # Python's own start-up is over
from {module} import {function} as main
sys.exit(main(["check", "slopes"]))
"""


@pytest.mark.slow
def test_ctrl_c_at_any_moment_after_python_started_exits_130_in_one_line():
    # Signals 35-111 ms after start, while ballpit.cli still imported, gave a 12-14 line traceback in
    # 28 of 60 tries: now the entry point routes Ctrl+C before it imports anything that takes time.
    spec = next(e for e in importlib.metadata.entry_points(group="console_scripts") if e.name == "ballpit")
    code = _STARTED_THEN_MAIN.format(module=spec.module, function=spec.attr)
    rng = random.Random(32)
    for _ in range(12):
        with subprocess.Popen(
            [sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
        ) as proc:
            assert proc.stderr.read(1) == b"!"
            time.sleep(rng.uniform(0.005, 0.25))  # the imports, the scene, the check itself
            proc.send_signal(signal.SIGINT)
            stderr = proc.stderr.read().decode()
            proc.wait(timeout=60)
        assert "Traceback" not in stderr, stderr
        if proc.returncode == -signal.SIGINT:
            # The signal came after main had returned and given Ctrl+C back: Python then ends by the
            # signal itself, which a shell reports as 130 too, and prints nothing.
            assert stderr == ""
        elif proc.returncode != 0:  # else the check was done before the signal came
            assert (proc.returncode, stderr) == (cli.EXIT_INTERRUPTED, "ballpit: interrupted\n")


def test_the_entry_point_imports_almost_nothing_before_it_routes_ctrl_c():
    code = (
        "import sys; before = set(sys.modules)\nimport ballpit.cli\nprint(sorted(set(sys.modules) - before))"
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert set(eval(r.stdout)) <= {"ballpit", "ballpit.cli", "signal", "_signal"}


@pytest.mark.parametrize("command", ["simulate", "compare"])
def test_a_step_longer_than_the_run_is_refused_in_one_line(command, capsys):
    status = cli.main([command, "slopes", "--dt", "100", "--duration", "5", "-q"])
    err = capsys.readouterr().err
    assert status == cli.EXIT_BAD_INPUT
    assert len(err.strip().splitlines()) == 1
    assert "a step of 100 s is longer than the run (5 s)" in err


@pytest.mark.parametrize("command", ["simulate", "compare"])
def test_a_step_longer_than_a_step_may_be_is_refused_in_one_line(command, capsys):
    status = cli.main([command, "slopes", "--dt", "2e9", "--duration", "1e10", "-q"])
    err = capsys.readouterr().err
    assert status == cli.EXIT_BAD_INPUT
    assert err.endswith("a step of 2e+09 s is longer than a step may be (1e+09 s): use a smaller --dt\n"), err


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["render", "slopes", "--out", "x.gif", "--size", "-5x10"], "--size: must be between 16 and 8192"),
        (["simulate", "slopes", "--dt", "-1e-3"], "--dt: must be positive and finite, got '-1e-3'"),
    ],
)
def test_a_value_that_starts_like_a_negative_number_is_checked_as_a_value(args, fragment, capsys):
    # "--size -5x10" said "expected one argument": argparse took the value for an option.
    with pytest.raises(SystemExit) as exit_:
        cli.main(args)
    err = capsys.readouterr().err
    assert exit_.value.code == cli.EXIT_BAD_INPUT and fragment in err and len(err.splitlines()) == 1


def test_run_reports_the_time_it_stepped_when_the_step_is_longer_than_the_run():
    world = ballpit.World(gravity=(0, 0, 0))
    world.add_sphere(position=(0, 0, 0), velocity=(1, 0, 0))
    summary = run(world, 5.0, 1e10)
    assert summary.steps == 1
    assert summary.sim_time == world.time == 5.0
    assert world.spheres[0].position[0] == pytest.approx(5.0)  # x = v·t: 5 s were stepped


def test_the_stop_handlers_are_restored_after_main(capsys):
    before = signal.getsignal(signal.SIGTERM)
    assert cli.main(["check", "slopes"]) == 0
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_run_killed_outright_leaves_a_visible_partial_file_that_the_next_run_removes(tmp_path, capsys):
    out = tmp_path / "run.npz"
    proc = subprocess.Popen(
        [sys.executable, "-m", "ballpit", "simulate", "pile", "--duration", "60", "--out", str(out), "-q"],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        while not list(tmp_path.glob("*.partial")) and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        proc.kill()
        proc.wait(timeout=60)
    left = [p.name for p in tmp_path.iterdir()]
    assert left == [f"run.npz.{proc.pid}.partial"]  # in plain sight, named as unfinished
    assert cli.main(["simulate", "slopes", "--duration", "0.01", "--out", str(out), "-q"]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["run.npz"]


def test_a_partial_file_of_a_running_process_is_left_alone(tmp_path, capsys):
    out = tmp_path / "run.csv"
    live = tmp_path / f"run.csv.{os.getppid()}.partial"  # the test runner's parent: alive
    live.write_text("time,id\n")
    assert cli.main(["simulate", "slopes", "--duration", "0.01", "--out", str(out), "-q"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["run.csv", live.name])


def _ballpit(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "ballpit", *args], cwd=ROOT, capture_output=True, text=True, timeout=timeout
    )


def _one_line_error(r: subprocess.CompletedProcess, *fragments: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr[-2000:]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.parametrize(
    ("out", "duration", "fragments"),
    [
        ("demo.gif", "1e308", ["1e+308 s at 30 fps is inf frames", "the limit is 100,000"]),
        ("frames/", "1e308", ["is inf frames"]),
        ("demo.gif", "60", ["1,800 frames of 960x540", "at most 1,035 at this size", "PNG frames"]),
    ],
)
def test_a_render_longer_than_its_output_can_take_is_refused_before_any_frame(
    tmp_path, out, duration, fragments
):
    r = _ballpit("render", "slopes", "--out", str(tmp_path / out), "--duration", duration, timeout=60)
    _one_line_error(r, *fragments)
    assert list(tmp_path.iterdir()) == []


def test_a_render_to_a_place_that_cannot_be_written_is_refused_before_any_frame():
    r = _ballpit("render", "slopes", "--out", "/proc/ballpit-demo.gif", "--duration", "0.1", timeout=60)
    _one_line_error(r, "/proc/ballpit-demo.gif: --out: cannot write in '/proc'")


@pytest.mark.parametrize(
    ("plot", "fragment"),
    [
        ("{tmp}", "--plot must end in .png, .svg or .pdf, not 'no suffix'"),
        ("{tmp}/missing/plot.png", "--plot: directory '{tmp}/missing' does not exist"),
        ("{tmp}/plot.xyz", "--plot must end in .png, .svg or .pdf, not '.xyz'"),
    ],
)
def test_bench_refuses_a_bad_plot_path_before_measuring(tmp_path, capsys, plot, fragment):
    plot, fragment = (s.replace("{tmp}", str(tmp_path)) for s in (plot, fragment))
    status = cli.main(["bench", "--workload", "slopes", "--steps", "1", "--plot", plot])
    captured = capsys.readouterr()
    assert status == 2
    assert captured.out == ""  # not even the table's header: nothing was measured
    assert captured.err.strip().splitlines() == [f"ballpit bench: {plot}: {fragment}"]


def test_bench_refuses_a_timeout_too_long_for_the_clock(capsys):
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["bench", "--workload", "slopes", "--timeout", "1e308"])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert "argument --timeout: must be at most 1e+06 seconds, got '1e308'" in err
    assert len(err.strip().splitlines()) == 1


_WRAPPED_INTERRUPT = """
import importlib.abc, os, signal, sys


class WrapsInterrupts(importlib.abc.MetaPathFinder):
    # What NumPy's C extension does when Ctrl+C lands in its import of datetime: the
    # KeyboardInterrupt comes out as an ImportError.
    def find_spec(self, name, path, target=None):
        if name == "ballpit.cli.commands":
            try:
                os.kill(os.getpid(), signal.SIGINT)
            except KeyboardInterrupt as e:
                raise ImportError("PyCapsule_Import could not import module datetime") from e
        return None


sys.meta_path.insert(0, WrapsInterrupts())
from {module} import {function} as main
sys.exit(main(["check", "slopes"]))
"""


def test_ctrl_c_that_a_library_turns_into_an_import_error_still_exits_130_in_one_line():
    spec = next(e for e in importlib.metadata.entry_points(group="console_scripts") if e.name == "ballpit")
    code = _WRAPPED_INTERRUPT.format(module=spec.module, function=spec.attr)
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert (r.returncode, r.stderr) == (cli.EXIT_INTERRUPTED, "ballpit: interrupted\n")


def test_an_import_error_with_no_stop_signal_is_not_taken_for_one():
    code = _WRAPPED_INTERRUPT.format(module="ballpit.cli", function="main").replace(
        "os.kill(os.getpid(), signal.SIGINT)",
        "raise ImportError('broken install')",
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "ImportError: broken install" in r.stderr
