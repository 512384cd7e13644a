"""F12: the back buffer (what the frame drew, panel and HUD included) saved as a PNG."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

SCREENSHOT_DIRECTORY = "screenshots"  # F12 saves here, under the current directory


def save_screenshot(width: int, height: int, directory: Path | None = None) -> Path:
    """Save the back buffer as ``ballpit-<date>-<time>[-n].png`` in ``directory`` (``screenshots/`` in
    the current directory, created if need be), never overwriting; returns its resolved path."""
    import numpy as np
    from OpenGL import GL
    from PIL import Image

    GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
    GL.glReadBuffer(GL.GL_BACK)
    data = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
    image = np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3)[::-1]
    directory = Path.cwd() / SCREENSHOT_DIRECTORY if directory is None else directory
    directory.mkdir(parents=True, exist_ok=True)
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    path = directory / f"ballpit-{stamp}.png"
    n = 1
    while path.exists():
        n += 1
        path = directory / f"ballpit-{stamp}-{n}.png"
    Image.fromarray(image).save(path)
    return path.resolve()
