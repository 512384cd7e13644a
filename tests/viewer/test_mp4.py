"""MP4 output: the writer offscreen (frame count, duration, a decoded frame against the PNG of the same
step), the recorder's frame clock, and the command line with and without PyAV."""

from __future__ import annotations

import subprocess
import sys

import av
import numpy as np
import pytest
from PIL import Image

from ..cli.runner import ROOT
from ..cli.runner import run_in_process as ballpit
from .conftest import line_of_balls


def decode(path) -> tuple[list[np.ndarray], dict]:
    """Every frame of an MP4 as RGB arrays, and what its container says (frames, seconds, rate)."""
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        facts = {
            "frames": stream.frames,
            "seconds": float(stream.duration * stream.time_base),
            "container_seconds": container.duration / 1e6,
            "rate": float(stream.average_rate),
            "codec": stream.codec_context.name,
            "size": (stream.width, stream.height),
        }
        frames = [frame.to_ndarray(format="rgb24") for frame in container.decode(video=0)]
    return frames, facts


def luma(image: np.ndarray) -> np.ndarray:
    """BT.709 luma of an RGB image: what H.264 keeps at full resolution."""
    rgb = image.astype(float)
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def test_an_mp4_render_holds_one_frame_per_step_of_1_over_fps_and_each_is_that_steps_png(offscreen, tmp_path):
    from ballpit.viewer.render import render_world

    kwargs = {"duration": 1.2, "fps": 10, "size": (320, 180), "progress": False, "samples": 0}
    out = render_world(line_of_balls(), tmp_path / "drop.mp4", **kwargs)
    render_world(line_of_balls(), f"{tmp_path}/frames/", **kwargs)
    assert out == tmp_path / "drop.mp4"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["drop.mp4", "frames"]  # no temporary file left
    frames, facts = decode(out)
    assert facts["codec"] == "h264" and facts["size"] == (320, 180)
    assert len(frames) == facts["frames"] == 12
    assert facts["seconds"] == pytest.approx(1.2) and facts["container_seconds"] == pytest.approx(1.2)
    assert facts["rate"] == pytest.approx(10.0)
    pngs = [np.asarray(Image.open(p).convert("RGB")) for p in sorted((tmp_path / "frames").iterdir())]
    assert len(pngs) == 12
    for k, frame in enumerate(frames):
        # H.264 at crf 18 rounds each 4x4 or 8x8 block's frequencies, and 4:2:0 keeps colour at half
        # resolution: the picture is close everywhere (mean under 3 of 255 levels; 99 % of values
        # within 12), but a colour edge (a red ball on the grey ground) shares its chroma with the
        # pixels beside it, so single RGB values there can be off by 60-90. Luma is kept at full
        # resolution: every pixel's luma is within 32 levels (measured at most 24).
        diff = np.abs(frame.astype(int) - pngs[k].astype(int))
        assert diff.mean() < 3.0, k
        assert np.percentile(diff, 99) <= 12, k
        assert np.abs(luma(frame) - luma(pngs[k])).max() <= 32, k
        # and it is that step's picture, not a neighbour's: where the balls moved between the PNGs
        # before and after it, it matches PNG k best
        near = range(max(k - 1, 0), min(k + 2, len(pngs)))
        moved = np.zeros(frame.shape[:2], bool)
        for j in near:
            moved |= np.abs(pngs[j].astype(int) - pngs[k].astype(int)).max(axis=2) > 40
        assert moved.sum() > 50, k  # the balls move in every frame of this clip
        errors = {j: np.abs(frame[moved].astype(int) - pngs[j][moved].astype(int)).mean() for j in near}
        assert min(errors, key=errors.get) == k, (k, errors)


def test_the_mp4_writer_holds_a_picture_for_repeated_frames_and_an_abort_leaves_no_file(tmp_path):
    from ballpit.viewer.mp4 import Mp4Writer

    red, blue = np.zeros((64, 96, 3), np.uint8), np.zeros((64, 96, 3), np.uint8)
    red[..., 0], blue[..., 2] = 220, 220
    writer = Mp4Writer(tmp_path / "held.mp4", (96, 64), 30)
    writer.write(red, repeat=3)
    writer.write(blue)
    assert writer.frames == 4 and writer.duration == pytest.approx(4 / 30)
    assert writer.close() == tmp_path / "held.mp4"
    frames, facts = decode(tmp_path / "held.mp4")
    # (so short a clip ends 5 of the muxer's 1/15360 s ticks early: x264's B-frame delay)
    assert facts["frames"] == 4 and facts["seconds"] == pytest.approx(4 / 30, abs=1e-3)
    assert [int(np.argmax(f.reshape(-1, 3).mean(axis=0))) for f in frames] == [0, 0, 0, 2]  # red x3, blue

    aborted = Mp4Writer(tmp_path / "dropped.mp4", (96, 64), 30)
    aborted.write(red)
    aborted.abort()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["held.mp4"]
    with pytest.raises(ValueError, match="even"):
        Mp4Writer(tmp_path / "odd.mp4", (95, 64), 30)


def test_the_frame_clock_gives_one_frame_per_1_over_fps_of_running_simulated_time():
    from ballpit.viewer.video import FrameClock

    clock = FrameClock(30)
    # a window drawing states 1/60 s apart: every other one is a video frame, the first at once
    assert [clock.due(k / 60, True) for k in range(7)] == [1, 0, 1, 0, 1, 0, 1]
    # a window drawing slower than the video (states 1/10 s apart): each picture held for 3 frames
    assert [clock.due(0.1 + k / 10, True) for k in range(1, 4)] == [3, 3, 3]
    frames = clock.frames
    assert frames == 4 + 9 and clock.last == pytest.approx(0.4)
    # paused: nothing; a step or scrub while paused adds nothing either
    assert clock.due(0.4, False) == 0 and clock.due(0.9, False) == 0
    # resumed (wherever the pause left it): the first running state is the next frame, then 1/fps on
    assert [clock.due(0.9 + k / 30, True) for k in range(3)] == [1, 1, 1]
    # back in time (R, a step back, a reload): a cut, and on from there
    assert clock.due(0.0, True) == 1 and clock.due(1 / 60, True) == 0 and clock.due(2 / 60, True) == 1


def test_render_to_mp4_on_the_command_line_and_its_one_line_refusals(tmp_path):
    r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / "s.mp4", "--duration", "0.5", "--fps",
                "12", "--size", "160x90")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"wrote {tmp_path / 's.mp4'}"
    _, facts = decode(tmp_path / "s.mp4")
    assert facts["frames"] == 6 and facts["seconds"] == pytest.approx(0.5) and facts["size"] == (160, 90)

    r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / "missing" / "s.mp4", "--duration", "0.1")
    line = assert_user_error(r)
    assert "directory" in line and "missing" in line and "does not exist" in line
    r = ballpit("render", "scenes/slopes.toml", "--out", tmp_path / "s2.mp4", "--size", "161x90")
    assert "even" in assert_user_error(r)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.mp4"]


def assert_user_error(r: subprocess.CompletedProcess) -> str:
    """Exit status 2, no traceback, one line on stderr; returns it."""
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    return lines[0]


# ballpit as installed without the video extra: PyAV cannot be imported in that process.
WITHOUT_AV = (
    "import sys; sys.modules['av'] = None; from ballpit.cli import main; sys.exit(main(sys.argv[1:]))"
)


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_without_pyav_render_to_mp4_says_which_extra_to_install_and_gif_still_works(tmp_path):
    def run(*args: object) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-c", WITHOUT_AV, *map(str, args)], capture_output=True,
                              text=True, cwd=ROOT, timeout=120)  # fmt: skip

    r = run("render", "scenes/slopes.toml", "--out", tmp_path / "x.mp4", "--duration", "0.1")
    line = assert_user_error(r)
    assert "needs PyAV" in line and "pip install 'ballpit[video]'" in line
    gif = tmp_path / "x.gif"
    r = run("render", "scenes/slopes.toml", "--out", gif, "--duration", "0.1", "--size", "64x48")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.gif"]


@pytest.mark.slow
def test_ctrl_c_during_an_mp4_render_leaves_no_file(tmp_path):
    import signal
    import time

    from ..cli.test_commands import running, wait_for

    out = tmp_path / "long.mp4"
    args = ["render", "scenes/slopes.toml", "--out", out, "--duration", "30", "--size", "64x48"]
    with running(*args) as proc:
        wait_for(lambda: any(tmp_path.glob("long.mp4.*.partial")))  # the writer is open
        time.sleep(1.0)  # and frames are going in
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert stderr.strip().splitlines()[-1] == "ballpit: interrupted"
    assert list(tmp_path.iterdir()) == []


def test_the_window_video_takes_the_3d_view_right_of_the_panel_round_its_centre():
    from ballpit.viewer.video import view_crop

    # the panel (330 px) shown: the 950 px right of it, the whole frame
    assert view_crop(1280, 720, 330, (950, 720)) == ((330, 0, 950, 720), (0, 0))
    # hidden while recording: the view widens to 1280 px about the same middle; its middle 950 are kept
    assert view_crop(1280, 720, 0, (950, 720)) == ((165, 0, 950, 720), (0, 0))
    # the window shrunk to 800x450: all of its view, centred in the frame (black round it)
    assert view_crop(800, 450, 330, (950, 720)) == ((330, 0, 470, 450), (240, 135))
