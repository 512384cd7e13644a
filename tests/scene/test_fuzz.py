"""Generated hostile scene files: ``check`` and ``simulate`` either accept a file (exit 0, nothing on
stderr) or refuse it with exactly one line naming it (exit 2); never a traceback, a warning or a hang.

The command line runs in this process (far faster than a subprocess per file); the subprocess cases
at the end run a few hostile files through the real ``python -m ballpit``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ballpit.scene import schema

from .helpers import run_cli

# ---------------------------------------------------------------------------------------- values

HOSTILE_FLOATS = [1e308, -1e308, 1e-320, 5e-324, 1e-300, 1e300, 1e10, 1e9, 1e-9, -0.0, 0.0, 2.5, 0.5, -1.0]
HOSTILE_INTS = [0, 1, 2, 3, -1, 10**9, 2**63 - 1, -(2**63)]
HOSTILE_TEXT = ["", "x", "rk4", "RK2", "euler", "#ff0000", "\n", "\x1b[2J", "\u202e", "a\x00b", "é", "\\"]


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string, any character escaped as TOML allows."""
    out = []
    for c in text:
        if c in '"\\':
            out.append("\\" + c)
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04x}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def toml_float(x: float) -> str:
    if x != x:
        return "nan"
    if x in (float("inf"), float("-inf")):
        return "inf" if x > 0 else "-inf"
    return repr(x)


scalars = st.one_of(
    st.sampled_from(HOSTILE_FLOATS).map(toml_float),
    st.floats(allow_nan=True, allow_infinity=True).map(toml_float),
    st.sampled_from(HOSTILE_INTS).map(str),
    st.integers(-5, 5).map(str),
    st.booleans().map(lambda b: "true" if b else "false"),
    st.one_of(st.sampled_from(HOSTILE_TEXT), st.text(max_size=12)).map(toml_string),
    st.just("1979-05-27"),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5).map(lambda items: "[" + ", ".join(items) + "]"),
        st.lists(
            st.tuples(st.sampled_from(["a", "b", "x"]), inner), max_size=3, unique_by=lambda kv: kv[0]
        ).map(lambda kvs: "{" + ", ".join(f"{k} = {v}" for k, v in kvs) + "}"),
    ),
    max_leaves=12,
)
# Values that are usually right, so the files get past the first check often enough to test the rest.
vectors = st.lists(st.sampled_from([0, 1, -1, 2.5, 1e9, 1e-9, 1e308, 0.3]), min_size=3, max_size=3).map(
    lambda xs: "[" + ", ".join(toml_float(float(x)) for x in xs) + "]"
)
counts = st.lists(st.sampled_from([1, 2, 3, 0, -1, 10**9]), min_size=3, max_size=3).map(
    lambda xs: "[" + ", ".join(map(str, xs)) + "]"
)
numbers = st.sampled_from([*HOSTILE_FLOATS, 1.0, 3.0]).map(toml_float)
quaternions = st.lists(st.sampled_from([0.0, 1.0, 1e308, 1e-300]), min_size=4, max_size=4).map(
    lambda xs: "[" + ", ".join(map(toml_float, xs)) + "]"
)
VECTOR_KEYS = ("position", "corner", "center", "normal", "gravity", "velocity", "angular_velocity")
NUMBER_KEYS = ("radius", "mass", "restitution", "friction", "rolling_friction", "timestep", "duration")
NUMBER_KEYS += ("linear_drag", "angular_drag", "restitution_threshold", "jitter", "velocity_jitter")
NUMBER_KEYS += ("spacing", "size")
plausible = {k: vectors for k in (*VECTOR_KEYS, "rotation", "look_at")}
plausible |= {k: numbers for k in NUMBER_KEYS} | {"count": counts, "orientation": quaternions}

KEYS = sorted({k for keys in schema.KEYS.values() for k in keys})
keys = st.one_of(
    st.sampled_from(KEYS),
    st.sampled_from(KEYS),
    st.text(max_size=8).map(toml_string),
)


@st.composite
def entries(draw: st.DrawFn) -> str:
    """One table of a scene file: a header and some keys, each value plausible or hostile."""
    name = draw(st.sampled_from([*schema.TABLES, "sphere", "sphere", "plane", "bogus"]))
    header = f"[[{name}]]" if schema.TABLES.get(name) == "array" else f"[{name}]"
    if draw(st.integers(0, 9)) == 0:  # the other bracket style
        header = f"[{name}]" if header.startswith("[[") else f"[[{name}]]"
    lines = [header]
    if name == "sphere" and draw(st.booleans()):
        lines.append(f"position = {draw(vectors)}")
    if name == "grid" and draw(st.booleans()):
        lines += [f"corner = {draw(vectors)}", f"count = {draw(counts)}"]
    own = st.sampled_from(schema.KEYS.get(name, KEYS))
    for key in draw(st.lists(st.one_of(own, own, own, keys), max_size=4, unique=True)):
        bare = key if not key.startswith('"') else None
        value = draw(plausible[bare]) if bare in plausible and draw(st.booleans()) else draw(values)
        lines.append(f"{key} = {value}")
    return "\n".join(lines)


@st.composite
def scene_files(draw: st.DrawFn) -> str:
    parts = draw(st.lists(entries(), max_size=5))
    top = draw(st.lists(st.tuples(keys, values), max_size=1)) if draw(st.integers(0, 3)) == 0 else []
    text = "".join(f"{k} = {v}\n" for k, v in top) + "\n".join(parts) + "\n"
    if draw(st.integers(0, 7)) == 0:  # raw damage: cut it short or splice in junk
        cut = draw(st.integers(0, len(text)))
        text = text[:cut] + draw(st.sampled_from(["", "[", "]]", '"', "= =", "\x00", "[[[", "\ufeff"]))
    return text


# ---------------------------------------------------------------------------------------- the property


@pytest.fixture(scope="module")
def fuzz_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz") / "fuzz.toml"


def check_one(path: Path, text: str) -> None:
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    outcomes = []
    for command in (["check"], ["simulate", "--duration", "0.01", "--dt", "0.005", "--quiet"]):
        code, lines = run_cli(command[0], path, *command[1:])
        if code == 0:
            assert lines == [], (command[0], text, lines)
        else:
            assert code == 2 and len(lines) == 1, (command[0], code, text, lines[:5])
            assert lines[0].startswith(f"ballpit: {path}"), lines[0]
            assert "Traceback" not in lines[0] and "\x1b" not in lines[0]
        outcomes.append((code, lines))
    assert outcomes[0] == outcomes[1] or outcomes[0][0] == outcomes[1][0] == 0, outcomes


@pytest.mark.slow
@settings(
    derandomize=True,
    max_examples=300,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(scene_files())
def test_generated_hostile_scene_files_give_one_line_or_run(fuzz_file, text):
    check_one(fuzz_file, text)


@pytest.mark.slow
@pytest.mark.parametrize(
    "text",
    [
        "sphere = 5\n",
        "a = " + "[" * 5_000 + "]" * 5_000 + "\n",
        "[[sphere]]\nposition = [0, 1, 0]\nradius = 1e308\n",
        '[[sphere]]\nposition = [0, 1, 0]\n"\\u001b[2J\\n" = 1\n',
        "[[grid]]\ncorner = [0, 1, 0]\ncount = [1, 1, 1]\njitter = 1e308\n",
    ],
    ids=["top-level value", "deep nesting", "huge radius", "escape key", "huge jitter"],
)
def test_hostile_files_in_a_real_subprocess(tmp_path, text):
    path = tmp_path / "hostile.toml"
    path.write_text(text)
    for command in (["check"], ["simulate", "--duration", "0.01"]):
        r = subprocess.run(
            [sys.executable, "-m", "ballpit", command[0], str(path), *command[1:]],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode == 2, r.stderr
        assert len(r.stderr.splitlines()) == 1 and r.stderr.startswith(f"ballpit: {path}")
        assert "Traceback" not in r.stderr and "\x1b" not in r.stderr
