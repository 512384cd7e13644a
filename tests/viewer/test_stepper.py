"""The physics thread beside the window (stepper.py) and its hand-over (handover.py): commands run
between steps and never inside one, results come back on the caller's thread, lockstep frames are
exact, the real-time factor is what the physics managed, and stopping never waits for a step."""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

from ballpit.scene import Scene, default_appearance
from ballpit.viewer import stepper
from ballpit.viewer.handover import Needs, capture
from ballpit.viewer.simulation import Phase, Simulation
from ballpit.viewer.stepper import PhysicsThread

from .conftest import line_of_balls


def wait_for(condition, timeout: float = 10.0) -> bool:
    end = time.monotonic() + timeout
    while not condition() and time.monotonic() < end:
        time.sleep(0.005)
    return condition()


def test_lockstep_frames_advance_exactly_the_time_given_and_apply_commands_first():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    physics = PhysicsThread(sim)
    try:
        physics.submit(lambda s: s.start())
        for _ in range(30):
            physics.advance(1.0 / 60.0)
        assert sim.phase is Phase.RUNNING
        assert sim.steps_total == 120  # 0.5 s at 1/240 s
        np.testing.assert_array_equal(physics.shown.positions, sim.render_state()[0])  # interpolated
        assert physics.shown.bar.now == 120 * sim.timestep  # every hand-over is of the state now
        physics.sync()  # the HUD's facts are read at most 10 times a second, or when asked
        assert physics.shown.hud.time == sim.world.time
    finally:
        physics.stop()


def test_commands_sent_while_it_runs_free_are_applied_between_steps_and_answered_on_the_callers_thread():
    sim = Simulation(line_of_balls(3))
    inside = []
    sim.before_step.append(lambda: inside.append(True))
    sim.after_step.append(lambda: inside.pop())
    physics = PhysicsThread(sim)
    seen, answers = [], []
    try:
        physics.submit(lambda s: s.start())
        physics.run_free()
        assert wait_for(lambda: sim.steps_total > 20)
        for k in range(20):
            physics.submit(lambda s, k=k: (seen.append((bool(inside), threading.get_ident())), k)[1],
                           lambda k: answers.append((k, threading.get_ident())))  # fmt: skip
            time.sleep(0.003)
        assert wait_for(lambda: len(seen) == 20)
        physics.deliver()
    finally:
        physics.stop()
    assert not any(mid_step for mid_step, _ in seen)  # never inside a step
    assert {ident for _, ident in seen} == {physics._thread.ident}  # on the physics thread
    assert answers == [(k, threading.get_ident()) for k in range(20)]  # in order, back on this thread


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_the_real_time_factor_is_what_slow_steps_manage_not_the_time_scale():
    """Each step made to take 20 ms of wall time: at most 50 steps of 1/240 s a second, a real-time
    factor of at most 50/240 = 0.21, whatever is asked."""
    sim = Simulation(line_of_balls(3))
    sim.before_step.append(lambda: time.sleep(0.02))
    physics = PhysicsThread(sim)
    try:
        physics.submit(lambda s: s.start())
        physics.run_free()
        assert wait_for(lambda: sim.real_time_factor > 0.0)
        time.sleep(1.2)
        factor, steps_per_second = sim.real_time_factor, sim.steps_per_second
    finally:
        physics.stop()
    assert 0.0 < factor <= 50 * sim.timestep * 1.05
    assert factor == np.float64(steps_per_second * sim.timestep) or math.isclose(
        factor, steps_per_second * sim.timestep, rel_tol=1e-9
    )


def test_steps_slower_than_real_time_follow_each_other_without_a_pause():
    """Frames of 1/60 s that each take 25 ms of wall time: the physics is behind, so it must step again at
    once. Timing the next step from the batch's start slept about a third of every batch away (each
    batch's own time only counted at the next), and the real-time factor fell below what steps manage."""
    world = line_of_balls(3)
    sim = Simulation(Scene(world, default_appearance(world), timestep=1.0 / 60.0))
    sim.before_step.append(lambda: time.sleep(0.025))
    physics = PhysicsThread(sim)
    try:
        physics.submit(lambda s: s.start())
        physics.run_free()
        assert wait_for(lambda: sim.steps_total > 2)
        idle, started = physics.idle_seconds, time.perf_counter()
        time.sleep(1.0)
        idle, wall = physics.idle_seconds - idle, time.perf_counter() - started
        busy = physics.busy_fraction
    finally:
        physics.stop()
    assert idle < 0.05 * wall, (idle, wall)
    assert busy > 0.9  # what the window reads to draw less (pacing.py)


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_the_busy_share_is_near_zero_while_nothing_steps_and_near_one_while_steps_run_late():
    world = line_of_balls(3)
    sim = Simulation(Scene(world, default_appearance(world), timestep=1.0 / 60.0))
    physics = PhysicsThread(sim, hold=False)
    try:
        physics.run_free()
        time.sleep(1.2)  # waiting for X, not held: it only sleeps
        waiting = physics.busy_fraction
        sim.before_step.append(lambda: time.sleep(0.03))  # every 1/60 s step takes 30 ms
        physics.submit(lambda s: s.start())
        assert wait_for(lambda: physics.busy_fraction > 0.9, timeout=5.0)
    finally:
        physics.stop()
    assert waiting < 0.1


@pytest.mark.slow  # waits out seconds of a long step by design
def test_stop_returns_at_once_in_the_middle_of_a_long_step():
    sim = Simulation(line_of_balls(3))
    started = threading.Event()

    def long_step() -> None:
        started.set()
        time.sleep(1.0)

    sim.before_step.append(long_step)
    physics = PhysicsThread(sim)
    physics.submit(lambda s: s.start())
    physics.run_free()
    assert started.wait(10)
    t = time.perf_counter()
    physics.stop()
    assert time.perf_counter() - t < 0.1
    assert physics.lock.locked()  # the step is still running: it was not waited for
    assert wait_for(lambda: not physics.alive, 5.0)  # and the thread ends after it, taking no more


def test_the_handover_is_a_copy_that_later_steps_leave_alone():
    sim = Simulation(line_of_balls(3), step_budget=math.inf)
    sim.start()
    sim.advance(0.1)
    shown = capture(sim, Needs(velocities=True, trails=True))
    positions, velocities = shown.positions.copy(), shown.velocities.copy()
    sim.advance(0.1)
    np.testing.assert_array_equal(shown.positions, positions)
    np.testing.assert_array_equal(shown.velocities, velocities)
    assert not np.array_equal(sim.world.spheres.positions, positions)
    assert shown.hud.time < sim.world.time and shown.trails is not None


def _cost(sim: Simulation, dear_from: float, dear_until: float, factor: float) -> None:
    """Each step between ``dear_from`` and ``dear_until`` (simulated s) takes ``factor`` times its dt of
    wall time; the others next to none."""

    def spend() -> None:
        if dear_from <= sim.world.time < dear_until:
            time.sleep(factor * sim.timestep)

    sim.before_step.append(spend)


def _shown_speed(physics: PhysicsThread, until: float) -> float:
    """Simulated over wall seconds of what the window is shown, from now until the shown state
    reaches ``until``."""
    start, began = physics.shown.time, time.perf_counter()
    while physics.shown.time < until:
        time.sleep(0.002)
        assert time.perf_counter() - began < 20
    return (physics.shown.time - start) / (time.perf_counter() - began)


@pytest.mark.slow
def test_a_dear_stretch_after_a_cheap_one_is_shown_in_real_time_from_the_steps_taken_ahead():
    # The first second costs nothing, the next 0.4 s 1.5x real time, then nothing again: on average
    # cheaper than real time, as pile.toml's fall and landing are. Running ahead, what the window shows
    # keeps real time throughout; stepping on the wall clock alone, the dear stretch plays slowly.
    speeds, ahead = {}, stepper.LEAD_SECONDS
    for lead in (ahead, 0.0):
        sim = Simulation(line_of_balls(3))
        _cost(sim, 1.0, 1.4, 1.5)
        physics = PhysicsThread(sim, lead=lead)
        try:
            physics.submit(lambda s: s.start())
            physics.run_free()
            speeds[lead] = _shown_speed(physics, 1.6)
            if lead:
                assert sim.real_time_factor == pytest.approx(1.0, abs=0.05)  # the speed shown
        finally:
            physics.stop()
    assert speeds[ahead] == pytest.approx(1.0, abs=0.04), speeds
    assert speeds[0.0] < 0.9, speeds  # 1.6 s shown in 1.8 s of wall time


def test_a_command_sent_while_the_run_is_ahead_acts_on_the_state_the_window_shows():
    # The world is put back at the step the window shows (its kept snapshot, restored), exactly as the
    # run had it there: a fresh run stepped that far has the same bits.
    sim = Simulation(line_of_balls(3))
    physics = PhysicsThread(sim)
    got = []
    try:
        physics.submit(lambda s: s.start())
        physics.run_free()
        assert wait_for(lambda: sim.world.time - physics.shown.time > 0.2)  # stepping ahead
        ahead, shown = sim.world.time, physics.shown.time
        physics.submit(lambda s: got.append((s.world.time, s.world.spheres.positions.copy())))
        assert wait_for(lambda: got)
    finally:
        physics.stop()
    at, positions = got[0]
    assert shown <= at < ahead
    fresh = line_of_balls(3)
    while fresh.time < at - 0.5 * sim.timestep:
        fresh.step(sim.timestep)
    assert fresh.time == at
    np.testing.assert_array_equal(positions, fresh.spheres.positions)


def test_a_record_closed_while_the_run_is_ahead_ends_at_the_state_the_window_shows(tmp_path):
    from ballpit.viewer.recording import Recorder

    sim = Simulation(line_of_balls(3))
    recorder = Recorder(tmp_path / "run.npz", sim)
    physics = PhysicsThread(sim)
    try:
        physics.submit(lambda s: s.start())
        physics.run_free()
        assert wait_for(lambda: sim.world.time - physics.shown.time > 0.2)
    finally:
        physics.stop()
    assert wait_for(lambda: not physics.alive)
    shown = physics.shown
    _, steps, _ = recorder.finish(shown.step)
    assert steps == shown.step < sim.timeline.history.current  # the steps taken ahead are left out
    with np.load(tmp_path / "run.npz") as run:
        assert run["time"].max() == shown.time


def _steps_while_drawing(physics: PhysicsThread, drawing: bool) -> float:
    """The share of windows of 5 ms, each opened 2 ms after a frame began (a batch under way ends
    first), in which the thread stepped; windows the test's own thread overslept (beyond 8 ms, under
    load) are left out."""
    stepped, windows = 0, 0
    for _ in range(60):
        physics.window_drawing(drawing)
        time.sleep(0.002)
        before, began = physics.sim.world.time, time.perf_counter()
        time.sleep(0.005)
        after, ended = physics.sim.world.time, time.perf_counter()
        physics.window_drawing(False)
        if ended - began < 0.008:
            windows += 1
            stepped += after != before
        if windows == 12:
            break
        time.sleep(0.02)  # the window waits for the rasteriser: the thread catches up
    assert windows >= 6
    return stepped / windows


def test_a_run_far_ahead_waits_for_the_window_to_lay_out_its_frame_and_steps_in_between(monkeypatch):
    # At 4 times real time and a 1/60 s step the thread needs a batch every 4 ms, so it steps in nearly
    # every 5 ms window; far enough ahead, not while the window lays out a frame (GATE_WAIT: 10 ms),
    # unless it is busy stepping more than GATE_BUSY of the time (set here below what it needs).
    world = line_of_balls(1)
    sim = Simulation(Scene(world, default_appearance(world), timestep=1.0 / 60.0))
    physics = PhysicsThread(sim, lead=2.0)
    try:
        physics.submit(lambda s: (s.start(), setattr(s, "time_scale", 4.0)))
        physics.run_free()
        far = 2 * stepper.GATE_AHEAD * 4.0
        assert wait_for(lambda: sim.world.time - physics.shown.time > far, timeout=30.0)
        monkeypatch.setattr(stepper, "GATE_BUSY", 1.0)  # however busy
        free = _steps_while_drawing(physics, drawing=False)
        laid_out = _steps_while_drawing(physics, drawing=True)
        assert sim.world.time - physics.shown.time > stepper.GATE_AHEAD * 4.0  # still far ahead
        monkeypatch.setattr(stepper, "GATE_BUSY", -1.0)  # busier than that: it steps at once
        busy = _steps_while_drawing(physics, drawing=True)
    finally:
        physics.stop()
    assert free >= 0.6, free
    assert laid_out <= 0.3, laid_out
    assert busy >= 0.6, busy


def test_the_tuning_comes_from_the_environment_only_where_the_viewer_starts_the_thread():
    """The lead, the switch interval and where the ghosts run."""
    defaults = {"lead": stepper.LEAD_SECONDS, "switch_interval": stepper.SWITCH_INTERVAL}
    defaults |= {"ghosts_apart": True, "hold": True, "gate_ahead": stepper.GATE_AHEAD}
    defaults |= {"hold_reach": stepper.HOLD_REACH}
    assert stepper.tuning_from({}) == defaults
    environ = {"BALLPIT_LEAD": "0", "BALLPIT_SWITCH": "0.002", "BALLPIT_GHOSTS": "thread"}
    environ |= {"BALLPIT_HOLD": "0", "BALLPIT_GATE": "inf", "BALLPIT_HOLD_REACH": "3"}
    tuned = stepper.tuning_from(environ)
    assert tuned == {"lead": 0.0, "switch_interval": 0.002, "ghosts_apart": False, "hold": False,
                     "gate_ahead": math.inf, "hold_reach": 3.0}  # fmt: skip
    sim = Simulation(line_of_balls(3))
    physics = PhysicsThread(sim, **tuned)
    try:
        assert physics.lead == 0.0 and not physics._may_run_ahead()  # held to the wall clock
        sim.toggle_ghosts()
        assert not sim.timeline.ghosts.remote  # stepped on the physics thread
    finally:
        physics.stop()


def _held(physics: PhysicsThread) -> bool:
    """The scene waits for X while the thread has stepped a lead of its drop."""
    return _held_to(physics, physics.lead)


def test_a_waiting_scene_is_stepped_ahead_but_shown_at_its_first_state_until_x():
    sim = Simulation(line_of_balls(3))
    physics = PhysicsThread(sim)
    try:
        physics.run_free()
        assert wait_for(lambda: _held(physics))
        time.sleep(0.1)
        shown = physics.shown
        assert sim.phase is Phase.WAITING  # what is asked before X sees it waiting
        assert shown.time == 0.0 and shown.hud.state == Phase.WAITING.value
        np.testing.assert_array_equal(shown.positions, line_of_balls(3).spheres.positions)
        assert sim.world.time >= physics.lead - 1e-9  # its first second stepped meanwhile
    finally:
        physics.stop()


def test_x_shows_the_steps_taken_while_held_from_that_instant_bit_for_bit():
    sim = Simulation(line_of_balls(3))
    physics = PhysicsThread(sim)
    try:
        physics.run_free()
        assert wait_for(lambda: _held(physics))
        stepped = sim.world.time
        physics.submit(lambda s: s.start(), rewind=False)
        pressed = time.perf_counter()
        assert wait_for(lambda: physics.shown.time >= 0.2)
        shown, wall = physics.shown, time.perf_counter() - pressed
    finally:
        physics.stop()
    assert shown.time <= stepped  # one of the states stepped before X
    assert shown.time == pytest.approx(wall, abs=0.05)  # shown from X at real speed
    assert shown.hud.state == Phase.RUNNING.value and shown.message == "dropped"
    fresh = line_of_balls(3)
    while fresh.time < shown.time - 0.5 * sim.timestep:
        fresh.step(sim.timestep)
    np.testing.assert_array_equal(shown.positions, fresh.spheres.positions)


def test_anything_asked_before_x_undoes_the_hold_and_finds_the_first_state_bit_for_bit(tmp_path):
    from ballpit.viewer.recording import Recorder

    sim = Simulation(line_of_balls(3))
    recorder = Recorder(tmp_path / "run.npz", sim)
    physics = PhysicsThread(sim)
    seen = []
    try:
        physics.run_free()
        assert wait_for(lambda: _held(physics))
        assert recorder.steps > 0  # the held steps were recorded as they were taken
        physics.submit(lambda s: seen.append((s.phase, s.world.time, s.timeline.history,
                                              s.world.spheres.positions.copy(), recorder.steps)))  # fmt: skip
        assert wait_for(lambda: seen)
        physics.submit(lambda s: s.start())  # X after something else: the drop as it always was
        assert wait_for(lambda: sim.world.time > 0.3)
        physics.submit(lambda s: seen.append((s.world.time, s.world.spheres.positions.copy())))
        assert wait_for(lambda: len(seen) == 2)
    finally:
        physics.stop()
    phase, at, history, positions, steps = seen[0]
    assert (phase, at, history, steps) == (Phase.WAITING, 0.0, None, 0)
    np.testing.assert_array_equal(positions, line_of_balls(3).spheres.positions)
    at, positions = seen[1]
    fresh = line_of_balls(3)
    while fresh.time < at - 0.5 * sim.timestep:
        fresh.step(sim.timestep)
    np.testing.assert_array_equal(positions, fresh.spheres.positions)


@pytest.mark.slow
def test_a_dear_start_is_shown_in_real_time_from_the_steps_taken_while_the_scene_waited_for_x():
    # Its first 0.9 s cost 1.5x real time each. Held before X, the first second is stepped while the
    # scene waits, and shown from X in real time. Not held, the 0.9 s take 1.35 s from X, and the run
    # is shown at 2/3 of real time.
    speeds = {}
    for hold in (True, False):
        sim = Simulation(line_of_balls(3))
        _cost(sim, 0.0, 0.9, 1.5)
        physics = PhysicsThread(sim, hold=hold)
        try:
            physics.run_free()
            if hold:
                assert wait_for(lambda physics=physics: _held(physics))
            else:
                time.sleep(1.0)
                assert sim.world.time == 0.0
            physics.submit(lambda s: s.start(), rewind=False)
            speeds[hold] = _shown_speed(physics, 0.9)
        finally:
            physics.stop()
    assert speeds[True] == pytest.approx(1.0, abs=0.04), speeds
    assert speeds[False] < 0.8, speeds


def test_a_waiting_scene_is_held_though_the_file_watch_asks_every_tenth_of_a_second():
    # the file watch reads nothing the steps change (it does not rewind): it is not something asked
    # that would undo the hold
    sim = Simulation(line_of_balls(3))
    physics = PhysicsThread(sim)
    try:
        physics.run_free()
        deadline = time.monotonic() + 10
        while not _held(physics) and time.monotonic() < deadline:
            physics.submit(lambda s: s.file_changed(), rewind=False)
            time.sleep(0.1)
        assert _held(physics)
    finally:
        physics.stop()


def _held_to(physics: PhysicsThread, seconds: float) -> bool:
    """The scene waits for X with ``seconds`` of its drop stepped."""
    sim = physics.sim
    return sim.held and sim.world.time >= seconds - 1e-9 and not physics._commands


def _holding(monkeypatch, ghosts: bool = False, **tuning) -> PhysicsThread:
    """A thread running free beside three balls waiting for X (with the ghosts on), its hold not cut
    short by HOLD_SECONDS however long a loaded machine takes to step it."""
    monkeypatch.setattr(stepper, "HOLD_SECONDS", math.inf)
    physics = PhysicsThread(Simulation(line_of_balls(3)), **tuning)
    if ghosts:
        physics.submit(lambda s: s.toggle_ghosts())
    physics.run_free()
    return physics


def test_a_small_scene_is_held_to_its_reach_and_shown_from_x_without_a_step_while_the_queue_lasts(
    monkeypatch,
):
    # held 6 s into its drop: after X the first 4.5 s are shown from the queue (it stays a lead of
    # 1.5 s ahead), the thread taking no step, and the HUD counts the steps it shows
    physics = _holding(monkeypatch, hold_reach=6.0)
    sim = physics.sim
    try:
        assert wait_for(lambda: _held_to(physics, 6.0), timeout=60)
        time.sleep(0.2)
        assert sim.world.time <= 6.0 + stepper.LEAD_FRAME + 1e-9  # no further than its reach
        steps = sim.steps_total
        physics.submit(lambda s: s.start(), rewind=False)
        pressed = time.perf_counter()
        assert wait_for(lambda: physics.shown.time >= 1.5)
        shown, wall = physics.shown, time.perf_counter() - pressed
        taken, rate = sim.steps_total - steps, sim.steps_per_second
    finally:
        physics.stop()
    assert taken == 0
    assert shown.time == pytest.approx(wall, abs=0.05)  # shown from X at real speed
    assert rate == pytest.approx(1.0 / sim.timestep, rel=0.1)
    fresh = line_of_balls(3)
    while fresh.time < shown.time - 0.5 * sim.timestep:
        fresh.step(sim.timestep)
    np.testing.assert_array_equal(shown.positions, fresh.spheres.positions)


def test_a_hold_queues_no_more_states_than_its_memory_allows(monkeypatch):
    # a budget of 1 s of this scene's queued states: held 1 s into its drop, not its 10 s reach nor
    # the 1.5 s lead (pile10k.toml's snapshots are 5.7 MB each)
    per_second = (stepper.QUEUED_BYTES + 3 * stepper.QUEUED_BYTES_PER_BALL) / stepper.LEAD_FRAME
    monkeypatch.setattr(stepper, "HOLD_MEMORY", 1.0 * per_second)
    physics = _holding(monkeypatch, hold_reach=10.0)
    sim = physics.sim
    try:
        assert wait_for(lambda: _held_to(physics, 1.0))
        time.sleep(0.3)
        held, queued = sim.world.time, len(physics._ahead)
    finally:
        physics.stop()
    assert held <= 1.0 + stepper.LEAD_FRAME + 1e-9 < physics.lead
    assert queued <= round(1.0 / stepper.LEAD_FRAME) + 1


@pytest.mark.slow  # the ghosts' process
def test_every_state_shown_from_a_long_hold_has_the_ghosts_of_its_own_step(monkeypatch):
    # the run held 10 s ahead of what is shown, the ghosts' process further still: each state queued
    # was captured with the ghosts (and their energies, for the HUD) of its own step, and the frames of
    # the steps shown are still kept when the window comes to them
    physics = _holding(monkeypatch, ghosts=True, ghosts_apart=True, hold_reach=10.0)
    sim = physics.sim
    try:
        assert wait_for(lambda: _held_to(physics, physics._reach()), timeout=300)
        with physics._handover_lock:
            queued = [state for _, state in physics._ahead]
        assert len(queued) >= 500 and all(state.ghost_step == state.step for state in queued)
        physics.submit(lambda s: s.start(), rewind=False)
        assert wait_for(lambda: physics.shown.time > 0.0)  # X applied: the queued states come due
        seen = set()
        while len(seen) < 20:
            shown = physics.shown
            shown.resolve_ghosts()
            assert shown.ghosts is not None and shown.ghost_step == shown.step
            seen.add(shown.step)
            time.sleep(0.05)
    finally:
        physics.stop()
        host = sim.ghost_host
        if host is not None:
            host._process.wait(timeout=10)


def test_a_hold_with_the_ghosts_stepped_on_its_own_thread_reaches_as_far_as_without_them(monkeypatch):
    physics = _holding(monkeypatch, ghosts=True, ghosts_apart=False, hold_reach=3.0)
    try:
        assert wait_for(lambda: _held_to(physics, 3.0))
        assert not physics.sim.timeline.ghosts.remote
    finally:
        physics.stop()
