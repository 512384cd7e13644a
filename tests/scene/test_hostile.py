"""Hostile scene files: each gives one line naming the file and the problem, exit status 2, and no
traceback, from both ``ballpit check`` and ``ballpit simulate``; none hangs or runs away."""

from __future__ import annotations

import codecs
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ballpit.scene import read_scene, schema
from ballpit.scene.lines import LineIndex

from .helpers import refused, run_cli


def scene(tmp_path: Path, text: str, name: str = "hostile.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ---------------------------------------------------------------------------------------- structure


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("sphere = 5\n", "'sphere' must be tables written [[sphere]], got 5"),
        ('grid = "x"\n', "'grid' must be tables written [[grid]]"),
        ("world = 5\n", "'world' must be a table written [world], got 5"),
        ("camera = [1, 2]\n", "'camera' must be a table written [camera], got [1, 2]"),
    ],
)
def test_a_top_level_value_where_a_table_belongs(tmp_path, text, fragment):
    line = refused(scene(tmp_path, text), fragment)
    assert ":1:" in line


def test_ten_thousand_nested_brackets(tmp_path):
    refused(scene(tmp_path, "a = " + "[" * 10_000 + "]" * 10_000 + "\n"), "nested too deeply")


def test_nested_inline_tables(tmp_path):
    refused(scene(tmp_path, "a = " + "{b = " * 5_000 + "1" + "}" * 5_000 + "\n"), "nested too deeply")


def test_a_deep_list_that_parses_is_shown_shortened(tmp_path):
    text = "[[sphere]]\nposition = " + "[" * 300 + "1" + "]" * 300 + "\n"
    line = refused(scene(tmp_path, text), "key 'position': must be a list of 3 numbers, got [[[")
    assert "[…]" in line


def test_a_subprocess_gives_the_same_single_line(tmp_path):
    path = scene(tmp_path, "sphere = 5\n")
    r = subprocess.run(
        [sys.executable, "-m", "ballpit", "check", str(path)], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.splitlines() == [f"ballpit: {path}:1: 'sphere' must be tables written [[sphere]], got 5"]


# ---------------------------------------------------------------------------------------- numbers

GRID = "[[grid]]\ncorner = [0, 1, 0]\n"


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (GRID + "count = [1, 1, 1]\njitter = 1e308\n", "key 'jitter': must be between 0 and 1e9, got 1e+308"),
        (GRID + "count = [2, 2, 2]\njitter = 1e308\n", "key 'jitter': must be between 0 and 1e9"),
        (GRID + "count = [2, 1, 1]\nvelocity_jitter = 1e308\n", "key 'velocity_jitter': must be between 0"),
        (GRID + "count = [3, 1, 1]\nspacing = 1e308\n", "key 'spacing': must be between 1e-9 and 1e9"),
        (GRID + "count = [3, 1, 1]\nspacing = 1e300\n", "key 'spacing': must be between 1e-9 and 1e9"),
        (
            "[[sphere]]\nposition = [0, 1, 0]\norientation = [1e308, 1e308, 1e308, 1e308]\n",
            "key 'orientation': components must be between -1e9 and 1e9",
        ),
        ("[[sphere]]\nposition = [0, 1, 0]\nradius = 1e308\n", "key 'radius': must be between 1e-9 and 1e9"),
        ("[[sphere]]\nposition = [0, 1, 0]\nradius = 1e-300\n", "key 'radius': must be between 1e-9 and 1e9"),
        ("[[sphere]]\nposition = [0, 1, 0]\nmass = 1e-320\n", "key 'mass': must be between 1e-9 and 1e9"),
        ("[[plane]]\nnormal = [1e308, 1e308, 0]\n", "key 'normal': components must be between -1e9 and 1e9"),
        ("[world]\ngravity = [0, -1e300, 0]\n", "key 'gravity': components must be between"),
        ("[world]\ntimestep = 1e-300\n", "key 'timestep': must be between 1e-9 and 1e9"),
        ("[[plane]]\nsize = [1e-300, 1]\n", "key 'size': must be between 1e-9 and 1e9"),
        ("[camera]\nposition = [1e300, 0, 0]\n", "key 'position': components must be between"),
    ],
)
def test_numbers_that_cannot_be_computed_with_are_refused(tmp_path, text, fragment):
    refused(scene(tmp_path, text), fragment)


def test_a_grid_reaching_beyond_the_largest_coordinate_is_refused(tmp_path):
    text = "[[grid]]\ncenter = [0, 1, 0]\ncount = [1000, 1, 1]\nspacing = 1e7\nradius = 1\n"
    refused(scene(tmp_path, text), "grid #1", "key 'spacing'", "reaches 4.995e+09 m from the origin")


def test_the_largest_and_smallest_numbers_still_load(tmp_path):
    text = (
        "[world]\ngravity = [0, -1e9, 0]\ntimestep = 1e-9\n"
        "[[plane]]\nposition = [0, -1e9, 0]\nsize = 1e9\n"
        "[[sphere]]\nposition = [0, 1, 0]\nradius = 1e-9\nmass = 1e-9\nvelocity = [1e9, 0, 0]\n"
        "[[sphere]]\nposition = [1e9, 1e9, 0]\nradius = 1e9\nmass = 1e9\n"
    )
    code, lines = run_cli("check", scene(tmp_path, text))
    assert code == 0 and lines == []


def test_substeps_beyond_the_physics_bound_are_refused(tmp_path):
    # 10⁹ substeps passed 'ballpit check' and would take days a step; World takes at most 1,000.
    refused(
        scene(tmp_path, "[world]\nsubsteps = 1000000000\n"),
        ":2: [world]: key 'substeps': must be at most 1,000",
    )
    refused(scene(tmp_path, "[world]\nsubsteps = 1001\n"), "must be at most 1,000, got 1001")
    assert read_scene(scene(tmp_path, "[world]\nsubsteps = 1000\n")).world.substeps == 1000


@pytest.mark.parametrize(
    "text",
    [
        "[[sphere]]\nposition = [0, 1, 0]\nrestitution = 2\n",
        "[[grid]]\ncorner = [0, 1, 0]\ncount = [2, 1, 1]\nrestitution = 1.5\n",
        "[[plane]]\nrestitution = 1.01\n",
    ],
)
def test_a_restitution_above_one_is_refused_as_the_world_refuses_it(tmp_path, text):
    refused(scene(tmp_path, text), "key 'restitution': must be between 0 and 1, got ")


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (
            "[[sphere]]\nposition = [1" + "0" * 400 + ", 0, 0]\n",
            "key 'position': components must be between -1e9",
        ),
        ("[[sphere]]\nposition = [0, 1, 0]\nradius = 1" + "0" * 400 + "\n", "must be between 1e-9 and 1e9"),
        ("[world]\nlinear_drag = -1" + "0" * 400 + "\n", "key 'linear_drag': must be between 0 and 1e9"),
        ("[[plane]]\nsize = [1" + "0" * 400 + ", 1]\n", "key 'size': must be between 1e-9 and 1e9"),
        ("[[sphere]]\nposition = [0, 1, 0]\ncolor = [1" + "0" * 400 + ", 0, 0]\n", "between 0 and 1"),
    ],
)
def test_an_integer_too_large_for_a_float_is_refused_by_name(tmp_path, text, fragment):
    refused(scene(tmp_path, text), fragment)


# ---------------------------------------------------------------------------------------- files


def test_a_file_name_over_255_bytes(tmp_path):
    refused(tmp_path / ("x" * 300 + ".toml"), "File name too long")


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    for command in ("check", "simulate"):
        r = subprocess.run(
            [sys.executable, "-m", "ballpit", command, str(fifo)], capture_output=True, text=True, timeout=60
        )
        assert r.returncode == 2, r.stderr
        assert r.stderr.splitlines() == [f"ballpit: {fifo}: not a regular file (a pipe, device or socket)"]


def test_dev_zero_is_refused_without_reading_it():
    r = subprocess.run(
        [sys.executable, "-m", "ballpit", "check", "/dev/zero"], capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 2
    assert r.stderr.splitlines() == ["ballpit: /dev/zero: not a regular file (a pipe, device or socket)"]


def test_a_file_over_16_mib_is_refused_unread(tmp_path):
    path = tmp_path / "huge.toml"
    with open(path, "wb") as f:
        f.truncate(16 * 1024 * 1024 + 1)  # sparse: costs no disk
    refused(path, "16777217 bytes, more than a scene file may have (16 MiB)")


# ---------------------------------------------------------------------------------------- size


def test_the_total_number_of_balls_is_capped_not_each_grid(tmp_path):
    grids = "".join(
        f"[[grid]]\ncorner = [{k * 1000}, 1, 0]\ncount = [100, 100, 60]\nradius = 0.1\n" for k in range(10)
    )
    line = refused(scene(tmp_path, grids), "grid #2", "key 'count'")
    assert (
        "asks for 600,000 balls; with the 600,000 before it that is more than the 1,000,000 a scene may have"
        in line
    )


def test_one_grid_over_the_cap(tmp_path):
    text = "[[grid]]\ncorner = [0, 1, 0]\ncount = [200, 100, 100]\n"
    refused(
        scene(tmp_path, text), "grid #1", "asks for 2,000,000 balls, more than the 1,000,000 a scene may have"
    )


@pytest.mark.slow
def test_forty_thousand_sphere_tables_check_in_linear_time(tmp_path):
    # Re-adding every earlier block for each new sphere made this take 37 s; linear it takes a few.
    text = "".join(f"[[sphere]]\nposition = [{2 * k}, 1, 0]\n" for k in range(40_000))
    started = time.process_time()  # CPU time: other work on the machine does not count
    scene_ = read_scene(scene(tmp_path, text))
    assert time.process_time() - started < 15.0
    assert len(scene_.world.spheres) == 40_000
    assert np.array_equal(scene_.world.spheres.positions[-1], [79_998, 1, 0])


def test_more_planes_than_a_scene_may_have_are_refused_before_any_is_read(tmp_path, monkeypatch):
    assert schema.MAX_PLANES == 100_000
    monkeypatch.setattr(schema, "MAX_PLANES", 3)
    text = "[[plane]]\nposition = [0, 0, 0]\n" * 3 + "[[plane]]\nposition = [0, nan, 0]\n"
    refused(scene(tmp_path, text), ":7: plane #4: 4 of them are more than the 3 a scene may have")


def test_more_spheres_than_a_scene_may_have_are_refused_before_any_is_read(tmp_path, monkeypatch):
    monkeypatch.setattr(schema, "MAX_BALLS", 2)
    text = "[[sphere]]\nposition = [0, 0, 0]\n" * 3
    refused(scene(tmp_path, text), ":5: sphere #3: 3 of them are more than the 2 a scene may have")


def _peak_rss_of_reading(path: Path) -> tuple[str, int]:
    """Read the scene in a process of its own: (what it said, its peak resident memory in bytes)."""
    code = (
        "import sys\n"
        "from ballpit.scene import read_scene\n"
        "try:\n"
        "    print(len(read_scene(sys.argv[1]).world.spheres))\n"
        "except ValueError as e:\n"
        "    print(e)\n"
        "print(int(next(l for l in open('/proc/self/status') if l.startswith('VmHWM')).split()[1]))\n"
    )
    r = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=600)
    said, peak = r.stdout.strip().splitlines()
    return said, int(peak) * 1024  # VmHWM: this process's own peak, in KiB (ru_maxrss can carry the
    # parent's, forked before the exec)


HALF_A_MILLION = 450_977  # 15 MiB of [[sphere]] tables, as the attack had them


def _many_spheres(path: Path, bad_last: bool) -> Path:
    with open(path, "w") as f:
        for k in range(HALF_A_MILLION):
            f.write(f"[[sphere]]\nposition=[{k % 80 * 2},{k // 80 % 80 * 2},{k // 6400 * 2}]\n")
        if bad_last:
            f.write("[[sphere]]\nposition=[nan,1,1]\n")
    return path


@pytest.mark.slow
def test_half_a_million_spheres_with_a_nan_at_the_end_are_refused_within_500_mb(tmp_path):
    # It took 1.36 GB: every parsed table, a Python object per value and the whole line index were kept.
    said, peak = _peak_rss_of_reading(_many_spheres(tmp_path / "bad.toml", bad_last=True))
    assert said.endswith(f"sphere #{HALF_A_MILLION + 1}: key 'position': must be finite, got [nan, 1, 1]")
    assert peak < 500e6, f"{peak / 1e6:.0f} MB"


@pytest.mark.slow
def test_half_a_million_spheres_load_within_500_mb(tmp_path):
    said, peak = _peak_rss_of_reading(_many_spheres(tmp_path / "good.toml", bad_last=False))
    assert said == str(HALF_A_MILLION)
    assert peak < 500e6, f"{peak / 1e6:.0f} MB"


@pytest.mark.slow
def test_a_million_ball_grid_loads_within_500_mb(tmp_path):
    # The start-overlap check listed every candidate pair at once: 1.2 GB for these 60 bytes.
    path = scene(tmp_path, "[[grid]]\ncount = [100, 100, 100]\ncorner = [0, 1, 0]\nradius = 0.1\n")
    said, peak = _peak_rss_of_reading(path)
    assert said == "1000000"
    assert peak < 500e6, f"{peak / 1e6:.0f} MB"


# ---------------------------------------------------------------------------------------- line index

LONG_LINES = {
    "a 50,000-part dotted header": "[" + ".".join(["a"] * 50_000) + "]\n",
    "a 200 KB quoted key full of dots": '"' + "x." * 100_000 + '" = 1\n',
    "a 200 KB string value": 'note = "' + "x" * 200_000 + '"\n',
    "an unclosed header of spaces": "[" + " " * 100_000 + "a\n",
    "an unclosed header of words": "[" + "a " * 100_000 + "\n",
    "escaped triple quotes in a multi-line string": 'a = """' + '\\"""' * 50_000 + '"""\n',
    "a dotted key with quoted parts": "a" + '."b.c"' * 30_000 + " = 1\n",
}


@pytest.mark.parametrize("text", LONG_LINES.values(), ids=LONG_LINES.keys())
def test_the_line_index_is_linear_on_long_lines(text):
    started = time.process_time()  # CPU time: other work on the machine does not count
    LineIndex(text)
    assert time.process_time() - started < 2.0


def test_a_long_dotted_header_is_refused_on_its_line(tmp_path):
    # (tomllib itself is quadratic in the parts: 20,000 keep this test short)
    refused(scene(tmp_path, "[" + ".".join(["a"] * 20_000) + "]\n"), ":1: unknown table or key 'a'")


def test_header_and_key_lines_still_found():
    index = LineIndex(
        '[world]\ngravity = [0, -1, 0]\n[[sphere]]  # first\n"quoted.key" = 1\n'
        "[[ sphere ]]\na.b = 2\n[\"x.y\".z]\n'k' = 3\n"
    )
    assert index.table("world").key_lines == {"gravity": 2}
    first, second = index.arrays["sphere"]
    assert first.header_line == 3 and first.key_lines == {"quoted.key": 4}
    assert second.header_line == 5 and second.key_lines == {"a": 6}
    assert index.table("x.y.z").header_line == 7 and index.table("x.y.z").key_lines == {"k": 8}


def test_a_utf8_byte_order_mark_is_skipped(tmp_path):
    path = tmp_path / "notepad.toml"
    path.write_bytes(codecs.BOM_UTF8 + b"[[sphere]]\nposition = [0, 1, 0]\nradius = 0.25\n")
    assert read_scene(path).world.spheres[0].radius == 0.25
    path.write_bytes(codecs.BOM_UTF8 + b"[[sphere]]\nradius = -1\n")
    refused(path, ":1: sphere #1: missing required key 'position'")  # lines are counted as before


@pytest.mark.parametrize("encoding", ["utf-16", "utf-32"])
def test_a_utf16_or_utf32_file_is_refused_naming_its_byte_order_mark(tmp_path, encoding):
    path = tmp_path / "wide.toml"
    path.write_bytes("[[sphere]]\nposition = [0, 1, 0]\n".encode(encoding))  # with its byte-order mark
    refused(path, ":1: starts with a UTF-16 byte-order mark: save it as UTF-8 text")


# ---------------------------------------------------------------------------------------- messages


def test_a_value_with_a_newline_and_terminal_escapes_is_quoted_visibly(tmp_path):
    text = '[[sphere]]\nposition = [0, 1, 0]\nradius = "a\\nb\\u001b[31mred\\u202e"\n'
    line = refused(scene(tmp_path, text), "key 'radius': must be a number, got ")
    assert line.endswith('got "a\\nb\\u001b[31mred\\u202e"') and "\x1b" not in line


def test_a_key_with_a_newline_and_terminal_escapes_is_quoted_visibly(tmp_path):
    text = '[[sphere]]\nposition = [0, 1, 0]\n"bad\\u001b[2Jkey\\nx" = 1\n'
    line = refused(scene(tmp_path, text), 'sphere #1: unknown key "bad\\u001b[2Jkey\\nx"')
    assert "\x1b" not in line
    line = refused(scene(tmp_path, '"\\u001b[2J\\r" = 1\n'), 'unknown table or key "\\u001b[2J\\r"')
    assert "\x1b" not in line and "\r" not in line


def test_a_file_name_with_a_newline_and_an_escape_stays_on_one_line(tmp_path):
    path = scene(tmp_path, "sphere = 5\n", name="bad\nname\x1b[31m.toml")
    for command in ("check", "simulate"):
        code, lines = run_cli(command, path)
        assert code == 2 and len(lines) == 1
        assert lines[0].startswith(f"ballpit: {tmp_path}/bad\\nname\\u001b[31m.toml:1: 'sphere' must be")


@pytest.mark.parametrize(
    ("value", "start"),
    [
        pytest.param("[" + ", ".join(["1"] * 1_000_000) + "]", "got [1, 1, 1, 1,", marks=pytest.mark.slow),
        ('"' + "x" * 200_000 + '"', 'got "xxxxxxxx'),
        ("[" + ", ".join(['"' + "y" * 100 + '"'] * 10) + "]", 'got ["yyyy'),
    ],
    ids=["a million-element list", "a 200 KB string", "a list of long strings"],
)
def test_long_values_are_shortened(tmp_path, value, start):
    line = refused(scene(tmp_path, f"[[sphere]]\nposition = [0, 1, 0]\nradius = {value}\n"), start)
    shown = line[line.index("got ") + 4 :]
    assert len(shown) == 60 and shown.endswith("…")
