"""Fixtures for the viewer tests.

The renderer tests draw offscreen through pyglet's headless EGL mode in this pytest process (the
``offscreen`` fixture switches the process to headless GL the first time it is used). The window tests
never open a window here: they run real windows in subprocesses under an Xvfb server of their own.
"""

from __future__ import annotations

import json
import os
import select
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

import ballpit

REPO = Path(__file__).resolve().parents[2]
# This pytest process only ever renders headless (EGL). A test that imports a module importing OpenGL
# (the renderer's constants) before the offscreen fixture ran must not fix PyOpenGL's loader to GLX for
# the rest of the worker; the window processes choose their own (backend.py, subprocess_env).
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")


@pytest.fixture(scope="session")
def offscreen_session():
    from ballpit.viewer.render import Offscreen

    screen = Offscreen((200, 150), samples=0)
    yield screen
    screen.close()


@pytest.fixture
def offscreen(offscreen_session):
    """A headless GL context with a 200×150 single-sample framebuffer and the real Renderer, current."""
    offscreen_session.window.switch_to()  # another test may have made its own context current
    return offscreen_session


@pytest.fixture(scope="session")
def xvfb():
    """Start an Xvfb server for the window tests; yields its DISPLAY string (e.g. ":90"). Xvfb picks a
    free display number itself and writes it to a pipe (``-displayfd``), so parallel test workers never
    end up sharing one server (where one worker's pointer clicks would land in another's window)."""
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (apt-get install xvfb); .ci/run installs it")
    read, write = os.pipe()
    # -noreset: by default the server resets when its last client leaves, and drops a client that
    # connected meanwhile (its XOpenDisplay fails: the viewer then exits 1 as if there were no display).
    # A test's xdotool calls come and go while the viewer it started is still connecting.
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1280x720x24", "-nolisten", "tcp", "-noreset"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        pass_fds=(write,),
    )
    os.close(write)
    number = b""
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and not number.endswith(b"\n"):
        if not select.select([read], [], [], max(deadline - time.monotonic(), 0.0))[0]:
            break
        chunk = os.read(read, 16)
        if not chunk:
            break
        number += chunk
    os.close(read)
    if proc.poll() is not None or not number.strip():
        proc.kill()
        error = proc.communicate()[1].decode(errors="replace")  # reaped, its pipe closed
        pytest.fail(f"Xvfb did not start: {error}")
    try:
        yield f":{int(number)}"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        proc.stderr.close()


def subprocess_env(display: str | None) -> dict[str, str]:
    """The environment for a viewer subprocess: this interpreter's, with DISPLAY set or removed."""
    env = {
        k: v for k, v in os.environ.items() if k not in ("DISPLAY", "PYOPENGL_PLATFORM", "WAYLAND_DISPLAY")
    }
    if display is not None:
        env["DISPLAY"] = display
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO / "src"), env.get("PYTHONPATH")]))
    return env


def xdotool(display: str, *args: str) -> str:
    """``xdotool ARGS`` on ``display``; what it printed."""
    out = subprocess.run(
        ["xdotool", *args], env=subprocess_env(display), capture_output=True, text=True, timeout=20
    )
    return out.stdout.strip()


@contextmanager
def started(args: Sequence[str], display: str, cwd: Path) -> Iterator[subprocess.Popen]:
    """``args`` in a process of its own under ``display``, stdout and stderr to text pipes. On the way
    out, also when the test fails, it is killed if still running, reaped, and its pipes are closed
    (else a failed test leaves them to the collector, whose "unclosed file" warnings land in whatever
    test of the worker runs then)."""
    proc = subprocess.Popen(
        args, env=subprocess_env(display), cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        yield proc
    finally:
        ended(proc)


def ended(proc: subprocess.Popen) -> str:
    """Kill ``proc`` if it still runs, reap it and close its pipes; what it wrote, for a message."""
    if proc.poll() is None:
        proc.kill()
    out, err = proc.communicate()
    return f"exit status {proc.returncode}; stdout {out!r}; stderr {err!r}"


def _run_scenarios(driver: Path, display: str, names: list[str], workdir: Path, *extra: str,
                   timeout: float) -> dict[str, dict]:  # fmt: skip
    """Run the scenarios ``names`` of a window driver script in one process under ``display``."""
    proc = subprocess.run(
        [sys.executable, str(driver), ",".join(names), str(workdir), *extra],
        env=subprocess_env(display), cwd=workdir, capture_output=True, text=True, timeout=timeout,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    results: dict[str, dict] = {}
    for line in proc.stdout.splitlines():
        if line.startswith(("RESULT ", "FAILED ")):
            status, name, text = line.split(" ", 2)
            results[name] = {"failed": json.loads(text)} if status == "FAILED" else json.loads(text)
    for name in names:
        assert name in results, proc.stdout + proc.stderr
    return results


def _moved(value: object, old: str, new: str) -> object:
    """``value`` (a scenario's result) with the paths under ``old`` under ``new`` instead."""
    if isinstance(value, str):
        return new + value[len(old) :] if value == old or value.startswith(old + os.sep) else value
    if isinstance(value, list):
        return [_moved(v, old, new) for v in value]
    if isinstance(value, dict):
        return {k: _moved(v, old, new) for k, v in value.items()}
    return value


# Results of batched scenarios by (driver, display): one process ran them all.
_BATCHES: dict[tuple[Path, str], dict[str, dict]] = {}


def run_driver(
    driver: Path, display: str, name: str, workdir: Path, *extra: str, timeout: float = 300,
    batch: tuple[str, ...] = (),
) -> dict:  # fmt: skip
    """The result of scenario ``name`` of a window driver script, run under ``display``.

    With ``batch`` (the driver's scenarios that need no extra arguments, ``name`` among them), the
    first call runs them all in one process, one window after another, and later calls take their
    result from that run: one Python start, one pyglet import and one GL set-up instead of one per test.
    What a scenario wrote into its folder is copied into ``workdir``.
    """
    if not batch:
        result = _run_scenarios(driver, display, [name], workdir, *extra, timeout=timeout)[name]
    else:
        assert name in batch and not extra
        key = (driver, display)
        folder = workdir.parent / f"batch-{driver.stem}"
        if key not in _BATCHES:
            folder.mkdir(exist_ok=True)
            _BATCHES[key] = _run_scenarios(driver, display, list(batch), folder, timeout=timeout * len(batch))
        result = _moved(_BATCHES[key][name], str(folder / name), str(workdir))
        shutil.copytree(folder / name, workdir, dirs_exist_ok=True)
    assert "failed" not in result, result.get("failed")
    return result


def line_of_balls(n: int = 5, y: float = 6.0, gravity: tuple = (0.0, -9.81, 0.0)) -> ballpit.World:
    """A World built in code: a ground, one slope and ``n`` balls in a row at height ``y``."""
    world = ballpit.World(gravity=gravity)
    world.add_plane(position=(0.0, 0.0, 0.0))
    world.add_plane(position=(0.0, 2.0, 0.0), rotation=(0.0, 0.0, 20.0), size=4.0, restitution=0.6)
    xs = np.linspace(-3.0, 3.0, n) if n > 1 else np.zeros(1)
    world.add_spheres(np.column_stack([xs, np.full(n, y), np.zeros(n)]), radius=0.3)
    return world
