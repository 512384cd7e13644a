"""An offscreen framebuffer to render into and read back: colour RGBA8 + 24-bit depth, optionally
multisampled (resolved into a single-sample buffer before reading)."""

from __future__ import annotations

import numpy as np
from OpenGL import GL


class FramebufferError(RuntimeError):
    """The driver rejected the framebuffer configuration."""


def _framebuffer(width: int, height: int, samples: int) -> tuple[int, list[int]]:
    fbo = GL.glGenFramebuffers(1)
    GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
    color, depth = GL.glGenRenderbuffers(2)
    for rb, fmt, attachment in ((color, GL.GL_RGBA8, GL.GL_COLOR_ATTACHMENT0),
                                (depth, GL.GL_DEPTH_COMPONENT24, GL.GL_DEPTH_ATTACHMENT)):  # fmt: skip
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, rb)
        if samples:
            GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, samples, fmt, width, height)
        else:
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, fmt, width, height)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, attachment, GL.GL_RENDERBUFFER, rb)
    status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
    if status != GL.GL_FRAMEBUFFER_COMPLETE:
        raise FramebufferError(
            f"offscreen framebuffer {width}x{height} ({samples} samples) incomplete: {status:#x}"
        )
    return fbo, [color, depth]


class Framebuffer:
    """Bind it, draw, then ``read()`` the image as an (H, W, 3) uint8 array, top row first."""

    def __init__(self, width: int, height: int, samples: int = 0) -> None:
        self.width, self.height = int(width), int(height)
        max_samples = int(GL.glGetIntegerv(GL.GL_MAX_SAMPLES))
        self.samples = min(int(samples), max_samples) if samples else 0
        self.fbo, self._renderbuffers = _framebuffer(self.width, self.height, self.samples)
        self.resolve_fbo = None
        if self.samples:
            self.resolve_fbo, more = _framebuffer(self.width, self.height, 0)
            self._renderbuffers += more
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)

    @property
    def multisample(self) -> bool:
        return self.samples > 0

    def bind(self) -> None:
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.fbo)

    def present(self, width: int, height: int) -> None:
        """Copy the image into the window's back buffer, ``width`` x ``height`` pixels (scaled up
        smoothly when the view is drawn at a lower resolution). Leaves the window's framebuffer bound."""
        w, h = self.width, self.height
        source = self.fbo
        if self.resolve_fbo is not None:  # a multisampled image resolves only at its own size
            GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.fbo)
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, self.resolve_fbo)
            GL.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
            source = self.resolve_fbo
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, source)
        GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, 0)
        same = (w, h) == (width, height)
        GL.glBlitFramebuffer(0, 0, w, h, 0, 0, width, height, GL.GL_COLOR_BUFFER_BIT,
                             GL.GL_NEAREST if same else GL.GL_LINEAR)  # fmt: skip
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        GL.glViewport(0, 0, width, height)

    def read(self) -> np.ndarray:
        """The rendered image, (height, width, 3) uint8, row 0 at the top."""
        source = self.fbo
        if self.resolve_fbo is not None:
            GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.fbo)
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, self.resolve_fbo)
            w, h = self.width, self.height
            GL.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
            source = self.resolve_fbo
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, source)
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        data = GL.glReadPixels(0, 0, self.width, self.height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.fbo)
        image = np.frombuffer(data, dtype=np.uint8).reshape(self.height, self.width, 3)
        return image[::-1].copy()

    def delete(self) -> None:
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        fbos = [self.fbo] + ([self.resolve_fbo] if self.resolve_fbo is not None else [])
        GL.glDeleteFramebuffers(len(fbos), fbos)
        GL.glDeleteRenderbuffers(len(self._renderbuffers), self._renderbuffers)
