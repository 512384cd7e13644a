"""The command line: exit codes, one-line errors, output files and their columns.

Run in this process (``runner.py``) except where the process itself is under test: signals, file
size limits and the console script start a real ``python -m ballpit``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from ballpit.scene import load_scene

from .runner import ROOT
from .runner import run_in_process as ballpit

TRAJECTORY_HEADER = "time,id,x,y,z,vx,vy,vz,wx,wy,wz,qx,qy,qz,qw"
EVENTS_HEADER = "time,kind,a,b,x,y,z,nx,ny,nz,impulse"


def assert_user_error(r: subprocess.CompletedProcess, *expected: str) -> str:
    """Exit status 2, no traceback, one line on stderr containing every expected fragment."""
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    for fragment in expected:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


BALL = "[[sphere]]\nposition = [0, 1, 0]\n"

# (name, scene text, fragments the one-line message must contain). Line numbers are the line of the
# offending key (or the entry's header when no key is at fault).
BAD_SCENES = [
    ("syntax error", "[world]\ngravity = [0, -9.81, 0\n", [":2:", "TOML syntax error", "Unclosed array"]),
    (
        "syntax error, bad value",
        "[[sphere]]\nposition = [0, 1, 0]\nradius = ?\n",
        [":3:", "TOML syntax error"],
    ),
    (
        "unknown key",
        BALL + "radus = 0.3\n",
        [":3:", "sphere #1", "unknown key 'radus'", "did you mean 'radius'?"],
    ),
    ("unknown table", "[[spheres]]\nposition = [0, 1, 0]\n", [":1:", "'spheres'", "did you mean 'sphere'?"]),
    ("unknown world key", "[world]\ngravty = [0, -1, 0]\n", [":2:", "[world]", "did you mean 'gravity'?"]),
    ("top-level key", "gravity = [0, -1, 0]\n", [":1:", "'gravity'", "[world]"]),
    ("single-bracket sphere", "[sphere]\nposition = [0, 1, 0]\n", [":1:", "[[sphere]]"]),
    (
        "wrong type",
        BALL + 'radius = "big"\n',
        [":3:", "sphere #1", "key 'radius'", "must be a number", '"big"'],
    ),
    ("wrong type, bool", BALL + "mass = true\n", [":3:", "key 'mass'", "got true"]),
    ("wrong type, hollow", BALL + "hollow = 1\n", [":3:", "key 'hollow'", "true or false"]),
    ("vector length", "[[sphere]]\nposition = [0, 1]\n", [":2:", "key 'position'", "3 components", "[0, 1]"]),
    (
        "vector of strings",
        '[[sphere]]\nposition = ["0", 1, 2]\n',
        [":2:", "key 'position'", "list of 3 numbers"],
    ),
    ("not finite, nan", "[[sphere]]\nposition = [0, nan, 0]\n", [":2:", "must be finite", "[0, nan, 0]"]),
    (
        "not finite, inf",
        BALL + "velocity = [inf, 0, 0]\n",
        [":3:", "key 'velocity'", "must be finite", "inf"],
    ),
    ("not finite, radius", BALL + "radius = -inf\n", [":3:", "key 'radius'", "-inf"]),
    (
        "radius not positive",
        BALL + "radius = -1.0\n",
        [":3:", "sphere #1", "key 'radius'", "must be positive", "-1.0"],
    ),
    ("mass not positive", "\n" + BALL + "mass = 0\n", [":4:", "key 'mass'", "must be positive, got 0"]),
    ("zero normal", "[[plane]]\nnormal = [0, 0, 0]\n", [":2:", "plane #1", "key 'normal'", "zero vector"]),
    (
        "normal and rotation",
        "[[plane]]\nnormal = [0, 1, 0]\nrotation = [0, 0, 10]\n",
        [":3:", "plane #1", "key 'rotation'", "not both"],
    ),
    (
        "unknown integrator",
        '[world]\nintegrator = "rk5"\n',
        [":2:", "[world]", "key 'integrator'", "euler, rk2, rk4", '"rk5"'],
    ),
    (
        "overlapping balls",
        BALL + "radius = 0.5\n\n[[sphere]]\nposition = [0.5, 1, 0]\nradius = 0.5\n",
        [":6:", "sphere #2", "key 'position'", "overlaps sphere #1"],
    ),
    (
        "negative restitution",
        "[[plane]]\nsize = 4\nrestitution = -0.5\n",
        [":3:", "plane #1", "key 'restitution'", "must be between 0 and 1", "-0.5"],
    ),
    ("negative friction", BALL + "friction = -0.1\n", [":3:", "sphere #1", "key 'friction'", "-0.1"]),
    ("negative drag", "[world]\nlinear_drag = -1\n", [":2:", "[world]", "key 'linear_drag'"]),
    ("bad size", "[[plane]]\nsize = [1, 2, 3]\n", [":2:", "key 'size'", "[1, 2, 3]"]),
    ("bad colour", BALL + 'color = "red"\n', [":3:", "key 'color'", "#rrggbb"]),
    ("colour out of range", BALL + "color = [255, 0, 0]\n", [":3:", "key 'color'", "between 0 and 1"]),
    ("missing position", "[[sphere]]\nradius = 1\n", [":1:", "sphere #1", "missing required key 'position'"]),
    ("grid count", "[[grid]]\ncorner = [0, 1, 0]\ncount = [2, 0, 1]\n", [":3:", "grid #1", "key 'count'"]),
    ("grid without place", "[[grid]]\ncount = [2, 2, 2]\n", [":1:", "grid #1", "'corner'"]),
    ("camera on its target", "[camera]\nposition = [1, 1, 1]\nlook_at = [1, 1, 1]\n", [":3:", "[camera]"]),
]


@pytest.mark.parametrize(("text", "expected"), [c[1:] for c in BAD_SCENES], ids=[c[0] for c in BAD_SCENES])
def test_bad_scene_exits_2_with_one_line_naming_file_entry_key_value_and_line(tmp_path, text, expected):
    scene = tmp_path / "bad.toml"
    scene.write_text(text)
    r = ballpit("check", scene)
    line = assert_user_error(r, str(scene), *expected)
    assert line.startswith(f"ballpit: {scene}:")
    assert r.stdout == ""


def test_missing_file(tmp_path):
    assert_user_error(ballpit("check", tmp_path / "nope.toml"), "nope.toml", "no such file")
    assert_user_error(ballpit("simulate", tmp_path / "nope.toml"), "nope.toml", "no such file")


def test_directory_and_binary_files(tmp_path):
    (tmp_path / "d.toml").mkdir()
    assert_user_error(ballpit("check", tmp_path / "d.toml"), "d.toml", "directory")
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    assert_user_error(ballpit("check", binary), "b.toml", "UTF-8")


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["simulate", "scenes/slopes.toml", "--duration", "-1"], "--duration"),
        (["simulate", "scenes/slopes.toml", "--duration", "abc"], "--duration"),
        (["simulate", "scenes/slopes.toml", "--dt", "0"], "--dt"),
        (["simulate", "scenes/slopes.toml", "--every", "0"], "--every"),
        (["simulate", "scenes/slopes.toml", "--integrator", "rk5"], "--integrator"),
        (["simulate", "scenes/slopes.toml", "--frobnicate"], "--frobnicate"),
        (["simulate"], "scene"),
        (["render", "scenes/slopes.toml", "--out", "x.gif", "--size", "big"], "--size"),
        (["render", "scenes/slopes.toml", "--out", "x.avi"], "x.avi"),
        (["nonsense"], "nonsense"),
        (["render", "scenes/slopes.toml"], "--out"),
        (["render", "scenes/slopes.toml", "--out", "x.gif", "--fps", "0"], "--fps"),
        (["check"], "scene"),
        (["check", "scenes/slopes.toml", "extra"], "extra"),
        (["simulate", "scenes/slopes.toml", "--out"], "--out"),
        (["bench", "--sizes", "abc"], "--sizes"),
        (["bench", "--sizes", "0"], "--sizes"),
        (["bench", "--steps", "0"], "--steps"),
        (["bench", "--workload", "moon"], "--workload"),
        (["bench", "--frobnicate"], "--frobnicate"),
        (["bench", "--timeout", "-1"], "--timeout"),
        (["simulate", "scenes/slopes.toml", "--integrator", "a\nb\x1b[31m"], "--integrator"),
        (["simulate", "scenes/slopes.toml", "--out", "a\nb.txt"], "a\\nb.txt"),
    ],
)
def test_bad_options_exit_2_in_one_line(args, fragment):
    line = assert_user_error(ballpit(*args), fragment)
    assert line.startswith("ballpit") and "usage:" not in line and "\x1b" not in line


def test_bad_output_paths_exit_2_and_leave_nothing(tmp_path):
    r = ballpit("simulate", "scenes/slopes.toml", "--duration", "0.05", "--out", tmp_path / "t.txt")
    assert_user_error(r, "t.txt", ".csv or .npz")
    good = tmp_path / "t.csv"
    r = ballpit(
        "simulate",
        "scenes/slopes.toml",
        "--duration",
        "0.05",
        "--out",
        good,
        "--events",
        tmp_path / "no" / "e.csv",
    )
    assert_user_error(r, "e.csv", "does not exist")
    r = ballpit("simulate", "scenes/slopes.toml", "--duration", "0.05", "--out", good, "--events", good)
    assert_user_error(r, "different files")
    assert list(tmp_path.iterdir()) == [], "no output, not even a temporary file, may be left behind"


def test_check_reports_ok():
    r = ballpit("check", "scenes/slopes.toml")
    assert r.returncode == 0 and r.stderr == ""
    assert "slopes.toml: ok: 5 balls, 5 planes" in r.stdout


def test_bundled_scene_by_name_from_anywhere(tmp_path):
    r = ballpit("check", "cradle", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "cradle.toml: ok" in r.stdout


def test_simulate_writes_csv_with_exact_columns_and_a_summary(tmp_path):
    out, ev = tmp_path / "t.csv", tmp_path / "e.csv"
    r = ballpit(
        "simulate", "scenes/slopes.toml", "--duration", "0.9", "--every", "4", "--out", out, "--events", ev
    )
    assert r.returncode == 0, r.stderr
    for fragment in ("216 steps", "steps/s", "wall time", "contacts", "energy start", "kinetic", "potential"):
        assert fragment in r.stdout
    assert "Traceback" not in r.stderr

    lines = out.read_text().splitlines()
    assert lines[0] == TRAJECTORY_HEADER
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (5 * (216 // 4 + 1), 15)
    assert np.array_equal(data[:, 1], np.tile(np.arange(5), 216 // 4 + 1))
    times = data[::5, 0]
    assert (
        times[0] == 0.0
        and np.allclose(np.diff(times), 4 / 240, atol=1e-6)
        and times[-1] == pytest.approx(0.9)
    )
    start = load_scene(ROOT / "scenes" / "slopes.toml").spheres.positions
    assert np.allclose(data[:5, 2:5], start)  # the first record: where the scene file puts the balls
    assert np.allclose(np.linalg.norm(data[:, 11:15], axis=1), 1.0)

    ev_lines = ev.read_text().splitlines()
    assert ev_lines[0] == EVENTS_HEADER
    rows = [line.split(",") for line in ev_lines[1:]]
    assert rows and all(len(row) == 11 for row in rows)
    assert {row[1] for row in rows} <= {"sphere-plane", "sphere-sphere"}
    assert {int(row[3]) for row in rows if row[1] == "sphere-plane"} >= {1, 2, 3, 4}, (
        "by 0.9 s every slope is hit"
    )
    assert all(0 < float(row[0]) <= 0.9 + 1e-9 and float(row[10]) >= 0 for row in rows)
    assert sorted(tmp_path.iterdir()) == sorted([ev, out]), "no temporary files left"


def test_npz_holds_the_same_data_as_csv(tmp_path):
    args = ["simulate", "scenes/slopes.toml", "--duration", "0.7", "--every", "3"]
    assert ballpit(*args, "--out", tmp_path / "t.csv", "--events", tmp_path / "e.csv").returncode == 0
    assert ballpit(*args, "--out", tmp_path / "t.npz", "--events", tmp_path / "e.npz").returncode == 0
    csv = np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)
    with np.load(tmp_path / "t.npz") as npz:
        assert list(npz.keys()) == TRAJECTORY_HEADER.split(",")
        assert npz["id"].dtype.kind == "i"
        stacked = np.column_stack([npz[k] for k in TRAJECTORY_HEADER.split(",")])
    assert np.allclose(stacked, csv, rtol=1e-8, atol=1e-9)
    ev_csv = np.genfromtxt(tmp_path / "e.csv", delimiter=",", names=True, dtype=None, encoding=None)
    with np.load(tmp_path / "e.npz") as npz:
        assert list(npz.keys()) == EVENTS_HEADER.split(",")
        assert list(npz["kind"]) == list(ev_csv["kind"])
        for key in ("time", "a", "b", "x", "y", "z", "nx", "ny", "nz", "impulse"):
            assert np.allclose(npz[key], ev_csv[key], rtol=1e-8, atol=1e-9), key


def test_overrides_and_quiet(tmp_path):
    out = tmp_path / "t.csv"
    overrides = ["--duration", "0.1", "--dt", "0.01", "--integrator", "euler"]
    r = ballpit("simulate", "scenes/slopes.toml", *overrides, "--out", out, "-q")
    assert r.returncode == 0 and r.stdout == "" and r.stderr == ""
    times = np.loadtxt(out, delimiter=",", skiprows=1)[::5, 0]
    assert np.allclose(times, np.arange(11) * 0.01)


def test_duration_that_is_not_a_whole_number_of_steps_ends_exactly(tmp_path):
    out = tmp_path / "t.csv"
    assert (
        ballpit(
            "simulate", "scenes/cradle.toml", "--duration", "0.105", "--dt", "0.01", "--out", out
        ).returncode
        == 0
    )
    times = np.loadtxt(out, delimiter=",", skiprows=1)[::6, 0]
    assert times[-1] == pytest.approx(0.105) and len(times) == 12


def interrupt_while_writing(args: list, folder: Path) -> tuple[int, str]:
    """Run ``ballpit ARGS`` from the repository and press Ctrl+C once it is writing into ``folder`` (a
    ``.partial`` file there) and half a second into its steps; its exit status and stderr."""
    with running(*args) as proc:
        wait_for(lambda: any(p.name.endswith(".partial") for p in folder.iterdir()))
        time.sleep(0.5)  # now inside the stepping loop
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    return proc.returncode, stderr


@pytest.mark.slow
def test_interrupt_leaves_no_partial_file(tmp_path):
    out, ev = tmp_path / "t.csv", tmp_path / "e.csv"
    args = ["simulate", "scenes/pile.toml", "--duration", "60", "--out", out, "--events", ev]
    status, stderr = interrupt_while_writing(args, tmp_path)
    assert status == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []


def test_failed_writer_leaves_target_untouched(tmp_path):
    out = tmp_path / "t.csv"
    out.write_text("previous complete run\n")
    r = ballpit(
        "simulate", "scenes/slopes.toml", "--duration", "0.05", "--out", out, "--events", tmp_path / "e.bin"
    )
    assert_user_error(r, "e.bin")
    assert out.read_text() == "previous complete run\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_help_and_version():
    r = ballpit("--help")
    assert r.returncode == 0 and "simulate" in r.stdout and "check" in r.stdout
    r = ballpit("--version")
    assert r.returncode == 0 and r.stdout.startswith("ballpit ")


def test_python_m_and_console_script_agree():
    script = Path(sys.executable).parent / "ballpit"
    r = subprocess.run([str(script), "check", "scenes/slopes.toml"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0 and "ok" in r.stdout


def test_view_validates_the_scene_before_opening_a_window(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[[sphere]]\nposition = [0, 1, 0]\nradius = 0\n")
    assert_user_error(ballpit("view", bad), "bad.toml:3:", "key 'radius'")
    assert_user_error(ballpit(bad), "bad.toml:3:", "key 'radius'")  # a scene file alone means view
    assert_user_error(ballpit("view", tmp_path / "missing.toml"), "missing.toml", "no such file")


def test_view_of_an_unknown_name_suggests_the_close_bundled_scenes_and_lists_them_all():
    r = ballpit("view", "slope")
    assert_user_error(r, "'slope'", "did you mean slopes?")
    assert "bundled scenes: billiards, cannon," in r.stderr and "pile10k" in r.stderr
    r = ballpit("view", "cradel")
    assert_user_error(r, "did you mean cradle?")
    r = ballpit("view", "qqqq")
    assert_user_error(r, "'qqqq'", "bundled scenes:")
    assert "did you mean" not in r.stderr


def test_scenes_lists_the_bundled_scenes():
    r = ballpit("scenes")
    assert r.returncode == 0
    names = [line.split()[0] for line in r.stdout.splitlines()]
    assert {"slopes", "cradle", "billiards", "incline", "pile", "pile10k"} <= set(names)


def test_a_run_of_more_than_a_billion_steps_is_refused_naming_the_numbers(tmp_path):
    r = ballpit("simulate", "scenes/slopes.toml", "--dt", "1e-300", timeout=30)
    assert_user_error(r, "--dt 1e-300", "10 s", "1e+301 steps", "limit is 1e+09")
    scene = tmp_path / "tiny.toml"
    # the smallest timestep a scene file may give (1e-9 s) over 2 s is still too many steps
    scene.write_text("[world]\ntimestep = 1e-9\n\n[[sphere]]\nposition = [0, 1, 0]\n")
    r = ballpit("simulate", scene, "--duration", "2", timeout=30)
    assert_user_error(r, str(scene), "timestep 1e-09", "2e+09 steps", "limit is 1e+09")
    scene.write_text("[world]\ntimestep = 1e-300\n\n[[sphere]]\nposition = [0, 1, 0]\n")
    r = ballpit("simulate", scene, "--duration", "2", timeout=30)
    assert_user_error(r, str(scene), "timestep", "1e-300")  # refused by the scene file's own range
    r = ballpit("simulate", "scenes/slopes.toml", "--duration", "1e300", "--dt", "1e-300", timeout=30)
    assert_user_error(r, "inf steps")


@pytest.mark.parametrize("option", ["--out", "--events"])
def test_a_file_name_over_255_bytes_is_one_line(tmp_path, option):
    long_name = "é" * 130 + ".csv"  # 264 bytes in UTF-8
    r = ballpit("simulate", "scenes/slopes.toml", "--duration", "0.01", option, tmp_path / long_name)
    assert_user_error(r, option, "264 bytes", "limit is 255")
    r = ballpit(
        "simulate", "scenes/slopes.toml", "--duration", "0.01", option, tmp_path / ("a" * 300) / "x.npz"
    )
    assert_user_error(r, option, "300 bytes")
    assert list(tmp_path.iterdir()) == []


def test_a_file_name_of_255_bytes_is_written(tmp_path):
    """The temporary file beside it must fit too, although its name is longer."""
    name = "é" * 125 + "a.csv"  # 255 bytes
    r = ballpit("simulate", "scenes/slopes.toml", "--duration", "0.01", "--out", tmp_path / name, "-q")
    assert r.returncode == 0, r.stderr
    assert [p.name for p in tmp_path.iterdir()] == [name]


def _die_with_parent(then=None):
    """A ``preexec_fn``: the child gets SIGKILL when the test process dies (Linux ``PR_SET_PDEATHSIG``),
    even killed outright where no ``finally`` runs; then ``then()``."""

    def setup() -> None:
        import ctypes

        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if then is not None:
            then()

    return setup


def start(*args: str | Path, preexec_fn=None, **kwargs) -> subprocess.Popen:
    """``ballpit ARGS`` in the background, from the repository; it dies with the test process."""
    return subprocess.Popen(
        [sys.executable, "-m", "ballpit", *map(str, args)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_die_with_parent(preexec_fn) if sys.platform == "linux" else preexec_fn,
        **kwargs,
    )


@contextmanager
def running(*args: str | Path, **kwargs) -> Iterator[subprocess.Popen]:
    """``ballpit ARGS`` started in the background (``start``), killed on the way out if it is still
    running: a test that fails or times out must not leave its 60 s run behind."""
    proc = start(*args, **kwargs)
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.communicate()  # reap it and close its pipes


def wait_for(condition, timeout: float = 60) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


def test_a_background_run_is_killed_when_its_test_fails_or_times_out():
    with pytest.raises(subprocess.TimeoutExpired), running("simulate", "scenes/pile10k.toml",
                                                          "--duration", "60", "-q") as proc:  # fmt: skip
        proc.communicate(timeout=0.5)  # as a test waiting on a run that is too slow
    assert proc.returncode == -signal.SIGKILL  # killed and reaped: nothing left running
    with pytest.raises(ProcessLookupError):
        os.kill(proc.pid, 0)
    with pytest.raises(AssertionError), running("simulate", "scenes/pile10k.toml", "--duration", "60",
                                                "-q") as proc:  # fmt: skip
        wait_for(lambda: False, timeout=0.2)  # a condition that never comes
    assert proc.returncode == -signal.SIGKILL


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
@pytest.mark.skipif(sys.platform != "linux", reason="PR_SET_PDEATHSIG is Linux's")
def test_a_background_run_dies_with_a_test_process_that_is_killed_outright(tmp_path):
    """As when a time limit kills pytest itself: no ``finally`` runs, and still nothing is left."""
    code = (
        "import sys, time; sys.path.insert(0, sys.argv[1]); from tests.cli.test_commands import start; "
        "p = start('simulate', 'scenes/pile10k.toml', '--duration', '60', '-q'); "
        "print(p.pid, flush=True); time.sleep(600)"
    )
    parent = subprocess.Popen([sys.executable, "-c", code, str(ROOT)], stdout=subprocess.PIPE, text=True)
    try:
        child = int(parent.stdout.readline())
        os.kill(child, 0)  # running
        parent.kill()
        parent.wait(timeout=10)

        def gone() -> bool:
            try:
                os.kill(child, 0)
            except ProcessLookupError:
                return True
            return Path(f"/proc/{child}/stat").read_text().split(") ")[1].startswith("Z")  # a zombie: dead

        wait_for(gone, timeout=10)
    finally:
        parent.kill()
        parent.communicate()


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_or_sighup_during_simulate_leaves_no_partial_file(tmp_path, signum):
    out, ev = tmp_path / "t.npz", tmp_path / "e.csv"

    def heard() -> None:  # a suite started under nohup hands SIGHUP down ignored, and ballpit keeps that
        signal.signal(signum, signal.SIG_DFL)

    with running(
        "simulate", "scenes/pile10k.toml", "--duration", "60", "--out", out, "--events", ev, preexec_fn=heard
    ) as proc:
        wait_for(lambda: sum(p.name.endswith(".partial") for p in tmp_path.iterdir()) == 2)
        time.sleep(1.0)  # inside the stepping loop, with the writers open
        proc.send_signal(signum)
        _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signum, stderr
    assert stderr.strip().splitlines()[-1] == f"ballpit: stopped by {signal.Signals(signum).name}"
    assert "Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []


def _limit_file_size() -> None:
    import resource

    resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))  # Python ignores SIGXFSZ: EFBIG


@pytest.mark.slow
@pytest.mark.parametrize("suffix", ["csv", "npz"])
def test_a_write_that_fails_part_way_leaves_nothing(tmp_path, suffix):
    """A file size limit makes the writes fail part way as a full disk does: one line, exit 1, no file."""
    out = tmp_path / f"t.{suffix}"
    with running("simulate", "scenes/pile.toml", "--duration", "1", "--out", out,
                 preexec_fn=_limit_file_size) as proc:  # fmt: skip
        _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 1, stderr
    assert "Traceback" not in stderr
    assert stderr.strip().splitlines() == [
        f"ballpit: {out}: cannot write: File too large; nothing was written"
    ]
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def small_disk(tmp_path):
    """A 1 MB tmpfs (needs root; skipped otherwise)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", disk],
                                           capture_output=True).returncode:  # fmt: skip
        pytest.skip("mounting a small tmpfs needs root")
    try:
        yield disk
    finally:
        subprocess.run(["umount", disk], check=True)


@pytest.mark.parametrize("suffix", ["csv", "npz"])
def test_a_full_disk_leaves_nothing(small_disk, suffix):
    out, ev = small_disk / f"t.{suffix}", small_disk / f"e.{suffix}"
    r = ballpit("simulate", "scenes/pile.toml", "--duration", "1", "--out", out, "--events", ev)
    assert r.returncode == 1, r.stderr
    assert "Traceback" not in r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert line.endswith("cannot write: No space left on device; nothing was written"), line
    assert list(small_disk.iterdir()) == []


@pytest.mark.slow
def test_ctrl_c_during_render_to_a_frame_folder_leaves_no_frames(tmp_path):
    keep = tmp_path / "frames" / "notes.txt"  # not ours: stays
    keep.parent.mkdir()
    keep.write_text("mine\n")
    for folder in (tmp_path / "frames", tmp_path / "new"):
        args = ["render", "scenes/slopes.toml", "--out", f"{folder}/", "--duration", "5", "--size", "64x48"]
        with running(*args) as proc:
            wait_for(lambda f=folder: f.is_dir() and len(list(f.glob("frame_*.png"))) >= 5)
            proc.send_signal(signal.SIGINT)
            _, stderr = proc.communicate(timeout=60)
        assert proc.returncode == 130, stderr
        assert stderr.strip().splitlines()[-1] == "ballpit: interrupted"
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == [
        "frames",
        "frames/notes.txt",
    ]


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # the dropped exception
def test_a_stop_signal_whose_exception_python_dropped_still_ends_a_render(tmp_path, monkeypatch):
    """As in simulate's loop: a SIGTERM handled inside code whose exceptions Python ignores (a weakref
    callback) loses its exception, and the stop signals are ignored from then on; the render's frame
    loop raises the stop again at its next frame, and leaves no frames behind."""
    import gc
    import weakref

    import ballpit.cli as cli
    from ballpit.viewer.simulation import Simulation

    advance, calls, refs = Simulation.advance, [], []

    class Token:
        pass

    def advance_and_lose_a_stop(self, seconds):
        calls.append(seconds)
        if len(calls) == 5:
            token = Token()
            refs.append(weakref.ref(token, lambda _: cli._on_stop_signal(signal.SIGTERM, None)))
            del token  # the handler runs here; what it raises is printed and dropped
            gc.collect()
        return advance(self, seconds)

    monkeypatch.setattr(Simulation, "advance", advance_and_lose_a_stop)
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        out = tmp_path / "frames"
        r = ballpit("render", "scenes/slopes.toml", "--out", f"{out}/", "--duration", "4", "--size", "32x32")
    finally:
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
    assert r.returncode == 128 + signal.SIGTERM, r.stderr
    assert "Traceback" not in r.stderr
    assert len(calls) == 5  # stopped at the frame after the lost stop, not after 119 more
    assert not out.exists()


def test_render_makes_no_missing_folder_on_the_way_to_its_output_as_simulate_makes_none(tmp_path):
    # A mistyped --out once made a folder at the root of the file system.
    for out in ("missing/demo.gif", "missing/frame.png", "missing/frames/", "missing/deeper/frames/"):
        r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / out, "--duration", "0.1")
        assert_user_error(r, "--out: directory", "missing", "does not exist")
        same = ballpit("simulate", "scenes/slopes.toml", "--out", tmp_path / "missing" / "t.csv")
        assert_user_error(same, "--out: directory", "missing", "does not exist")
    assert list(tmp_path.iterdir()) == []
    r = ballpit(
        "render",
        "scenes/slopes.toml",
        "--out",
        f"{tmp_path / 'frames'}/",
        "--duration",
        "0.1",
        "--fps",
        "10",
        "--size",
        "32x32",
    )
    assert r.returncode == 0, r.stderr  # the folder for the frames itself is the output, and is made
    assert len(list((tmp_path / "frames").glob("frame_*.png"))) == 1


def test_render_into_a_path_through_a_file_is_one_line(tmp_path):
    (tmp_path / "notadir").write_text("a file\n")
    for out in ("notadir/x.gif", "notadir/frames/", "notadir/deeper/x.png"):
        r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / out)
        assert_user_error(r, "--out", "notadir", "is a file, not a folder")
    r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / ("a" * 300 + ".gif"))
    assert_user_error(r, "--out", "304 bytes")
    assert [p.name for p in tmp_path.iterdir()] == ["notadir"]


# ballpit as installed without the plot extra: matplotlib cannot be imported.
WITHOUT_MATPLOTLIB = (
    "import sys; sys.modules['matplotlib'] = None; from ballpit.cli import main; sys.exit(main(sys.argv[1:]))"
)


def without_matplotlib(*args: str | Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", WITHOUT_MATPLOTLIB, *map(str, args)],
        capture_output=True, text=True, cwd=ROOT, timeout=timeout,
    )  # fmt: skip


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_without_matplotlib_the_viewers_commands_run_and_plot_options_say_what_to_install(tmp_path):
    # what the viewer and the headless runner need works without it
    r = without_matplotlib("simulate", "scenes/slopes.toml", "--duration", "0.1", "--out", tmp_path / "t.csv")
    assert r.returncode == 0, r.stderr
    r = without_matplotlib("render", "scenes/slopes.toml", "--out", tmp_path / "f.png", "--duration", "0.1",
                           "--size", "64x48")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "f.png").is_file()
    # --plot is refused up front, in one line naming the extra, before any run
    png = tmp_path / "e.png"
    for args in (["simulate", "scenes/slopes.toml", "--duration", "30"], ["compare", "scenes/slopes.toml"]):
        r = without_matplotlib(*args, "--plot", png)
        assert_user_error(r, "--plot needs matplotlib", "pip install 'ballpit[plot]'")
    r = without_matplotlib("bench", "--workload", "free", "--sizes", "8", "--steps", "2", "--plot", png)
    assert_user_error(r, "--plot needs matplotlib", "ballpit[plot]")
    assert "steps/s" not in r.stdout  # nothing was measured first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "t.csv"]
