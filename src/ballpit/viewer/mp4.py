"""MP4 (H.264) files from RGB frames, through PyAV: shared by ``ballpit render --out x.mp4`` and the
window's recorder (F9, video.py). No GL here.

A file holds one frame per 1/fps of simulated time at a constant frame rate, so it plays at real
speed whatever the drawing cost. Encoding (RGB to BT.709 YUV 4:2:0, then x264) runs on a thread of its
own: PyAV releases the GIL while FFmpeg converts and encodes, so neither the caller nor the physics
thread waits for it, and the caller only waits when it gets more than ``QUEUED`` frames ahead. The
frames go into a temporary file beside the target (writers.temp_path) that is renamed into place when
the recording ends: an interrupted run leaves no file that looks complete.

PyAV is an optional dependency (``pip install 'ballpit[video]'``): ``have_av`` says whether it is
there, and the command line and the viewer name the extra when it is not.
"""

from __future__ import annotations

import os
import queue
import threading
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

MISSING_AV = "needs PyAV, which is not installed: pip install 'ballpit[video]'"
QUEUED = 8  # frames waiting for the encoder at most (8 frames of 1280x720 are 22 MB)
# x264 settings: a file rendered offline is worth a slower preset; a live recording must keep up with
# the window on a small machine (ultrafast encodes 1280x720 in about 10 ms a frame, veryfast 15-20).
PRESETS = {"file": ("veryfast", 18), "live": ("ultrafast", 20)}


def have_av() -> bool:
    """Whether PyAV can be imported (it is the ``video`` extra, not a core dependency)."""
    try:
        import av  # noqa: F401
    except ImportError:
        return False
    return True


def even_size(width: int, height: int) -> tuple[int, int]:
    """The largest even size within ``width`` x ``height``: 4:2:0 colour needs even sides."""
    return int(width) // 2 * 2, int(height) // 2 * 2


class Mp4Writer:
    """An H.264 MP4 file of ``size`` (width, height, both even) at ``fps`` frames per second.

    ``write(image)`` queues one (H, W, 3) uint8 RGB frame, top row first (``repeat`` times: the same
    picture held for that many frames); ``close()`` finishes the file and renames it into place;
    ``abort()`` drops it. An encoder error is raised from the next ``write`` or ``close``.
    """

    def __init__(self, path: Path | str, size: tuple[int, int], fps: float, kind: str = "file") -> None:
        import av

        from ..cli.writers import remove_stale_temps, temp_path

        width, height = int(size[0]), int(size[1])
        if width % 2 or height % 2 or width < 2 or height < 2:
            raise ValueError(f"an MP4's width and height must be even, got {width}x{height}")
        self.path = Path(path)
        self.size = (width, height)
        self.fps = fps
        self.frames = 0  # frames queued so far
        self.wait_seconds = 0.0  # wall s ``write`` waited for the encoder (its queue full)
        remove_stale_temps(self.path)
        self._temp = temp_path(self.path)
        self._container = av.open(str(self._temp), "w", format="mp4", options={"movflags": "+faststart"})
        try:
            rate = Fraction(fps).limit_denominator(1001)
            stream = self._container.add_stream("libx264", rate=rate)
            stream.width, stream.height, stream.pix_fmt = width, height, "yuv420p"
            preset, crf = PRESETS[kind]
            stream.options = {"preset": preset, "crf": str(crf)}
            codec = stream.codec_context
            codec.time_base = 1 / rate
            # BT.709, limited range, tagged: players show the colours the renderer drew
            codec.colorspace = codec.color_primaries = codec.color_trc = 1
            codec.color_range = 1
        except BaseException:
            self._container.close()
            self._temp.unlink(missing_ok=True)
            raise
        self._stream = stream
        self._queue: queue.Queue[tuple[np.ndarray, int] | None] = queue.Queue(maxsize=QUEUED)
        self._error: BaseException | None = None
        self._closed = False
        self._thread = threading.Thread(target=self._encode_all, name="ballpit mp4", daemon=True)
        self._thread.start()

    @property
    def duration(self) -> float:
        """Seconds of video queued so far."""
        return self.frames / self.fps

    def write(self, image: np.ndarray, repeat: int = 1) -> None:
        """Queue ``image`` as the next ``repeat`` frames (cropped to the file's size if larger)."""
        self._raise_error()
        if repeat < 1:
            return
        width, height = self.size
        image = np.asarray(image)
        if image.shape[0] < height or image.shape[1] < width or image.shape[2:] != (3,):
            raise ValueError(f"a frame of {width}x{height} RGB was expected, got shape {image.shape}")
        self._put((image[:height, :width], int(repeat)))
        self.frames += int(repeat)

    def _put(self, item: tuple[np.ndarray, int] | None) -> None:
        """Queue ``item``, waiting while the encoder is ``QUEUED`` frames behind (not if it failed)."""
        while True:
            if item is not None:
                self._raise_error()
            if not self._thread.is_alive():
                return
            try:
                self._queue.put_nowait(item)
                return
            except queue.Full:
                pass
            started = time.perf_counter()
            try:
                self._queue.put(item, timeout=0.1)
                return
            except queue.Full:
                continue
            finally:
                self.wait_seconds += time.perf_counter() - started

    def close(self) -> Path:
        """Encode what is queued, finish the file and move it into place; returns its path."""
        if not self._closed:
            self._closed = True
            self._put(None)
            self._thread.join()
            if self._error is None:
                try:
                    self._container.close()
                except BaseException as exc:
                    self._error = exc
            if self._error is not None:
                self._temp.unlink(missing_ok=True)
                self._raise_error()
            os.replace(self._temp, self.path)
        return self.path

    def abort(self) -> None:
        """Stop now and remove the unfinished file."""
        if self._closed:
            return
        self._closed = True
        self._error = self._error or RuntimeError("aborted")  # the encoder stops at the next frame
        self._put(None)
        self._thread.join()
        try:
            self._container.close()
        except Exception:
            pass
        self._temp.unlink(missing_ok=True)

    def _raise_error(self) -> None:
        if self._error is not None:
            error = self._error
            if isinstance(error, OSError):
                raise error
            raise OSError(f"video encoding failed: {type(error).__name__}: {error}") from error

    def _encode_all(self) -> None:
        """The encoder thread: frames off the queue, each converted, encoded and muxed in order."""
        import av

        stream, container = self._stream, self._container
        pts = 0
        try:
            while True:
                item = self._queue.get()
                if item is None or self._error is not None:
                    break
                image, repeat = item
                frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(image), format="rgb24")
                frame = frame.reformat(format="yuv420p", dst_colorspace="ITU709", dst_color_range="MPEG")
                for _ in range(repeat):
                    frame.pts = pts
                    pts += 1
                    for packet in stream.encode(frame):
                        container.mux(packet)
            if self._error is None:
                for packet in stream.encode():  # flush the encoder's delayed frames
                    container.mux(packet)
        except BaseException as exc:
            self._error = exc
