"""``render``: offscreen GIF / PNG / frame-folder output, the drop starting at once, a progress bar."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image, ImageSequence

from .conftest import line_of_balls

SCENE = """
[camera]
position = [0, 3, 9]
look_at = [0, 2, 0]

[[plane]]
position = [0, 0, 0]

[[plane]]
position = [0, 2, 0]
rotation = [0, 0, 20]
size = 3
restitution = 0.9

[[sphere]]
position = [0, 4.5, 0]
radius = 0.4
color = "#e0482f"
"""


def frames_of(path) -> list[np.ndarray]:
    with Image.open(path) as gif:
        return [np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(gif)]


def test_render_writes_an_animated_gif_of_the_drop_starting_at_once(offscreen, tmp_path, capsys):
    from ballpit.viewer.render import render

    scene = tmp_path / "drop.toml"
    scene.write_text(SCENE)
    out = render(scene, tmp_path / "drop.gif", duration=0.6, fps=10, size=(96, 64))
    assert out == tmp_path / "drop.gif"
    frames = frames_of(out)
    assert len(frames) == 6
    assert frames[0].shape == (64, 96, 3)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 60  # the ball has fallen
    first = frames[0].astype(int)
    red = (first[..., 0] > first[..., 1] + 60) & (first[..., 0] > first[..., 2] + 60)
    assert red.sum() >= 4  # the small red ball keeps its colour through the GIF palette
    err = capsys.readouterr().err
    assert "rendering drop.toml" in err and "6/6" in err  # tqdm progress bar on stderr


def test_render_to_a_directory_writes_numbered_png_frames(offscreen, tmp_path, capsys):
    from ballpit.viewer.render import render_world

    out = render_world(
        line_of_balls(), f"{tmp_path}/frames/", duration=0.3, fps=10, size=(48, 32), progress=False
    )
    names = sorted(p.name for p in out.iterdir())
    assert names == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
    with Image.open(out / "frame_0002.png") as image:
        assert image.size == (48, 32)
    assert capsys.readouterr().err == ""  # progress=False: silent


def test_render_to_a_png_file_writes_the_last_frame(offscreen, tmp_path):
    from ballpit.viewer.render import render_world

    out = render_world(
        line_of_balls(), tmp_path / "shot.png", duration=0.1, fps=10, size=(40, 30), progress=False
    )
    with Image.open(out) as image:
        assert image.size == (40, 30)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"out": "movie.avi"}, "out must be"),
        ({"duration": 0}, "duration"),
        ({"fps": -1}, "fps"),
        ({"size": (8, 8)}, "size"),
    ],
)
def test_bad_render_arguments_raise_value_errors_naming_them(tmp_path, kwargs, message):
    from ballpit.viewer.render import render_world

    args = {
        "out": tmp_path / "x.gif",
        "duration": 0.1,
        "fps": 10,
        "size": (32, 32),
        "progress": False,
    } | kwargs
    if isinstance(args["out"], str):
        args["out"] = tmp_path / args["out"]
    with pytest.raises(ValueError, match=message):
        render_world(line_of_balls(), **args)


@pytest.mark.parametrize("fps", [30, 24, 20, 7])
def test_a_gif_plays_for_exactly_its_duration_at_any_frame_rate(offscreen, tmp_path, fps):
    from ballpit.viewer.render import render

    scene = tmp_path / "drop.toml"
    scene.write_text(SCENE)
    out = render(scene, tmp_path / "drop.gif", duration=1.0, fps=fps, size=(48, 32), progress=False)
    with Image.open(out) as gif:
        durations = [frame.info["duration"] for frame in ImageSequence.Iterator(gif)]
    assert sum(durations) == 1000  # GIF delays are whole hundredths of a second, so exactly 100 of them
    # Pillow merges identical frames; each written frame still starts within 5 ms of its true time
    starts = np.cumsum([0, *durations[:-1]])
    nearest = np.round(starts * fps / 1000) * 1000 / fps
    assert np.abs(starts - nearest).max() <= 5
