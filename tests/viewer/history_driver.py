"""Scenarios for the history, replay, ghosts and energy plot, in a real viewer window under Xvfb.

Run as ``python history_driver.py SCENARIO WORKDIR`` (test_history_window.py does this). Keys go in as
pyglet events dispatched into the real window; the timeline is scrubbed with real X pointer events
from xdotool. The last stdout line is ``RESULT <json>``.
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import window_driver as wd

import ballpit
from ballpit.physics import INTEGRATOR_NAMES
from ballpit.viewer.ghosts import TINTS
from ballpit.viewer.screen import timeline_bar

DT = 1 / 240  # the default timestep of a world built in code


def digest(world: ballpit.World) -> str:
    """Every ball's full state and the time, bit for bit."""
    return hashlib.sha256(world.state.body.tobytes() + np.float64(world.time).tobytes()).hexdigest()


def reference_digests(make, steps: int, integrator: str | None = None) -> list[str]:
    """The state after 0, 1, ..., ``steps`` steps of a plain headless run."""
    world = make()
    if integrator:
        world.integrator = integrator
    out = [digest(world)]
    for _ in range(steps):
        world.step(DT)
        out.append(digest(world))
    return out


def bounce_world() -> ballpit.World:
    """A frictionless ball bouncing on a perfectly elastic ground: the energy is conserved exactly."""
    world = ballpit.World(integrator="rk4")
    world.add_plane(position=(0, 0, 0), restitution=1.0, friction=0.0)
    world.add_sphere(position=(0, 2.0, 0), radius=0.25, restitution=1.0, friction=0.0)
    return world


def press_xdotool_drag(viewer, x0: float, x1: float, y: float) -> None:
    """A real left-button drag along the window from x0 to x1 at height y (pyglet's y, from the bottom)."""
    wid = str(viewer.window._window)
    top = viewer.window.height - y
    wd.xdotool("mousemove", "--window", wid, str(int(x0)), str(int(top)))
    wd.settle(viewer, 3)
    wd.xdotool("mousedown", "1")
    wd.settle(viewer, 3)
    for x in np.linspace(x0, x1, 5)[1:]:
        wd.xdotool("mousemove", "--window", wid, str(int(x)), str(int(top)))
        wd.settle(viewer, 2)
    wd.xdotool("mouseup", "1")
    wd.settle(viewer, 3)


def bar_pixels(viewer) -> int:
    """How many pixels along the timeline bar's row have its colours (drawn, not just computed)."""
    image = wd.grab(viewer)
    x, y, w, h = timeline_bar(viewer.window.width, viewer.panel.width)
    row = image[viewer.window.height - int(y + h / 2), int(x) : int(x + w)]
    return int((row[:, 2] > row[:, 0] + 40).sum())  # the blue of the bar over a dark background


# ---------------------------------------------------------------------- scenarios
def history_keys(workdir: Path) -> dict:
    from pyglet.window import key

    viewer = wd.open_viewer(size=(640, 360), world=wd.balls_world())
    sim = viewer.sim
    reference = reference_digests(wd.balls_world, 600)
    wd.pump(viewer, 2)
    out: dict = {"bar_before_drop": bar_pixels(viewer)}
    wd.press(viewer, "X", frames=90)  # 1.5 s: 360 steps
    wd.press(viewer, "SPACE")
    h = sim.timeline.history
    out["paused_at"] = h.current
    out["paused_matches"] = digest(sim.world) == reference[h.current]
    checks = []

    def check(label: str) -> None:
        checks.append([label, h.current, digest(sim.world) == reference[h.current]])

    for _ in range(3):
        wd.press(viewer, "LEFT")
        check("left")
    wd.press(viewer, "LEFT", modifiers=key.MOD_SHIFT)
    check("shift+left")
    wd.press(viewer, "RIGHT")
    check("right")
    wd.press(viewer, "N")
    check("n")
    wd.press(viewer, "RIGHT", modifiers=key.MOD_SHIFT)
    check("shift+right")
    out["checks"] = checks
    out["latest"] = h.latest
    out["bar_pixels"] = bar_pixels(viewer)
    out["labels"] = [c.label for c in viewer.renderer.draws.calls]

    wd.point_at(viewer)
    x, y, w, bh = timeline_bar(viewer.window.width, viewer.panel.width)
    press_xdotool_drag(viewer, x + 0.8 * w, x + 0.25 * w, y + bh / 2)  # real pointer: drag back to 25 %
    out["scrubbed_to"] = h.current
    out["scrub_expected"] = round(0.25 * h.latest)
    out["scrub_matches"] = digest(sim.world) == reference[h.current]
    out["scrub_phase"] = sim.phase.name
    out["hud"] = viewer.hud.text

    resumed_from = h.current
    wd.press(viewer, "SPACE")  # resume from the past: the future is dropped
    out["after_resume_latest"] = h.latest
    out["resumed_from"] = resumed_from
    wd.pump(viewer, 20)
    wd.press(viewer, "SPACE")
    out["rerun_at"] = h.current
    out["rerun_matches"] = digest(sim.world) == reference[h.current]
    return out


def ghosts_and_plot(workdir: Path) -> dict:
    viewer = wd.open_viewer(size=(1280, 720), world=bounce_world(), panel=True)
    sim = viewer.sim
    wd.press(viewer, "G")  # before the drop: the ghosts drop with X
    wd.press(viewer, "P")  # the panel's energy plot
    wd.press(viewer, "X", frames=180)  # 3 s: two bounces
    wd.press(viewer, "SPACE")
    steps = sim.timeline.history.current
    out: dict = {"steps": steps, "drifts": sim.timeline.drifts()}
    # the same drift, worked out headless: the run and plain copies under the other integrators
    expected, before_last = {}, {}
    for name in INTEGRATOR_NAMES:
        world = bounce_world()
        e0 = world.kinetic_energy() + world.potential_energy()
        world.integrator = name
        for step in range(steps):
            if step == steps - 1:
                before_last[name] = np.array(world.spheres.positions)
            world.step(DT)
        expected[name] = ((world.kinetic_energy() + world.potential_energy()) - e0) / abs(e0) * 100
    out["expected"] = expected
    out["ghosts_in_a_process"] = sim.timeline.ghosts.remote and sim.ghost_host.child_cpu() > 0.0
    wd.pump(viewer, 1, dt=0.0)
    out["hud"] = viewer.hud.text
    out["calls"] = [[c.label, c.instances] for c in viewer.renderer.draws.calls]
    image = wd.grab(viewer)
    x, top, w, h = viewer.panel.rects["plot area energy"]  # window pixels, top row first
    region = image[int(top) : int(top + h), int(x) : int(x + w)]
    tints = {name: tuple(round(255 * c) for c in TINTS[name]) for name in ("euler", "rk4")}
    out["plot_pixels"] = {
        name: int((np.abs(region - np.array(c)).max(axis=-1) < 40).sum()) for name, c in tints.items()
    }
    pink = (region[..., 0] > 220) & (region[..., 1] < 160) & (region[..., 2] > 180)  # the kinetic energy
    out["kinetic_pixels"] = int(pink.sum())
    series = sim.timeline.energy.series()
    out["series"] = sorted(series)
    out["span"] = float(series["time"][-1] - series["time"][0])
    # stepping back moves the ghosts too: the window draws them where the same runs were a step earlier
    wd.press(viewer, "LEFT")
    shown = viewer.shown
    out["ghost_step_after_left"] = shown.ghost_step
    out["ghosts_after_left_match"] = {
        name: bool(np.array_equal(positions, before_last[name])) for name, positions, _, _ in shown.ghosts
    }
    wd.press(viewer, "G")
    wd.pump(viewer, 1, dt=0.0)
    out["calls_off"] = [c.label for c in viewer.renderer.draws.calls]
    return out


def replay(workdir: Path) -> dict:
    from ballpit.cli.trajectory import read_trajectory

    scene = Path(sys.argv[3])
    trajectory = read_trajectory(workdir / sys.argv[4])
    viewer = wd.open_viewer(
        size=(640, 360), scene_path=scene, trajectory=read_trajectory(workdir / sys.argv[4])
    )
    sim = viewer.sim
    rp = sim.timeline.replay

    def frame_matches() -> bool:
        return bool(np.array_equal(np.asarray(sim.world.spheres.positions), trajectory.position[rp.current]))

    out: dict = {"phase": sim.phase.name, "frames": trajectory.frames, "first": [rp.current, frame_matches()]}
    wd.pump(viewer, 30)  # 0.5 s
    out["after_half_second"] = [rp.current, float(sim.world.time), frame_matches()]
    wd.press(viewer, "SPACE")
    at = rp.current
    wd.pump(viewer, 10)
    out["paused_still"] = rp.current == at
    wd.press(viewer, "LEFT")
    out["left"] = [at, rp.current, frame_matches()]
    wd.press(viewer, "RIGHT")
    wd.press(viewer, "RIGHT")
    out["right_twice"] = [rp.current, frame_matches()]
    wd.point_at(viewer)
    x, y, w, bh = timeline_bar(viewer.window.width, viewer.panel.width)
    press_xdotool_drag(viewer, x + 0.5 * w, x + 0.1 * w, y + bh / 2)
    out["scrub"] = [rp.current, rp.latest, frame_matches()]
    wd.type_text(viewer, "+")  # time ×2
    wd.press(viewer, "SPACE")
    t0 = float(sim.world.time)
    wd.pump(viewer, 30)
    out["fast"] = [float(sim.world.time) - t0, sim.time_scale, frame_matches()]
    wd.pump(viewer, 400)
    out["end"] = [rp.current, rp.latest, sim.phase.name]
    out["hud"] = viewer.hud.text
    return out


def replay_refuses_reaching_in(workdir: Path) -> dict:
    """B (a real X key press) and a real pointer drag on a ball, in a replay: each is refused with a
    message, and the replay plays on frame by frame as recorded."""
    from ballpit.cli.trajectory import read_trajectory

    scene = Path(sys.argv[3])
    trajectory = read_trajectory(workdir / sys.argv[4])
    viewer = wd.open_viewer(size=(640, 360), scene_path=scene, trajectory=trajectory)
    sim = viewer.sim
    rp = sim.timeline.replay

    def frame_matches() -> bool:
        return bool(np.array_equal(np.asarray(sim.world.spheres.positions), trajectory.position[rp.current]))

    def state() -> dict:
        return {"frame": rp.current, "matches": frame_matches(), "balls": sim.ball_count,
                "phase": sim.phase.name, "error": sim.error}  # fmt: skip

    wd.pump(viewer, 10)
    wd.point_at(viewer)
    out: dict = {"before": state()}
    wd.xdotool("key", "b")
    wd.settle(viewer)
    out["b_message"] = wd.shown_message(viewer)
    wd.pump(viewer, 30)  # 0.5 s more of the replay
    out["after_b"] = state()

    wd.press(viewer, "SPACE")  # paused, so the ball stays under the pointer
    at = state()
    pixels, _ = viewer.camera.project(np.asarray(sim.world.spheres.positions)[:1], 640, 360)
    x, y = (int(v) for v in pixels[0])  # ball 0's centre, from the top-left corner
    wid = str(viewer.window._window)
    wd.xdotool("mousemove", "--window", wid, str(x), str(y))
    wd.settle(viewer, 3)
    wd.xdotool("mousedown", "1")
    wd.settle(viewer, 3)
    wd.xdotool("mousemove", "--window", wid, str(x + 60), str(y - 40))
    wd.settle(viewer, 3)
    out["drag_message"] = wd.shown_message(viewer)
    out["held"] = viewer.interaction.held_ball
    wd.xdotool("mouseup", "1")
    wd.settle(viewer, 3)
    out["paused_at"], out["after_drag"] = at, state()
    wd.press(viewer, "SPACE")
    wd.pump(viewer, 30)
    out["resumed"] = state()
    return out


def integrator_ghosts_part_ways(workdir: Path) -> dict:
    """The bundled integrators scene: F1 names it beside G; G, then X; where the ghosts are, against
    their balls, in metres and in window pixels, 1 s and 5 s into the drop."""
    from ballpit.viewer.hud import help_text

    scene = Path(sys.argv[3])
    viewer = wd.open_viewer(size=(640, 360), scene_path=scene)
    sim = viewer.sim
    wd.press(viewer, "F1")
    out: dict = {"help_shown": viewer.hud.show_help, "help": help_text()}
    wd.press(viewer, "F1")
    wd.press(viewer, "G")
    wd.press(viewer, "X")
    radius = float(np.median(sim.world.spheres.radii))
    out["radius"] = radius
    for seconds in (1.0, 5.0):
        while sim.world.time < seconds - 1e-9:
            wd.pump(viewer, 1, dt=sim.timestep)  # one step a frame
        main = np.asarray(sim.world.spheres.positions)
        pixels, depth = viewer.camera.project(main, 640, 360)
        focal = 180 / np.tan(np.radians(viewer.camera.fov_y_degrees / 2))
        at: dict = {"time": float(sim.world.time), "drawn_radius": float(np.median(radius / depth * focal))}
        frame = sim.timeline.ghosts.frame_at(sim.timeline.history.current)
        for name, theirs, _, _ in frame.bodies:
            ghost_pixels, _ = viewer.camera.project(theirs, 640, 360)
            at[name] = {
                "metres": np.linalg.norm(theirs - main, axis=1).tolist(),
                "pixels": np.linalg.norm(ghost_pixels - pixels, axis=1).tolist(),
                "time": frame.time,
            }
        wd.pump(viewer, 1, dt=0.0)
        at["calls"] = [[c.label, c.instances] for c in viewer.renderer.draws.calls]
        out[f"t{seconds:g}"] = at
    return out


def ghosts_in_real_time(workdir: Path) -> dict:
    """The viewer's own free run (wall-clock frames, the physics running ahead) with the ghosts on: the
    step each frame draws the ghosts at against the step of the state it shows, then Esc, Esc while the
    ghosts' process steps ahead: how long the window takes to close, and whether the process is gone."""
    import time

    from pyglet.window import key

    world = bounce_world()
    world.add_sphere(position=(1.0, 3.0, 0), radius=0.25, restitution=1.0, friction=0.0)
    viewer = wd.open_viewer(size=(640, 360), world=world)
    wd.press(viewer, "G")
    wd.press(viewer, "X")
    frames = []
    end = time.perf_counter() + 3.0
    while time.perf_counter() < end:
        viewer.pump()
        shown = viewer._drawn_shown  # the state the 3-D view was last drawn from
        frames.append([shown.step, shown.ghost_step, len(shown.ghosts)])
    out: dict = {"frames": frames, "calls": [[c.label, c.instances] for c in viewer.renderer.draws.calls]}
    wd.press(viewer, "SPACE", frames=0)  # paused: a child that fell behind (a loaded machine) catches up
    # until the pause has reached the physics (the steps run ahead dropped, the run put back at the step
    # shown) and the ghosts of that step are drawn: before it, an earlier frame may already agree
    wd.pump_until(
        viewer,
        lambda: (
            viewer._drawn_shown.ghost_step == viewer._drawn_shown.step == viewer.sim.timeline.history.current
        ),
        timeout=30,
    )
    drawn = viewer._drawn_shown
    out["paused"] = [drawn.step, drawn.ghost_step, viewer.sim.timeline.history.current]
    pid = viewer.sim.ghost_host.pid
    out["pid_alive"] = not _gone(pid)
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    wd.pump(viewer, 2, dt=None)
    pressed = time.perf_counter()
    viewer.window.dispatch_event("on_key_press", key.ESCAPE, 0)
    while not viewer.closed and time.perf_counter() - pressed < 10:
        viewer.pump()
    viewer.pump()
    out["quit_seconds"] = time.perf_counter() - pressed
    out["closed"] = viewer.closed
    deadline = time.perf_counter() + 10
    while not _gone(pid) and time.perf_counter() < deadline:
        time.sleep(0.02)
    out["pid_gone"] = _gone(pid)
    return out


def _gone(pid: int) -> bool:
    """The process has exited (reaped, or a zombie)."""
    import os

    try:
        os.waitpid(pid, os.WNOHANG)  # our child: reap it if it has ended
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


SCENARIOS = {
    f.__name__: f
    for f in (
        history_keys,
        ghosts_and_plot,
        replay,
        replay_refuses_reaching_in,
        integrator_ghosts_part_ways,
        ghosts_in_real_time,
    )
}


if __name__ == "__main__":
    wd.main(SCENARIOS)
