"""The headless runner in-process: step plans, energies, the recorded outputs against a direct run."""

from __future__ import annotations

import re
import signal
from dataclasses import replace
from pathlib import Path

import pytest

import ballpit
from ballpit.cli.simulate import (
    MAX_STEPS,
    Energy,
    RunSummary,
    TooManySteps,
    energy,
    format_summary,
    run,
    step_plan,
)

from .runner import run_in_process

ROOT = Path(__file__).resolve().parents[2]


def test_step_plan_ends_exactly_and_refuses_more_than_max_steps():
    assert step_plan(0.105, 0.01) == [(10, 0.01), (1, pytest.approx(0.005))]
    assert step_plan(1.0, 0.25) == [(4, 0.25)]
    assert sum(n for n, _ in step_plan(1.0, 1.0 / MAX_STEPS)) == MAX_STEPS
    with pytest.raises(TooManySteps, match=r"1e\+301 steps; the limit is 1e\+09"):
        step_plan(10.0, 1e-300)
    with pytest.raises(TooManySteps, match="inf steps"):
        step_plan(1e300, 1e-300)


ROLLING_STOP = """
[[plane]]
normal = [0, 1, 0]
rolling_friction = 0.3

[[sphere]]
position = [0, 0.5, 0]
radius = 0.5
velocity = [1, 0, 0]
angular_velocity = [0, 0, -2]
rolling_friction = 0.3
"""


def test_energy_is_the_worlds_own_and_includes_spin():
    world = ballpit.World(gravity=(0, -2.0, 0))
    world.add_sphere(position=(0, 3, 0), radius=0.5, mass=2.0, velocity=(1, 0, 0), angular_velocity=(0, 0, 4))
    world.add_sphere(position=(5, 1, 0), radius=0.2, hollow=True, angular_velocity=(3, 0, 0))
    e = energy(world)
    spin = 0.5 * (0.4 * 2.0 * 0.25) * 16 + 0.5 * (2 / 3 * 1.0 * 0.04) * 9
    assert e.kinetic == pytest.approx(0.5 * 2.0 * 1.0 + spin, rel=1e-12)
    assert e.potential == pytest.approx(2.0 * 2.0 * 3 + 1.0 * 2.0 * 1, rel=1e-12)
    assert (e.kinetic, e.potential) == (world.kinetic_energy(), world.potential_energy())


def test_summary_prints_energies_that_are_zero_to_within_rounding_as_0(tmp_path):
    """A ball stopped by rolling friction reports a kinetic energy of exactly 0 (it kept about 1e-71 J
    of rounding residue while friction and rolling resistance were solved one after the other); such a
    residue next to 4.9 J prints as 0 too."""
    scene = tmp_path / "stop.toml"
    scene.write_text(ROLLING_STOP)
    world = ballpit.load_scene(scene)
    summary = run(world, 2.0, 1 / 240)
    assert summary.energy_end.kinetic == 0.0
    residue = replace(summary, energy_end=Energy(1e-71, summary.energy_end.potential))
    for ran in (summary, residue):
        lines = format_summary(ran, "stop", "rk4", 1 / 240, 1)
        assert lines[-1].endswith("end 4.905 J (kinetic 0 + potential 4.905)"), lines[-1]
        assert "e-" not in lines[-1]


def test_small_but_real_energies_are_kept():
    start, end = Energy(0.0, 1000.0), Energy(1e-9, 999.0)
    summary = RunSummary(1, 1.0, 1.0, 0, 0, 0, start, end)
    assert "kinetic 1e-09" in format_summary(summary, "x", "rk4", 0.01, 1)[-1]
    assert "potential 0)" in format_summary(RunSummary(1, 1.0, 1.0, 0, 0, 0, start, Energy(1.0, 1e-14)),
                                            "x", "rk4", 0.01, 1)[-1]  # fmt: skip


def read_profile(stdout: str) -> tuple[dict[str, float], str]:
    """The stage times (ms per step) and the counts line that ``simulate --profile`` printed."""
    ms, counts = {}, ""
    for line in stdout.splitlines():
        match = re.fullmatch(r"\s+(.+?)\s+(\d+\.\d+) ms", line)
        if match:
            ms[match.group(1)] = float(match.group(2))
        elif "intervals/step" in line:
            counts = line
    return ms, counts


@pytest.mark.slow
@pytest.mark.parametrize(("scene", "crowded"), [("slopes", False), ("pile", True)])
def test_profile_prints_the_time_of_every_stage_and_the_counts_per_step(scene, crowded):
    from ballpit.physics.core.profile import STAGES

    command = ["simulate", f"scenes/{scene}.toml", "--duration", "0.8", "--profile", "-q"]
    r = run_in_process(*command, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    ms, counts = read_profile(r.stdout)
    assert set(STAGES) | {"step"} == set(ms), r.stdout
    assert 0 < sum(ms[s] for s in STAGES) <= ms["step"] * 1.01 + 0.002  # the stages are inside the step
    steps = int(re.search(r"over (\d+) steps", r.stdout).group(1))
    rate = {"slopes": 240, "pile": 60}[scene]  # pile: 1/60 s frames of 4 soft substeps
    assert steps == round(0.8 * rate)
    intervals = float(re.search(r"intervals/step (\d+\.\d+)", counts).group(1))
    assert intervals >= 1.0
    taken_whole = int(re.search(rf"crowded (\d+)/{steps}", counts).group(1))
    assert (taken_whole > 0) == crowded, counts


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # the dropped exception
def test_a_stop_signal_whose_exception_python_dropped_still_ends_the_run():
    """A stop signal handled inside code whose exceptions Python ignores (here a weakref callback, as
    importlib's module-lock one is) loses the handler's exception, and the handler has set the stop
    signals to be ignored by then: the stepping loop raises the stop again at its next step."""
    import gc
    import weakref

    import ballpit.cli as cli

    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    world = ballpit.World()
    world.add_sphere(position=(0, 1, 0), radius=0.1)
    seen: list[int] = []
    refs: list[weakref.ref] = []

    class Token:
        pass

    def observe(w):
        seen.append(1)
        if len(seen) == 10:
            token = Token()
            refs.append(weakref.ref(token, lambda _: cli._on_stop_signal(signal.SIGTERM, None)))
            del token  # the callback runs here; what it raises is printed and dropped
            gc.collect()
            assert cli._stopped_by == [signal.SIGTERM]  # the handler ran; its exception went nowhere

    cli._stopped_by.clear()
    try:
        with pytest.raises(cli.Terminated):
            run(world, 1.0, 0.01, observe=observe)
    finally:
        cli._stopped_by.clear()
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
    assert len(seen) == 10  # stopped at the step after the lost one, not at the run's end (101)
