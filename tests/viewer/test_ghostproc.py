"""The integrator ghosts in a process of their own, without a window: the same frames, energies and
drifts as ghosts stepped here, bit for bit, through steps back, resumes, edits, resets and integrator
switches; and the child never outlives the viewer nor makes it wait."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
import time
from operator import methodcaller

import numpy as np
import pytest

from ballpit.viewer.ghostproc import Frames
from ballpit.viewer.ghosts import GhostFrame
from ballpit.viewer.simulation import Simulation

from .conftest import REPO, line_of_balls

WAIT = 120.0  # s: the child's start imports NumPy and the physics, slow on a loaded machine


def pair() -> tuple[Simulation, Simulation]:
    """The same scene twice: ghosts stepped here, and ghosts stepped in a process of their own."""
    here = Simulation(line_of_balls(3), step_budget=math.inf)
    apart = Simulation(line_of_balls(3), step_budget=math.inf)
    apart.ghosts_apart()
    return here, apart


def both(sims: tuple[Simulation, ...], act) -> None:
    for sim in sims:
        act(sim)
        sim.timeline.settle_ghosts(WAIT)


def running(seconds: float):
    def run(sim: Simulation) -> None:
        for _ in range(round(seconds * 60)):
            sim.advance(1 / 60)

    return run


def close(sim: Simulation) -> None:
    """Close ``sim``, then reap its ghosts' child, which ends at once: a Popen the collector frees
    unreaped warns ("subprocess N is still running") in whatever test of the worker runs then."""
    host = sim.ghost_host
    sim.close()
    if host is not None:
        host._process.wait(timeout=10)  # close() never waits: the viewer does not, a test must


def assert_same_ghosts(here: Simulation, apart: Simulation) -> None:
    step = here.timeline.history.current if here.timeline.history is not None else None
    assert apart.timeline.ghosts.remote and not here.timeline.ghosts.remote
    mine, theirs = here.timeline.ghosts.frame_at(step), apart.timeline.ghosts.frame_at(step)
    assert theirs.step == mine.step and theirs.time == mine.time and theirs.totals == mine.totals
    for (name, p, q, r), (name2, p2, q2, r2) in zip(mine.bodies, theirs.bodies, strict=True):
        assert name == name2
        assert np.array_equal(p, p2) and np.array_equal(q, q2) and np.array_equal(r, r2)
    assert here.timeline.drifts() == apart.timeline.drifts()
    a, b = here.timeline.energy.series(), apart.timeline.energy.series()
    assert sorted(a) == sorted(b)
    for key in a:
        assert np.array_equal(a[key], b[key], equal_nan=True), key


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_ghosts_in_their_own_process_follow_the_run_through_steps_back_and_resumes_bit_for_bit():
    here, apart = pair()
    try:
        both((here, apart), lambda sim: (sim.toggle_ghosts(), sim.start()))
        both((here, apart), running(0.3))
        assert here.timeline.history.current == 72
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: (sim.toggle_pause(), sim.jump(-0.1)))
        assert here.timeline.history.current == 48
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: sim.step_back())
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: sim.scrub(0.5))
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: (sim.toggle_pause(), running(0.1)(sim)))  # resumed from the past
        assert here.timeline.history.current == 36 + 24
        assert_same_ghosts(here, apart)
    finally:
        close(apart)


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_edits_resets_and_integrator_switches_reach_the_ghosts_in_the_same_process():
    here, apart = pair()
    try:
        both((here, apart), lambda sim: (sim.toggle_ghosts(), sim.start(), running(0.15)(sim)))
        pid = apart.ghost_host.pid
        # an edit made while the child has stepped ahead of the run: it goes back to the edited step
        time.sleep(0.2)
        both((here, apart), lambda sim: sim.remove_ball(1))
        assert all(len(b[1]) == 2 for b in apart.timeline.ghosts.frame_at(None).bodies)
        both((here, apart), running(0.1))
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: sim.set_integrator("euler"))
        assert apart.timeline.ghosts.integrators == ("rk2", "rk4", "symplectic")
        both((here, apart), running(0.1))
        assert_same_ghosts(here, apart)
        both((here, apart), lambda sim: (sim.reset(), sim.start(), running(0.1)(sim)))
        assert_same_ghosts(here, apart)
        assert apart.ghost_host.pid == pid  # one child for the viewer's life
        both((here, apart), lambda sim: sim.toggle_ghosts())
        assert apart.timeline.ghosts is None and apart.timeline.drifts() == []
    finally:
        close(apart)


def test_an_edit_that_cannot_reach_the_ghosts_process_says_so():
    _, apart = pair()
    try:
        apart.toggle_ghosts()
        apart.start()
        index = 0
        with pytest.raises(TypeError, match="must pickle"):
            apart.timeline.ghosts.edited(lambda world: world.remove_sphere(index), 0)
    finally:
        close(apart)


def test_a_ghost_world_that_fails_in_the_child_stops_the_ghosts_and_the_hud_says_why():
    from ballpit.viewer.handover import timeline_lines

    _, apart = pair()
    try:
        both((apart,), lambda sim: (sim.toggle_ghosts(), sim.start(), running(0.1)(sim)))
        apart.timeline.ghosts.edited(methodcaller("no_such_method"), apart.timeline.history.current)
        with pytest.raises(RuntimeError, match="no_such_method"):
            apart.timeline.ghosts.frame_at(apart.timeline.history.current + 1, wait=WAIT)
        assert any(line.startswith("ghosts stopped: AttributeError") for line in timeline_lines(apart))
        both((apart,), lambda sim: (sim.toggle_ghosts(), sim.toggle_ghosts()))  # G twice: they start again
        assert apart.timeline.ghosts.error is None
    finally:
        close(apart)


def test_frames_are_found_by_the_latest_step_at_or_before_and_the_oldest_go_first():
    frames = Frames(keep=3)
    for step in (4, 8, 12, 16):
        frames.add(GhostFrame(step, step / 240, {}))
    assert frames.get(4) is None  # past the bound
    assert frames.at_or_before(11).step == 8 and frames.at_or_before(None).step == 16
    assert frames.at_or_before(7) is None
    frames.forget_after(8)
    assert frames.at_or_before(None).step == 8
    frames.forget_after(None)
    assert frames.at_or_before(None) is None


def test_the_ghosts_process_imports_no_window_or_gl():
    script = "import sys, ballpit.viewer.ghostproc; print(sorted({m.split('.')[0] for m in sys.modules}))"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert "numpy" in out
    for name in ("pyglet", "OpenGL", "imgui_bundle"):
        assert f"'{name}'" not in out


def gone(pid: int) -> bool:
    """The process has exited (a zombie nobody reaped counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


@pytest.mark.slow
def test_the_ghosts_process_ends_when_the_viewer_process_dies_without_closing_it():
    """The viewer's process ends with os._exit while the child steps ahead: the child sees its socket
    close and exits by itself."""
    script = textwrap.dedent(
        """
        import math, os, sys
        sys.path.insert(0, sys.argv[1])
        from tests.viewer.conftest import line_of_balls
        from ballpit.viewer.simulation import Simulation
        sim = Simulation(line_of_balls(40), step_budget=math.inf)
        sim.ghosts_apart()
        sim.toggle_ghosts()
        sim.start()
        sim.advance(1 / 60)
        sim.timeline.settle_ghosts(120)
        print(sim.ghost_host.pid, flush=True)
        os._exit(0)
        """
    )
    command = [sys.executable, "-c", script, str(REPO)]
    out = subprocess.run(command, capture_output=True, text=True, timeout=300)
    pid = int(out.stdout.split()[0])
    deadline = time.perf_counter() + 30
    while not gone(pid) and time.perf_counter() < deadline:
        time.sleep(0.05)
    assert gone(pid)


def test_closing_never_waits_for_the_ghosts_process_in_the_middle_of_its_steps():
    sim = Simulation(line_of_balls(40), step_budget=math.inf)
    sim.ghosts_apart()
    sim.toggle_ghosts()
    sim.start()
    sim.advance(1 / 60)
    sim.timeline.settle_ghosts(WAIT)  # the child now steps a second ahead of the run
    pid = sim.ghost_host.pid
    started = time.perf_counter()
    sim.close()
    assert time.perf_counter() - started < 0.5
    deadline = time.perf_counter() + 10
    process = sim.ghost_host._process
    while process.returncode is None and time.perf_counter() < deadline:
        time.sleep(0.02)
    assert process.returncode is not None  # ended and reaped by the host itself: no zombie is left
    assert not os.path.exists(f"/proc/{pid}")


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_after_a_move_back_in_time_the_child_steps_ahead_of_that_step_not_of_the_old_present():
    _, apart = pair()
    try:
        both((apart,), lambda sim: (sim.toggle_ghosts(), sim.start(), running(0.5)(sim)))
        both((apart,), lambda sim: (sim.toggle_pause(), sim.scrub(0.0)))
        assert apart.timeline.history.current == 0
        ahead = apart.timeline.ghosts.ahead
        assert ahead >= 240  # at least a second ahead
        assert apart.timeline.ghosts.frame_at(ahead, wait=WAIT).step == ahead  # it steps on from 0...
        time.sleep(0.3)
        assert apart.ghost_host.reached == ahead  # ...and stops there, not 0.5 s later
    finally:
        close(apart)


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_the_child_hears_how_far_the_run_got_every_bit_of_its_reach_and_stays_that_far_ahead():
    from ballpit.viewer.ghostproc import TELL_EVERY

    _, apart = pair()
    try:
        both((apart,), lambda sim: (sim.toggle_ghosts(), sim.start()))
        ghosts, host = apart.timeline.ghosts, apart.ghost_host
        tell = round(ghosts.ahead * TELL_EVERY)
        assert tell > 1

        def reached_after(steps: int) -> int:
            """Step the run ``steps`` steps, sampling the energy every one (as the viewer's thread does
            every frame); the step the child then stops at."""
            for _ in range(steps):
                apart.lead(1)
            time.sleep(0.5)
            ghosts.frame_at(ghosts.target, wait=WAIT)  # it is past the run's step
            deadline = time.perf_counter() + WAIT
            while time.perf_counter() < deadline:
                before = host.reached
                time.sleep(0.3)
                if host.reached == before:
                    return before
            raise AssertionError("the child never stopped")

        first = reached_after(0)
        assert first == ghosts.ahead  # the run at step 0: its reach past it
        assert reached_after(tell - 1) == first  # not told yet: it waits where it was
        assert reached_after(1) == tell + ghosts.ahead  # told: its whole reach past the run again
    finally:
        close(apart)
