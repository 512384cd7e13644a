"""Offscreen rendering to an MP4, a GIF or PNGs through pyglet's headless EGL mode: no display needed.

``render`` switches this process to headless GL (it cannot open a window afterwards; see backend.py),
starts the drop at once and steps the physics exactly 1/fps of simulated time per frame, whatever the
wall time. Output by ``out``: ``*.mp4`` an H.264 video (mp4.py; it needs PyAV), ``*.gif`` an animated
GIF, ``*.png`` one PNG of the last frame, a directory (existing, ending in ``/`` or without a suffix)
numbered PNG frames ``frame_0000.png``, ...
"""

from __future__ import annotations

import itertools
import math
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import backend
from .camera import Camera
from .simulation import Simulation

if TYPE_CHECKING:
    from .mp4 import Mp4Writer

OUTPUT_KINDS = "a .mp4 file, a .gif file, a .png file or a directory (ending in /) for PNG frames"
# A GIF is written at the end from all its frames, which stay in memory until then (Pillow needs them
# together): at most this many bytes of them (one byte a pixel), 34 s at 960x540 and 30 fps. PNG frames
# and MP4 frames go to disk one by one, at most MAX_FRAMES of them (55 min at 30 fps).
MAX_GIF_BYTES = 512 << 20
MAX_FRAMES = 100_000


class Offscreen:
    """A headless GL context with a framebuffer of ``size`` and a Renderer: draw scenes into images."""

    def __init__(self, size: tuple[int, int] = (800, 450), samples: int = 4) -> None:
        backend.use_headless()
        import pyglet
        from pyglet import gl

        config = gl.Config(major_version=3, minor_version=3, forward_compatible=True)
        # The window is only a pbuffer that owns the context; drawing goes to our framebuffer.
        self.window = pyglet.window.Window(width=16, height=16, visible=False, config=config)
        self.window.switch_to()

        from .frame import FrameFeeder
        from .framebuffer import Framebuffer
        from .renderer import Renderer

        self.width, self.height = int(size[0]), int(size[1])
        self.renderer = Renderer()
        self.target = Framebuffer(self.width, self.height, samples)
        self.feeder = FrameFeeder(self.renderer)

    def draw(self, camera: Camera) -> np.ndarray:
        """Draw what was uploaded to the renderer; returns the image (H, W, 3) uint8, top row first."""
        self.window.switch_to()
        self.target.bind()
        self.renderer.draw(camera, self.width, self.height, multisample=self.target.multisample)
        return self.target.read()

    def render(self, sim: Simulation, camera: Camera, flags: object = None) -> np.ndarray:
        """Upload the simulation's current (interpolated) state and draw it."""
        self.window.switch_to()
        self.feeder.upload(sim, flags, camera.position)  # type: ignore[arg-type]
        return self.draw(camera)

    def close(self) -> None:
        self.window.switch_to()
        self.target.delete()
        self.renderer.delete()
        self.window.close()

    def __enter__(self) -> Offscreen:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def gif_palette(sample: np.ndarray, sphere_colors: np.ndarray, ramps: int = 8, shades: int = 8):
    """One 256-colour palette for every GIF frame: the sample frame's main colours (median cut) plus
    shades of the commonest ball colours, which are too few pixels to survive a plain median cut."""
    from PIL import Image

    colors, counts = np.unique(
        np.round(np.asarray(sphere_colors) * 255).astype(int), axis=0, return_counts=True
    )
    chosen = colors[np.argsort(-counts)[:ramps]]
    k = np.linspace(0.35, 1.15, shades)[None, :, None]
    ramp = np.clip(chosen[:, None, :] * k + np.maximum(k - 1.0, 0.0) * 255, 0, 255).reshape(-1, 3)
    base_count = 256 - len(ramp)
    base = Image.fromarray(sample).quantize(colors=base_count, method=Image.Quantize.MEDIANCUT).getpalette()
    entries = list(base[: base_count * 3]) + [int(v) for v in ramp.reshape(-1)]
    entries += [0] * (768 - len(entries))
    palette = Image.new("P", (1, 1))
    palette.putpalette(entries)
    return palette


def gif_durations(frames: int, fps: float) -> list[int]:
    """Per-frame GIF delays in milliseconds that keep the animation on time.

    GIF stores delays in whole hundredths of a second, so 1/30 s cannot be written as such (Pillow
    truncates 33 ms to 30, and a 30 fps GIF played 11 % fast). Frame i starts at round(100·i/fps)
    hundredths instead: the delays alternate (30 and 40 ms at 30 fps), every frame starts within
    5 ms of its true time and the total is exact to the hundredth.
    """
    starts = [round(100 * i / fps) for i in range(frames + 1)]
    return [10 * (b - a) for a, b in itertools.pairwise(starts)]


def _output_kind(out: Path, raw: str) -> str:
    if raw.endswith(("/", os.sep)) or out.is_dir() or not out.suffix:
        return "frames"
    suffix = out.suffix.lower()
    if suffix in (".gif", ".png", ".mp4"):
        return suffix[1:]
    raise ValueError(f"out must be {OUTPUT_KINDS}, got {raw!r}")


def frame_count(duration: float, fps: float, size: tuple[int, int], kind: str) -> int:
    """How many frames ``duration`` s at ``fps`` makes; ValueError when that is more than the output
    ``kind`` ("gif", "png" or "frames") takes (see MAX_GIF_BYTES and MAX_FRAMES)."""
    wanted = duration * fps
    if not wanted <= MAX_FRAMES:  # inf and NaN too
        raise ValueError(
            f"{duration:g} s at {fps:g} fps is {wanted:.3g} frames; the limit is {MAX_FRAMES:,} "
            f"({MAX_FRAMES / fps:.4g} s at {fps:g} fps)"
        )
    frames = max(1, round(wanted))
    if kind == "gif" and frames * size[0] * size[1] > MAX_GIF_BYTES:
        most = MAX_GIF_BYTES // (size[0] * size[1])
        raise ValueError(
            f"{duration:g} s at {fps:g} fps is {frames:,} frames of {size[0]}x{size[1]}; a GIF holds its "
            f"frames in memory until written, at most {most:,} at this size ({most / fps:.3g} s): render "
            "a shorter clip, a smaller --size or a lower --fps, or PNG frames into a folder"
        )
    return frames


def _check(duration: float, fps: float, size: tuple[int, int], kind: str = "gif") -> tuple[int, int]:
    if not (isinstance(duration, int | float) and math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    if width < 16 or height < 16 or width > 8192 or height > 8192:
        raise ValueError(f"size must be between 16 and 8192 pixels each way, got {size!r}")
    if kind == "mp4" and (width % 2 or height % 2):
        raise ValueError(f"an MP4's size must be even each way (H.264's 4:2:0 colour), got {width}x{height}")
    return width, height


def _open_video(out: Path, kind: str, size: tuple[int, int], fps: float) -> Mp4Writer | None:
    """The MP4 writer for ``out`` when ``kind`` is "mp4", else None."""
    if kind != "mp4":
        return None
    from .mp4 import Mp4Writer

    return Mp4Writer(out, size, fps)


@contextmanager
def _closing(video: Mp4Writer | None) -> Iterator[None]:
    """Finish the video when the frames are done; drop the unfinished file when they are not."""
    try:
        yield
    except BaseException:
        if video is not None:
            video.abort()
        raise
    if video is not None:
        video.close()


def render(
    scene_path: Path,
    out: Path,
    duration: float = 4.0,
    fps: float = 30.0,
    size: tuple[int, int] = (800, 450),
    progress: bool = True,
    each_frame: Callable[[], None] | None = None,
) -> Path:
    """Render the scene file's drop, starting at once, to ``out``; returns the path written."""
    from ballpit.scene import read_scene

    scene = read_scene(scene_path)
    return render_world(
        scene, out, duration, fps, size, progress, scene_path=Path(scene_path), each_frame=each_frame
    )


def render_world(
    world: object,
    out: Path | str,
    duration: float = 4.0,
    fps: float = 30.0,
    size: tuple[int, int] = (800, 450),
    progress: bool = True,
    scene_path: Path | None = None,
    samples: int = 4,
    each_frame: Callable[[], None] | None = None,
) -> Path:
    """Render a Scene, or a World built in code, like ``render`` does. ``each_frame`` is called before
    every frame (the command line's check for a stop signal whose exception was lost)."""
    from PIL import Image
    from tqdm import tqdm

    raw = str(out)
    out = Path(out)
    kind = _output_kind(out, raw)
    width, height = _check(duration, fps, size, kind)
    frames = frame_count(duration, fps, (width, height), kind)
    digits = max(4, len(str(frames - 1)))  # frame_0000.png ...: names sort in frame order
    if kind == "frames":
        out.mkdir(parents=True, exist_ok=True)
    elif kind != "mp4":  # an MP4's folder must exist, as simulate's outputs' do (the CLI says so)
        out.parent.mkdir(parents=True, exist_ok=True)

    sim = Simulation(world, scene_path, step_budget=math.inf)
    look = sim.appearance
    camera = Camera.looking_at(look.camera_position, look.camera_look_at)
    sim.start()
    images: list[Image.Image] = []
    palette: Image.Image | None = None
    last: np.ndarray | None = None
    video = _open_video(out, kind, (width, height), fps)
    with _closing(video), Offscreen((width, height), samples) as screen:
        bar = tqdm(
            range(frames), desc=f"rendering {look.name}", unit="frame", file=sys.stderr, disable=not progress
        )
        for index in bar:
            if each_frame is not None:
                each_frame()
            if index:
                remaining = 1.0 / fps
                while remaining > 1e-12:  # the accumulator takes at most 0.25 s per call
                    chunk = min(remaining, 0.2)
                    sim.advance(chunk)
                    remaining -= chunk
            last = screen.render(sim, camera)
            if kind == "frames":
                Image.fromarray(last).save(out / f"frame_{index:0{digits}d}.png")
            elif kind == "gif":
                if palette is None:
                    palette = gif_palette(last, look.sphere_colors)
                images.append(Image.fromarray(last).quantize(palette=palette, dither=Image.Dither.NONE))
            elif video is not None:
                video.write(last)
    if kind == "gif":
        images[0].save(
            out,
            save_all=True,
            append_images=images[1:],
            duration=gif_durations(len(images), fps),
            loop=0,
            disposal=1,
        )
    elif kind == "png":
        Image.fromarray(last).save(out)
    return out
