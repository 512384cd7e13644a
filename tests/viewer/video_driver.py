"""Drives a real viewer window under Xvfb and records it to MP4 with F9 (test_video_window.py runs it).

Same protocol as window_driver.py: ``python video_driver.py NAME[,NAME...] WORKDIR``, a ``RESULT``
line per scenario. Keys go in as real pyglet events through the window's event queue.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from window_driver import balls_world, main, open_viewer, press, pump, pump_for


def _video(viewer) -> dict:
    finished = viewer.video.last_video
    return {"path": str(finished.path), "frames": finished.frames, "seconds": finished.seconds,
            "exists": finished.path.exists()}  # fmt: skip


def f9_lockstep(workdir: Path) -> dict:
    """F9 while the balls fall, 1.5 s of frames of 1/60 s, F9 again; then a pause in the middle of a
    second recording (Space) adds nothing."""
    viewer = open_viewer(size=(320, 180), world=balls_world())
    press(viewer, "X", frames=3)
    first_times = []
    viewer.window.dispatch_event("on_key_press", *_key("F9"))
    for _ in range(90):
        pump(viewer, 1)
        first_times.append(viewer.shown.time)
    recording = viewer.video.is_recording
    press(viewer, "F9", frames=1)
    out = {"recording": recording, "times": first_times, "first": _video(viewer), "fps": viewer.video.fps,
           "started_at": viewer.video.started_at}  # fmt: skip
    # a second one: 0.5 s running, 1 s paused, 0.5 s running
    press(viewer, "F9")
    pump(viewer, 29)
    press(viewer, "SPACE", frames=60)
    press(viewer, "SPACE", frames=30)
    press(viewer, "F9")
    out["paused"] = _video(viewer)
    out["names"] = sorted(p.name for p in (workdir / "videos").iterdir())
    return out


def f9_real_time(workdir: Path) -> dict:
    """The window in real time (the physics on its own thread, as in ``ballpit view``) at 640x360:
    F9 for about 2 s of the run, then F9; the simulated time the video covers."""
    viewer = open_viewer(size=(640, 360), world=balls_world())
    press(viewer, "X", frames=2)
    pump_for(viewer, 0.3)
    viewer.window.dispatch_event("on_key_press", *_key("F9"))
    times = []
    for _ in range(10_000):
        viewer.pump()
        times.append(viewer.shown.time)
        if len(times) > 3 and times[-1] - times[0] >= 2.0:
            break
    frames_drawn = len(times)
    viewer.window.dispatch_event("on_key_press", *_key("F9"))
    viewer.pump()
    return {"times": times, "frames_drawn": frames_drawn, "video": _video(viewer), "fps": viewer.video.fps,
            "started_at": viewer.video.started_at, "last": viewer.video.clock.last,
            "rate": viewer.sim.real_time_factor}  # fmt: skip


def f9_without_pyav(workdir: Path) -> dict:
    """PyAV cannot be imported (as in a minimal install): F9 says which extra to install."""
    sys.modules["av"] = None  # type: ignore[assignment]  # import av now raises ImportError
    viewer = open_viewer(size=(320, 180), world=balls_world())
    press(viewer, "X", frames=2)
    press(viewer, "F9", frames=5)
    return {"recording": viewer.video.is_recording, "message": viewer.hud.message,
            "videos": (workdir / "videos").exists()}  # fmt: skip


def _key(name: str) -> tuple[int, int]:
    from pyglet.window import key

    return getattr(key, name), 0


SCENARIOS = {f.__name__: f for f in (f9_lockstep, f9_real_time, f9_without_pyav)}

if __name__ == "__main__":
    main(SCENARIOS)
